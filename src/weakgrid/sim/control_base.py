"""Base of machine controls (exciters, governors, PSS): link to a machine and its bus."""

from __future__ import annotations

import numpy as np

from .component import Component, fast_index


class MachineControl(Component):
    """A control attached to one machine (link ``machine=<machine name>``).

    After :meth:`setup`: ``mach`` (global machine numbers), ``bus`` (bus
    positions of the machines) and ``Sn`` (machine ratings [MVA]) are arrays.
    Per-unit conversions with ``base="power"``/``"ipower"`` use the machine
    rating (or the parameter ``Tn`` when it is given and > 0, as ANDES does for
    turbine ratings).
    """

    def setup(self, system):
        super().setup(system)
        self.mach = np.array([system.machine_number(lk["machine"]) for lk in self.links], dtype=int)
        self._mi = fast_index(self.mach)
        self.bus = np.zeros(self.n, dtype=int)
        self.Sn = np.zeros(self.n)
        for i, m in enumerate(self.mach):
            mtype, mname = system._machines[m]
            mc = system.components[mtype]
            j = mc.names.index(mname)
            self.bus[i] = mc.bus[j]
            self.Sn[i] = mc.p["Sn"][j]
        Sn = self.Sn
        if "Tn" in self.p:
            Sn = np.where(self.p["Tn"] > 0, self.p["Tn"], Sn)
        coeff = {"power": Sn / system.Sb, "ipower": system.Sb / Sn}
        for prm in self.params:
            if prm.base in coeff:
                self.p[prm.name] = self.p[prm.name] * coeff[prm.base]

    def pattern(self, system):
        return None  # grouped with the machine by the system
