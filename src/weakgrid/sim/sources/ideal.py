"""Ideal sources that hold bus quantities fixed: what ANDES 2.0 simulates for a power-flow
generator (``Slack`` or ``PV``) that no machine or converter replaces.

In ANDES's time-domain simulation such a static generator keeps its power-flow equations
(its ``u`` stays 1; only a dynamic device sets it to 0), with the power-flow limits off
(``pv2pq = av2pv = 0``, the defaults):

* a **Slack** holds its bus voltage magnitude *and angle* (``v = v0``, ``a = a0``) and
  supplies whatever active and reactive power that takes: an ideal voltage source, an
  *infinite bus* — infinite inertia (its frequency never moves) and unlimited current
  (it feeds a fault at its bus without its voltage moving);
* a **PV** injects its scheduled active power ``p0`` and holds its bus voltage magnitude
  ``v0`` with unlimited reactive power; its angle follows the network instantly: no inertia,
  no frequency response, unlimited reactive current.

Neither exists physically; they are the stiffest possible boundary conditions, and a study
on such a grid should be read with that in mind (the ANDES importer says so in
``system.import_notes``).

How it is solved: each source replaces the current balance of its bus by its own constraint.
In the second evaluation pass (it runs last, after every other device has added its current
``I_other``), it computes the current it must inject, ``I_src = (Y V)_b - I_other``, and adds
``I_src - k R`` where ``R`` is its constraint residual (zero when the constraint holds), so the
bus's network residual becomes ``k R``. At a solution ``R = 0``: the constraint holds exactly
and ``I_src`` is the source's current. ``k`` scales ``R`` to currents (``|Y_bb|`` for
voltage constraints, 1 for the power constraint).
"""

from __future__ import annotations

import numpy as np

from ..component import Component
from ..errors import DataError
from ..namespace import NUMPY, add_at, take, to_numpy
from ..network import PD, QD


class _BusConstraint(Component):
    """A source holding two real quantities of its bus; linked to a gen-table row (``gen``)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "device"
    order = 9            # last: reads the currents of every other device at its bus
    params = ()
    outputs = ("P", "Q")
    units = {"P": "power", "Q": "power"}
    #: the power-flow phasor ``V0`` [pu] and scheduled power ``p0`` [pu, system base] it holds
    #: (from the operating point, read only when evaluating): per batch member
    #: (:mod:`weakgrid.sim.batch`); the loads at its buses are not (``bus_load``)
    batch_params = ("V0", "p0")

    def add_source(self, name, gen, also=()):
        """Add a source for the gen-table row ``gen`` (0-based, in service).

        ``also``: further in-service gen-table rows at the same bus that no other device
        represents (several static generators on one bus: PSS/E's ACTIVSg2000 has two at bus
        1090). One source holds the bus for all of them and carries their summed scheduled
        active power (a bus can hold only one voltage constraint)."""
        link = {"gen": gen}
        if len(also):
            link["also"] = [int(g) for g in also]
        self.add(name, link, {})
        return name

    def setup(self, system):
        super().setup(system)
        self.resolve_gen_rows(system)
        self.gen_also = self._resolve_also(system)
        seen = {}
        for i, b in enumerate(self.bus):
            if b in seen:
                raise DataError(self.element(i), "gen", int(self.gen[i]),
                                f"bus {system.network.bus_ids[b]} already held by {seen[b]}; "
                                "give a bus at most one ideal source")
            seen[b] = self.element(i)
        self.__dict__.pop("k", None)
        for c in system.components.values():
            if c is not self and isinstance(c, _BusConstraint):
                for i, b in enumerate(self.bus):
                    if b in set(np.atleast_1d(getattr(c, "bus", [])).tolist()):
                        raise DataError(self.element(i), "gen", int(self.gen[i]),
                                        f"bus {system.network.bus_ids[b]} already holds another ideal source")
        self._ver = None

    def _resolve_also(self, system):
        """The ``also`` rows of each instance (a list per instance), checked: in service and
        at the instance's bus."""
        from ..network import GEN_BUS, GEN_STATUS

        net, out = system.network, []
        for i, lk in enumerate(self.links):
            rows = [int(g) for g in lk.get("also", [])]
            for g in rows:
                if not (0 <= g < net.gen.shape[0]) or net.gen[g, GEN_STATUS] <= 0 or \
                        int(net.gen[g, GEN_BUS]) != int(net.gen[self.gen[i], GEN_BUS]):
                    raise DataError(self.element(i), "also", g,
                                    "give in-service gen-table rows at the source's own bus "
                                    f"{system.network.bus_ids[self.bus[i]]}")
            out.append(rows)
        return out

    def pattern(self, system):
        """Rows of the source's bus: its own and neighbouring bus voltages, and the states of
        every other device injecting at that bus (the source cancels their currents)."""
        f, t = system.network.branch_admittances()[:2]
        groups = []
        for b in self.bus:
            nbr = {int(b)} | {int(j) for j in t[f == b]} | {int(j) for j in f[t == b]}
            cols = [k for j in sorted(nbr) for k in system.bus_vars(j)]
            for c in system.comps:
                cb = getattr(c, "bus", None)
                if c is self or cb is None or c.kind not in ("machine", "device") or len(np.atleast_1d(cb)) != c.n:
                    continue
                for i in np.nonzero(np.atleast_1d(cb) == b)[0]:
                    cols += c.instance_states(int(i))
            groups.append((system.bus_vars(b), cols))
        return groups

    def init(self, system, x, sig):
        net = system.network
        self.V0 = net.pf.V[self.bus].copy()
        self.p0 = net.pf.Pg[self.gen].copy()
        for i, rows in enumerate(getattr(self, "gen_also", [])):
            self.p0[i] += float(np.sum(net.pf.Pg[rows])) if rows else 0.0
        # the loads at its buses (PD, QD [MW, Mvar]): its rows of the network matrix, which
        # ``finish`` reads from the evaluating grid, hold their admittances, so the batch
        # simulator must not give members with other loads there one evaluating copy (this
        # attribute is part of the grid's fingerprint, the loads elsewhere are not)
        self.bus_load = net.bus[self.bus][:, [PD, QD]].copy()
        self._nb = net.nb

    def _rows(self, system):
        """Rows ``b`` and ``nb + b`` of the real-form admittance matrix (as applied now), in
        the namespace of the evaluation (computed on NumPy when the network changes)."""
        if self._ver != system.net_version:
            nb = self._nb
            Yr = system.Yr
            bus = to_numpy(self.bus)
            Yre = Yr[bus].toarray()
            Yim = Yr[bus + nb].toarray()
            ybb = np.abs(Yre[np.arange(self.n), bus] + 1j * Yim[np.arange(self.n), bus])
            xp = self.xp
            if not hasattr(self, "k"):
                self.k = np.maximum(ybb, 1.0)   # fixed at the first evaluation (pre-event network)
                if xp is not NUMPY:
                    self.k = xp.asarray(self.k)
            self._Yre, self._Yim = (Yre, Yim) if xp is NUMPY else (xp.asarray(Yre), xp.asarray(Yim))
            self._ver = system.net_version
        return self._Yre, self._Yim

    def finish(self, ctx):
        xp = self.xp
        Yre, Yim = self._rows(ctx.system)
        vec = xp.concat([xp.real(ctx.V), xp.imag(ctx.V)], axis=-1)
        Inet = vec @ Yre.T + 1j * (vec @ Yim.T)
        V = take(xp, ctx.V, self.bus)
        Isrc = Inet - take(xp, ctx.I, self.bus)
        R = self.residual(V, Isrc)
        add_at(xp, ctx.I, self.bus, Isrc - R, True)
        S = V * xp.conj(Isrc)
        ctx.out[f"{self.type_name}.P"], ctx.out[f"{self.type_name}.Q"] = xp.real(S), xp.imag(S)

    def residual(self, V, Isrc):
        raise NotImplementedError


class InfiniteBus(_BusConstraint):
    """Ideal voltage source (infinite bus): holds its bus at the power-flow phasor ``V0``.

    Reproduces ANDES 2.0's time-domain handling of a ``Slack`` generator that no machine or
    converter replaces (its equations ``v = v0``, ``a = a0`` stay active). Physically:
    infinite inertia (constant frequency and angle), unlimited active and reactive power
    and current. Outputs ``P``, ``Q`` [pu, system base]: the power it supplies.
    """

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    def residual(self, V, Isrc):
        return self.k * (V - self.V0)


class PVSource(_BusConstraint):
    """Constant active power ``P0`` at constant voltage magnitude ``|V0|`` (a power-flow PV bus).

    Reproduces ANDES 2.0's time-domain handling of a ``PV`` generator that no machine or
    converter replaces (its equations ``p = p0`` and ``v = v0`` stay active, reactive limits
    off). Physically: no inertia and no frequency response (its angle follows the network
    instantly), unlimited reactive power and current. ``P0`` and ``|V0|`` [pu] come from the
    power flow. Outputs ``P``, ``Q`` [pu, system base].
    """

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    def residual(self, V, Isrc):
        xp = self.xp
        P = xp.real(V * xp.conj(Isrc))
        return (P - self.p0) + 1j * self.k * (xp.abs(V) - xp.abs(self.V0))
