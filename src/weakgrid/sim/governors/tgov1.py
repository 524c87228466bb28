"""TGOV1: steam turbine-governor (PSS/E TGOV1, ANDES conventions).

Block diagram (pu on the system base after conversion; times in s)::

    wd = omega - wref0
    pd = pref0 + (paux - wd)/R
    pd --[Lag 1/(1+sT1), non-windup VMIN..VMAX]--> LAG
    LAG --[LeadLag (1+sT2)/(1+sT3)]--> LL
    tm = LL - Dt*wd

``R`` is on the turbine base (``ipower``), ``VMAX``, ``VMIN``, ``Dt`` on the
turbine base (``power``); the turbine base is ``Tn`` if > 0 else the machine ``Sn``.
``pref0`` is the initial mechanical torque.
"""

from __future__ import annotations

import numpy as np

from ..blocks import LagNonWindup, LeadLag
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param


class TGOV1(MachineControl):
    """Steam turbine-governor TGOV1. Parameters: R, VMAX, VMIN, Dt [pu, turbine base]; T1, T2, T3 [s]."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "governor"
    #: the power reference computed at init (from the operating point): per batch member
    batch_params = ("pref0",)
    order = 2
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("R", "T1", "VMAX", "VMIN", "T2", "T3", "Dt")
    params = (
        Param("Tn", 0.0, "MVA", "turbine rating (0: machine Sn)", "nonneg"),
        Param("wref0", 1.0, "pu", "speed reference", "pos"),
        Param("R", 0.05, "pu (turbine base)", "droop", "pos", "ipower"),
        Param("VMAX", 1.2, "pu (turbine base)", "maximum valve position", "", "power"),
        Param("VMIN", 0.0, "pu (turbine base)", "minimum valve position", "", "power"),
        Param("T1", 0.1, "s", "valve time constant", "pos"),
        Param("T2", 0.2, "s", "lead time constant", "nonneg"),
        Param("T3", 10.0, "s", "lag time constant", "pos"),
        Param("Dt", 0.0, "pu (turbine base)", "turbine damping", "", "power"),
    )
    states = ("LAG", "LL")
    outputs = ("pout",)

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.LAG = LagNonWindup(1.0, p["T1"], p["VMIN"], p["VMAX"])
        self.LL = LeadLag(p["T2"], p["T3"])
        self.paux = np.zeros(self.n)
        self._key = f"{self.type_name}.pout"

    #: parameter names of the limits of each limited state (for error messages)
    limit_fields = {"LAG": ("VMIN", "VMAX")}

    def limits(self):
        return [(self.idx("LAG"), self.p["VMIN"], self.p["VMAX"])]

    def init(self, system, x, sig):
        tm0 = sig["tm0"][self.mach]
        self.pref0 = tm0.copy()
        x[self.sl(0)] = tm0
        x[self.sl(1)] = self.LL.init(tm0)

    def _pd(self, wd):
        """Valve demand: reference and auxiliary input plus droop, before the valve lag."""
        return self.pref0 + (self.paux - wd) / self.p["R"]

    def compute(self, ctx):
        xp, p, m = self.xp, self.p, self._mi
        lag, ll = ctx.x[..., self._sls[0]], ctx.x[..., self._sls[1]]
        wd = take(xp, ctx.sig["omega"], m) - p["wref0"]
        pd = self._pd(wd)
        ctx.f[..., self._sls[0]] = self.LAG.deriv(lag, pd)
        y, ctx.f[..., self._sls[1]] = self.LL.output_deriv(ll, lag)
        pout = y - p["Dt"] * wd
        put(xp, ctx.sig["tm"], m, pout)
        ctx.out[self._key] = pout
