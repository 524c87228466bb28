"""SEXS: simplified excitation system (PSS/E SEXS, ANDES conventions).

Block diagram::

    vi = vref - v + vs
    vi --[LeadLag (1+sTA)/(1+sTB), TA = TATB*TB]--> LL
    LL --[Lag K/(1+sTE), non-windup EMIN..EMAX]--> vf

``TE = 0`` makes the last block a static gain clipped to ``[EMIN, EMAX]``.
"""

from __future__ import annotations

from ..blocks import Lag, LeadLag
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param


class SEXS(MachineControl):
    """Simplified exciter. Parameters: TATB [-], TB, TE [s], K [pu], EMIN, EMAX [pu]."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("TATB", "TB", "K", "TE", "EMIN", "EMAX")
    params = (
        Param("TATB", 0.4, "-", "ratio TA/TB", "nonneg"),
        Param("TB", 5.0, "s", "lag time constant of the lead-lag", "pos"),
        Param("K", 20.0, "pu", "gain", "pos"),
        Param("TE", 1.0, "s", "exciter time constant", "nonneg"),
        Param("EMIN", -99.0, "pu", "minimum field voltage", ""),
        Param("EMAX", 99.0, "pu", "maximum field voltage", ""),
    )
    states = ("LL", "LAW")
    outputs = ("vi",)

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.LL = LeadLag(p["TATB"] * p["TB"], p["TB"])
        self.LAW = Lag(p["K"], p["TE"])

    #: parameter names of the limits of each limited state (for error messages)
    limit_fields = {"LAW": ("EMIN", "EMAX")}

    def limits(self):
        on = self.p["TE"] > 0
        return [(self.idx("LAW")[on], self.p["EMIN"][on], self.p["EMAX"][on])]

    def init(self, system, x, sig):
        vf0 = sig["vf0"][self.mach]
        vi0 = vf0 / self.p["K"]
        self.vref0 = sig["Ecomp0"][self.mach] + vi0
        x[self.sl(0)] = self.LL.init(vi0)
        x[self.sl(1)] = vf0

    def compute(self, ctx):
        xp, m = self.xp, self._mi    # a slice when the machines are contiguous (a view, no gather)
        ll, law = ctx.x[..., self._sls[0]], ctx.x[..., self._sls[1]]
        vi = self.vref0 - take(xp, ctx.sig["Ecomp"], m) + take(xp, ctx.sig["vs"], m)
        y = self.LL.output(ll, vi)
        ctx.f[..., self._sls[0]] = self.LL.deriv(ll, vi)
        ctx.f[..., self._sls[1]] = self.LAW.deriv(law, y)
        vf = xp.minimum(xp.maximum(self.LAW.output(law, y), self.p["EMIN"]), self.p["EMAX"])
        put(xp, ctx.sig["vf"], m, vf)
        ctx.out["SEXS.vi"] = vi
