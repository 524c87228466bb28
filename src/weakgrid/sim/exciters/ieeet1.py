"""IEEET1: IEEE type 1 DC exciter (1968/1979 IEEE type 1, PSS/E IEEET1).

Block diagram (pu, times in s)::

    v --[Lag 1/(1+sTR)]--> LG
    vi = vref - LG + vs                                  (vs: PSS output)
    (vi - WF) --[Lag KA/(1+sTA), non-windup VRMIN..VRMAX]--> VR
    TE dEfd/dt = VR - (KE*Efd + Efd*SE(Efd))             (DC exciter, quadratic saturation)
    Efd --[Washout s*KF/(1+sTF)]--> WF                   (rate feedback)

``VRMAX = 0`` means no upper limit (as ANDES); ``TA = 0`` makes the regulator the limited
gain ``VR = clip(KA*(vi - WF), VRMIN, VRMAX)`` (PSS/E; ANDES's EI_33 data). ``Switch`` is accepted and unused
(as in PSS/E). ``KE = 0`` is taken literally (PSS/E's "compute KE so that VR
starts at VRMAX" option is not implemented).
"""

from __future__ import annotations

from ..blocks import Lag, LagNonWindup, Washout
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param
from .dc_common import SATURATION_PARAMS, DCExciter, vrmax_or_unlimited


class IEEET1(MachineControl):
    """IEEE type 1 exciter. Times [s]: TR, TA, TE, TF; gains [pu]: KA, KE, KF; VRMAX, VRMIN [pu];
    E1, SE1, E2, SE2 (saturation)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("TR", "KA", "TA", "VRMAX", "VRMIN", "KE", "TE", "KF", "TF", "Switch", "E1",
                   "SE1", "E2", "SE2")
    params = (
        Param("TR", 0.02, "s", "sensing time constant", "nonneg"),
        Param("KA", 5.0, "pu", "regulator gain", "pos"),
        Param("TA", 0.04, "s", "regulator time constant (0: no lag)", "nonneg"),
        Param("VRMAX", 7.3, "pu", "maximum regulator output (0: unlimited)", ""),
        Param("VRMIN", -7.3, "pu", "minimum regulator output", ""),
        Param("KE", 1.0, "pu", "exciter constant", ""),
        Param("TE", 0.8, "s", "exciter time constant", "pos"),
        Param("KF", 0.1, "pu", "rate feedback gain", "nonneg"),
        Param("TF", 1.0, "s", "rate feedback time constant", "pos"),
        Param("Switch", 0.0, "-", "unused (PSS/E)", ""),
    ) + SATURATION_PARAMS
    states = ("LG", "VR", "Efd", "WF")
    outputs = ("vi", "vout")

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.LG = Lag(1.0, p["TR"])
        self.LA = LagNonWindup(p["KA"], p["TA"], p["VRMIN"], vrmax_or_unlimited(p["VRMAX"]))
        self.EX = DCExciter(p["KE"], p["TE"], p["E1"], p["SE1"], p["E2"], p["SE2"])
        self.WF = Washout(p["KF"], p["TF"])

    def limits(self):
        return [(self.idx("VR"), self.LA.lower, self.LA.upper)]

    def init(self, system, x, sig):
        m = self.mach
        vf0, v = sig["vf0"][m], sig["Ecomp0"][m]
        vr0 = self.EX.vr0(vf0)
        self.vref0 = v + vr0 / self.p["KA"]
        x[self.sl(0)] = self.LG.init(v)
        x[self.sl(1)] = vr0
        x[self.sl(2)] = vf0
        x[self.sl(3)] = self.WF.init(vf0)

    def compute(self, ctx):
        xp, m = self.xp, self._mi
        lg, vr, efd, wf = (ctx.x[..., s] for s in self._sls)
        s = ctx.sig
        v = take(xp, s["Ecomp"], m)
        vi = self.vref0 - self.LG.output(lg, v) + take(xp, s["vs"], m)
        f = ctx.f
        f[..., self._sls[0]] = self.LG.deriv(lg, v)
        u = vi - self.WF.output(wf, efd)
        f[..., self._sls[1]] = self.LA.deriv(vr, u)
        f[..., self._sls[2]] = self.EX.deriv(efd, self.LA.output(vr, u))   # = vr unless TA = 0
        f[..., self._sls[3]] = self.WF.deriv(wf, efd)
        put(xp, s["vf"], m, efd)
        ctx.out["IEEET1.vi"], ctx.out["IEEET1.vout"] = vi, efd
