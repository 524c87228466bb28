"""STAB1: speed-sensitive stabilizing model (PSS/E STAB1).

Block diagram (PSS/E Model Library, STAB1; pu, times in s)::

    omega - 1 --[Washout  K s/(1 + sT)]--[LeadLag (1+sT1)/(1+sT3)]--[LeadLag (1+sT2)/(1+sT4)]
              --> clip(-HLIM, HLIM) = vs

PSS/E gives the washout's high-frequency gain ``K/T`` (CON J) rather than ``K``, and the lead
time constants as the ratios ``T1/T3`` and ``T2/T4``; weakgrid keeps those data as given
(parameters ``KT``, ``T1T3``, ``T2T4``) and forms ``K = KT*T``, ``T1 = T1T3*T3``,
``T2 = T2T4*T4``. The input is the rotor speed deviation [pu]; the output limit is a static
(windup) limit. In steady state the washout blocks the constant input: ``vs = 0``.

Zero-parameter conventions: ``T3 = 0`` / ``T4 = 0`` make the lead-lag a unit gain (its lead
``T1 = T1T3*T3`` is then 0 too); ``T`` must be > 0 (a washout without a time constant has no
meaning in STAB1).
"""

from __future__ import annotations

from ..blocks import LeadLag, Washout, hard_limit
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param


class STAB1(MachineControl):
    """Speed-input PSS. Parameters: KT = K/T [pu]; T, T3, T4 [s]; T1T3 = T1/T3, T2T4 = T2/T4 [-];
    HLIM [pu]."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "pss"
    order = 1
    params = (
        Param("KT", 1.0, "pu", "washout high-frequency gain K/T (pu output per pu speed)", ""),
        Param("T", 1.0, "s", "washout time constant", "pos"),
        Param("T1T3", 1.0, "-", "ratio T1/T3 of the first lead-lag", "nonneg"),
        Param("T3", 0.05, "s", "first lead-lag lag time constant T3", "nonneg"),
        Param("T2T4", 1.0, "-", "ratio T2/T4 of the second lead-lag", "nonneg"),
        Param("T4", 0.05, "s", "second lead-lag lag time constant T4", "nonneg"),
        Param("HLIM", 0.1, "pu", "output limit (symmetric, +-HLIM)", "nonneg"),
    )
    states = ("WO", "LL1", "LL2")
    outputs = ("sig", "vss", "vs")

    #: PSS/E .dyr record after ``IBUS 'STAB1' ID``: CONs K/T, T, T1/T3, T3, T2/T4, T4, HLIM.
    psse_record = ("KT", "T", "T1T3", "T3", "T2T4", "T4", "HLIM")

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.WO = Washout(p["KT"] * p["T"], p["T"])
        self.LL1 = LeadLag(p["T1T3"] * p["T3"], p["T3"])
        self.LL2 = LeadLag(p["T2T4"] * p["T4"], p["T4"])

    def init(self, system, x, sig):
        # speed deviation 0 in steady state: every state (and the output) is 0
        x[self.sl(0)] = 0.0
        x[self.sl(1)] = 0.0
        x[self.sl(2)] = 0.0

    def compute(self, ctx):
        xp, p = self.xp, self.p
        m = self._mi
        f = ctx.f
        sl = self._sls
        wo, x1, x2 = (ctx.x[..., k] for k in sl)
        u = take(xp, ctx.sig["omega"], m) - 1.0
        y0 = self.WO.output(wo, u)
        y1 = self.LL1.output(x1, y0)
        y2 = self.LL2.output(x2, y1)
        f[..., sl[0]] = self.WO.deriv(wo, u)
        f[..., sl[1]] = self.LL1.deriv(x1, y0)
        f[..., sl[2]] = self.LL2.deriv(x2, y1)
        vs = hard_limit(y2, -p["HLIM"], p["HLIM"], xp)
        put(xp, ctx.sig["vs"], m, vs)
        ctx.out["STAB1.sig"], ctx.out["STAB1.vss"], ctx.out["STAB1.vs"] = u, y2, vs
