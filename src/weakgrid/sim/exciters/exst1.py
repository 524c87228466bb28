"""EXST1: IEEE type ST1 potential-source static exciter (PSS/E EXST1).

Block diagram (pu, times in s)::

    v --[Lag 1/(1+sTR)]--> LG
    vi  = vref - LG - WF + vs                      (vs: PSS output)
    vil = clip(vi, VIMIN, VIMAX)
    vil --[LeadLag (1+sTC)/(1+sTB)]--> LL
    LL  --[Lag KA/(1+sTA)]--> VR
    VR_Vt = 1:  lo, hi = Vt*VRMIN, Vt*VRMAX - KC*XadIfd    (terminal-voltage and field-current
                                                       dependent limits, IEEE ST1A and PSS/E)
    VR_Vt = 0:  lo, hi = VRMIN - KC*XadIfd, VRMAX - KC*XadIfd        (ANDES 2.0; the default)
    VR_limited = 1:  Efd = clip(VR, lo, hi);  Efd --[Washout s*KF/(1+sTF)]--> WF   (standard)
    VR_limited = 0:  VR --[Washout s*KF/(1+sTF)]--> WF;  Efd = VR unless WF is beyond lo..hi,
                     then that bound                                               (ANDES 2.0)

Difference from ANDES 2.0 (documented, not copied): ANDES applies the output
limiter's test to the rate-feedback signal instead of the regulator output (so its
ceiling is in effect never reached) and feeds back the regulator output; here both
follow the standard diagram. They agree whenever the output limiter is inactive.
``VR_limited = 0`` reproduces ANDES (set by ``from_andes(..., conventions="andes")``). ANDES also
leaves out the terminal voltage ``Vt`` in the output limits (``VR_Vt = 0``, the default, so that
the ANDES-validated cases keep their numbers); the IEEE ST1A / PSS/E ceiling
``Vt*VRMAX - KC*XadIfd`` (``VR_Vt = 1``) is what the PSS/E reader sets: on
PowerSimulationsDynamics.jl's PSS/E EXST1 case (fault near the machine) PSS/E's field voltage
peaks at 5.91 pu < VRMAX = 6, and only the Vt-dependent ceiling matches it (3.5 % of the swing
off with the constant one).
"""

from __future__ import annotations

from ..blocks import Lag, LeadLag, Washout, hard_limit
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param


class EXST1(MachineControl):
    """IEEE ST1 static exciter. Times [s]: TR, TC, TB, TA, TF; gains [pu]: KA, KC, KF;
    limits VIMAX, VIMIN, VRMAX, VRMIN [pu]."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("TR", "VIMAX", "VIMIN", "TC", "TB", "KA", "TA", "VRMAX", "VRMIN", "KC", "KF",
                   "TF")
    @classmethod
    def psse_params(cls, values, ctx):
        """PSS/E's EXST1: output limits ``Vt*VRMIN``, ``Vt*VRMAX - KC*XadIfd`` (``VR_Vt = 1``)."""
        return dict(values, VR_Vt=1.0)

    params = (
        Param("TR", 0.01, "s", "sensing time constant", "nonneg"),
        Param("VIMAX", 0.2, "pu", "maximum input error", ""),
        Param("VIMIN", 0.0, "pu", "minimum input error", ""),
        Param("TC", 1.0, "s", "lead time constant", "nonneg"),
        Param("TB", 1.0, "s", "lag time constant", "nonneg"),
        Param("KA", 80.0, "pu", "regulator gain", "pos"),
        Param("TA", 0.05, "s", "regulator time constant", "pos"),
        Param("VRMAX", 8.0, "pu", "maximum output", ""),
        Param("VRMIN", -3.0, "pu", "minimum output", ""),
        Param("KC", 0.2, "pu", "rectifier loading factor", "nonneg"),
        Param("KF", 0.1, "pu", "rate feedback gain", "nonneg"),
        Param("TF", 1.0, "s", "rate feedback time constant", "pos"),
        Param("VR_limited", 1.0, "-", "1: the output limits act on the regulator output, which the "
              "rate feedback takes (IEEE); 0: ANDES 2.0's EXST1 (limit test on the rate feedback, "
              "which takes the unlimited regulator output)", "flag"),
        Param("VR_Vt", 0.0, "-", "1: output limits Vt*VRMIN, Vt*VRMAX - KC*XadIfd (IEEE ST1A, "
              "PSS/E; set by the PSS/E reader); 0: VRMIN - KC*XadIfd, VRMAX - KC*XadIfd (ANDES "
              "2.0, and the default for the grids validated against it)", "flag"),
    )
    states = ("LG", "LL", "VR", "WF")
    outputs = ("vi", "vout")

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.LG = Lag(1.0, p["TR"])
        self.LL = LeadLag(p["TC"], p["TB"])
        self.LR = Lag(p["KA"], p["TA"])
        self.WF = Washout(p["KF"], p["TF"])
        self._std = p["VR_limited"] > 0
        self._vt = p["VR_Vt"] > 0

    def init(self, system, x, sig):
        p = self.p
        m = self.mach
        vf0, v = sig["vf0"][m], sig["Ecomp0"][m]
        vi0 = vf0 / p["KA"]
        self.vref0 = v + vi0
        x[self.sl(0)] = self.LG.init(v)
        x[self.sl(1)] = self.LL.init(vi0)
        x[self.sl(2)] = self.LR.init(vi0)
        x[self.sl(3)] = self.WF.init(vf0)

    def compute(self, ctx):
        xp, p = self.xp, self.p
        m = self._mi
        lg, ll, vr, wf = (ctx.x[..., s] for s in self._sls)
        s = ctx.sig
        v = take(xp, s["Ecomp"], m)
        xad = take(xp, s["XadIfd"], m)
        vt = xp.where(self._vt, take(xp, s["Vt"], m), 1.0)
        lo = vt * p["VRMIN"] - xp.where(self._vt, 0.0, p["KC"] * xad)
        hi = vt * p["VRMAX"] - p["KC"] * xad
        fb_in = xp.where(self._std, hard_limit(vr, lo, hi, xp), vr)        # rate feedback input
        wfy = self.WF.output(wf, fb_in)
        efd = xp.where(self._std, fb_in, xp.where(wfy > hi, hi, xp.where(wfy < lo, lo, vr)))
        vi = self.vref0 - self.LG.output(lg, v) - wfy + take(xp, s["vs"], m)
        vil = hard_limit(vi, p["VIMIN"], p["VIMAX"], xp)
        y = self.LL.output(ll, vil)
        f = ctx.f
        f[..., self._sls[0]] = self.LG.deriv(lg, v)
        f[..., self._sls[1]] = self.LL.deriv(ll, vil)
        f[..., self._sls[2]] = self.LR.deriv(vr, y)
        f[..., self._sls[3]] = self.WF.deriv(wf, fb_in)
        put(xp, s["vf"], m, efd)
        ctx.out["EXST1.vi"], ctx.out["EXST1.vout"] = vi, efd
