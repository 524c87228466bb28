"""TG2: simplified turbine-governor (Milano, *Power System Modelling and Scripting*, TG type 2).

Block diagram (pu on the system base after conversion; times in s)::

    wd  = wref0 - omega                                  (positive for under-speed)
    wd --[gain 1/R]--[LeadLag (1+sT1)/(1+sT2)]--> ll
    pout = clip(pref0 + ll, pmin, pmax)                  (static output limit)

``R`` is on the turbine base (``ipower``), ``pmax``/``pmin`` on the turbine
base (``power``). The speed dead band (``dbl``, ``dbu``, ``dbc``) is accepted and
not applied. (ANDES 2.0 with its default ``deadband = 0`` gives TG2 no speed
response at all, its dead-band flag defaulting to "inside the band"; the peer
test enables ANDES's dead band with a 1e-9 pu band.)
"""

from __future__ import annotations

import numpy as np

from ..blocks import LeadLag, hard_limit
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param


class TG2(MachineControl):
    """Turbine-governor type 2. Parameters: R, pmax, pmin [pu, turbine base]; T1, T2 [s]."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "governor"
    #: the power reference computed at init (from the operating point): per batch member
    batch_params = ("pref0",)
    order = 2
    params = (
        Param("Tn", 0.0, "MVA", "turbine rating (0: machine Sn)", "nonneg"),
        Param("wref0", 1.0, "pu", "speed reference", "pos"),
        Param("R", 0.05, "pu (turbine base)", "droop", "pos", "ipower"),
        Param("pmax", 999.0, "pu (turbine base)", "maximum power output", "", "power"),
        Param("pmin", 0.0, "pu (turbine base)", "minimum power output", "", "power"),
        Param("dbl", -0.0001, "pu", "dead band lower limit (not applied)", ""),
        Param("dbu", 0.0001, "pu", "dead band upper limit (not applied)", ""),
        Param("dbc", 0.0, "pu", "dead band neutral value (not applied)", ""),
        Param("T1", 0.2, "s", "transient gain (lead) time constant", "nonneg"),
        Param("T2", 10.0, "s", "governor (lag) time constant", "pos"),
    )
    states = ("ll",)
    outputs = ("pout",)

    def setup(self, system):
        super().setup(system)
        self.LL = LeadLag(self.p["T1"], self.p["T2"])

    def init(self, system, x, sig):
        self.pref0 = sig["tm0"][self.mach].copy()
        x[self.sl(0)] = self.LL.init(np.zeros(self.n))

    def compute(self, ctx):
        xp, p = self.xp, self.p
        m = self._mi
        ll = ctx.x[..., self._sls[0]]
        u = (p["wref0"] - take(xp, ctx.sig["omega"], m)) / p["R"]
        ctx.f[..., self._sls[0]] = self.LL.deriv(ll, u)
        pout = hard_limit(self.pref0 + self.LL.output(ll, u), p["pmin"], p["pmax"], xp)
        put(xp, ctx.sig["tm"], m, pout)
        ctx.out["TG2.pout"] = pout
