"""IEESGO: IEEE standard steam turbine-governor (PSS/E IEESGO).

Block diagram (pu; times in s)::

    (omega - wref0) --[Lag K1/(1+sT1)]--[LeadLag (1+sT2)/(1+sT3)]--> F2
    P = clip(pref0 + paux - F2, PMIN, PMAX)                (static valve limit)
    P  --[Lag 1/(1+sT4)]--> F3                             (steam inlet)
    F3 --[Lag K2/(1+sT5)]--> F4                            (reheater)
    F4 --[Lag K3/(1+sT6)]--> F5                            (crossover)
    pm = (1-K2)*F3 + (1-K3)*F4 + F5

``PMAX``, ``PMIN`` are on the turbine base (``power``); ``K1`` [pu/pu] is used
as given (no base conversion, as ANDES). Time constants equal to zero make the
lag a gain.
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LeadLag, hard_limit
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param


class IEESGO(MachineControl):
    """IEEE standard governor. Parameters: T1..T6 [s]; K1 [pu/pu speed], K2, K3 [-]; PMAX, PMIN [pu]."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "governor"
    #: the power reference computed at init (from the operating point): per batch member
    batch_params = ("pref0",)
    order = 2
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("T1", "T2", "T3", "T4", "T5", "T6", "K1", "K2", "K3", "PMAX", "PMIN")
    params = (
        Param("Tn", 0.0, "MVA", "turbine rating (0: machine Sn)", "nonneg"),
        Param("wref0", 1.0, "pu", "speed reference", "pos"),
        Param("T1", 0.02, "s", "controller lag", "nonneg"),
        Param("T2", 1.0, "s", "lead compensation", "nonneg"),
        Param("T3", 1.0, "s", "governor lag", "nonneg"),
        Param("T4", 0.5, "s", "steam inlet delay", "nonneg"),
        Param("T5", 10.0, "s", "reheater delay", "nonneg"),
        Param("T6", 0.5, "s", "crossover delay", "nonneg"),
        Param("K1", 0.02, "pu", "1/pu regulation (gain on the speed deviation)", ""),
        Param("K2", 1.0, "-", "fraction K2", ""),
        Param("K3", 1.0, "-", "fraction K3", ""),
        Param("PMAX", 5.0, "pu (turbine base)", "maximum power", "", "power"),
        Param("PMIN", 0.0, "pu (turbine base)", "minimum power", "", "power"),
    )
    states = ("F1", "F2", "F3", "F4", "F5")
    outputs = ("P", "pout")

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.F1 = Lag(p["K1"], p["T1"])
        self.F2 = LeadLag(p["T2"], p["T3"])
        self.F3 = Lag(1.0, p["T4"])
        self.F4 = Lag(p["K2"], p["T5"])
        self.F5 = Lag(p["K3"], p["T6"])
        self.paux = np.zeros(self.n)

    def init(self, system, x, sig):
        tm0 = sig["tm0"][self.mach]
        self.pref0 = tm0.copy()
        zero = np.zeros(self.n)
        x[self.sl(0)] = self.F1.init(zero)
        x[self.sl(1)] = self.F2.init(zero)
        x[self.sl(2)] = self.F3.init(tm0)
        x[self.sl(3)] = self.F4.init(tm0)
        x[self.sl(4)] = self.F5.init(self.F4.init(tm0))

    def compute(self, ctx):
        xp, p = self.xp, self.p
        m = self._mi
        f1, f2, f3, f4, f5 = (ctx.x[..., s] for s in self._sls)
        wd = take(xp, ctx.sig["omega"], m) - p["wref0"]
        y1 = self.F1.output(f1, wd)
        y2 = self.F2.output(f2, y1)
        pv = hard_limit(self.pref0 + self.paux - y2, p["PMIN"], p["PMAX"], xp)
        y3 = self.F3.output(f3, pv)
        y4 = self.F4.output(f4, y3)
        y5 = self.F5.output(f5, y4)
        f = ctx.f
        f[..., self._sls[0]] = self.F1.deriv(f1, wd)
        f[..., self._sls[1]] = self.F2.deriv(f2, y1)
        f[..., self._sls[2]] = self.F3.deriv(f3, pv)
        f[..., self._sls[3]] = self.F4.deriv(f4, y3)
        f[..., self._sls[4]] = self.F5.deriv(f5, y4)
        pout = (1 - p["K2"]) * y3 + (1 - p["K3"]) * y4 + y5
        put(xp, ctx.sig["tm"], m, pout)
        ctx.out["IEESGO.P"], ctx.out["IEESGO.pout"] = pv, pout
