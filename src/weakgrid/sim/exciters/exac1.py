"""EXAC1: IEEE type AC1 alternator-rectifier exciter (PSS/E EXAC1).

Block diagram (pu, times in s)::

    v --[Lag 1/(1+sTR)]--> LG
    vsen = LG if TR_used else v                           (sensed voltage; TR_used = 0: ANDES 2.0)
    vi = vref - vsen - WF + vs                            (vs: PSS output)
    vi --[LeadLag (1+sTC)/(1+sTB)]--> LL
    LL --[Lag KA/(1+sTA), non-windup VRMIN..VRMAX]--> VR
    VFE = KE*VE + VE*SE(VE) + KD*XadIfd                   (alternator demagnetization)
    TE dVE/dt = VR - VFE
    VFE --[Washout s*KF/(1+sTF)]--> WF                    (rate feedback)
    IN = KC*XadIfd/VE,  Efd = VE * FEX(IN)                (rectifier regulation)

At initialization ``VE`` solves ``VE*FEX(KC*XadIfd/VE) = vf0`` (monotone in
``VE``; solved by bisection).

Difference from ANDES 2.0 (documented, not copied): ANDES feeds the unfiltered
bus voltage to the summing junction (its ``TR`` lag is computed but unused); here the
sensed voltage passes through ``TR`` as in the standard. They agree for ``TR = 0``.
The flag ``TR_used = 0`` reproduces ANDES (the lag state stays, its output unused); the
ANDES importer sets it with ``from_andes(..., conventions="andes")``. Effect on ANDES's
``ieee14_exac1`` (census fault): 2.0e-5 pu of speed / 0.15 deg with the standard,
1.2e-5 pu / 0.034 deg with ``TR_used = 0`` (the gap of ANDES's ieee14 base case).
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LagNonWindup, LeadLag, Washout, rectifier_fex
from ..control_base import MachineControl
from ..namespace import NUMPY, put, take
from ..params import Param
from .dc_common import SATURATION_PARAMS, DCExciter


def _efd(VE, KC, XadIfd, xp=NUMPY):
    """Rectifier output ``VE * FEX(KC*XadIfd/VE)`` of an AC exciter [pu] (``xp``: the arrays'
    namespace; ``VE`` is kept off 0 where ``IN`` is not used)."""
    on = VE > 0
    IN = xp.where(on, KC * XadIfd / xp.where(on, VE, 1.0), 0.0)
    return VE * rectifier_fex(IN, xp)


def ve_for_efd(vf0, KC, XadIfd):
    """Exciter voltage ``VE`` with ``VE*FEX(KC*XadIfd/VE) = vf0`` [pu] (bisection; the left side
    increases with ``VE``). Shared by the AC exciters (EXAC1, ESAC1A)."""
    lo = np.asarray(vf0, float).copy()                 # Efd <= VE
    hi = vf0 + 2.0 * KC * np.abs(XadIfd) + 1.0          # FEX = 0 beyond IN = 1
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        below = _efd(mid, KC, XadIfd) < vf0
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return 0.5 * (lo + hi)


def init_ac_exciter(c, x, sig, feedback):
    """Steady state of an AC exciter with states ``(LG, LL, regulator, VE, rate feedback)``
    (EXAC1, ESAC1A): ``VE`` from the field voltage, the regulator at ``VFE = KE VE + SE + KD
    XadIfd``, the voltage reference from the input error ``VFE / KA``."""
    p, m = c.p, c.mach
    vf0, v, xad = sig["vf0"][m], sig["Ecomp0"][m], sig["XadIfd"][m]
    VE0 = ve_for_efd(vf0, p["KC"], xad)
    vfe0 = c.EX.vfe(VE0) + p["KD"] * xad
    vi0 = vfe0 / p["KA"]
    c.vref0 = v + vi0
    x[c.sl(0)] = c.LG.init(v)
    x[c.sl(1)] = c.LL.init(vi0)
    x[c.sl(2)] = vfe0
    x[c.sl(3)] = VE0
    x[c.sl(4)] = feedback.init(vfe0)


class EXAC1(MachineControl):
    """IEEE AC1 exciter. Times [s]: TR, TB, TC, TA, TE, TF; gains [pu]: KA, KF, KC, KD, KE;
    VRMAX, VRMIN [pu]; E1, SE1, E2, SE2 (saturation)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("TR", "TB", "TC", "KA", "TA", "VRMAX", "VRMIN", "TE", "KF", "TF", "KC", "KD",
                   "KE", "E1", "SE1", "E2", "SE2")
    params = (
        Param("TR", 0.01, "s", "sensing time constant", "nonneg"),
        Param("TB", 1.0, "s", "lag time constant", "nonneg"),
        Param("TC", 1.0, "s", "lead time constant", "nonneg"),
        Param("KA", 80.0, "pu", "regulator gain", "pos"),
        Param("TA", 0.04, "s", "regulator time constant", "pos"),
        Param("VRMAX", 8.0, "pu", "maximum regulator output", ""),
        Param("VRMIN", 0.0, "pu", "minimum regulator output", ""),
        Param("TE", 0.8, "s", "exciter time constant", "pos"),
        Param("KF", 0.1, "pu", "rate feedback gain", "nonneg"),
        Param("TF", 1.0, "s", "rate feedback time constant", "pos"),
        Param("KC", 0.1, "pu", "rectifier loading factor", "nonneg"),
        Param("KD", 0.0, "pu", "demagnetizing factor", "nonneg"),
        Param("KE", 1.0, "pu", "exciter constant", ""),
        Param("TR_used", 1.0, "-", "1: the sensed voltage passes through TR (IEEE 421.5); "
              "0: the unfiltered voltage enters the summing junction (ANDES 2.0)", "flag"),
    ) + SATURATION_PARAMS
    states = ("LG", "LL", "VR", "VE", "WF")
    outputs = ("vi", "VFE", "vout")

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.LG = Lag(1.0, p["TR"])
        self.LL = LeadLag(p["TC"], p["TB"])
        self.LA = LagNonWindup(p["KA"], p["TA"], p["VRMIN"], p["VRMAX"])
        self.EX = DCExciter(p["KE"], p["TE"], p["E1"], p["SE1"], p["E2"], p["SE2"])
        self.WF = Washout(p["KF"], p["TF"])
        self._lagged = p["TR_used"] > 0

    def limits(self):
        return [(self.idx("VR"), self.p["VRMIN"], self.p["VRMAX"])]

    def init(self, system, x, sig):
        init_ac_exciter(self, x, sig, self.WF)

    def compute(self, ctx):
        xp = self.xp
        p = self.p
        m = self._mi
        lg, ll, vr, ve, wf = (ctx.x[..., s] for s in self._sls)
        s = ctx.sig
        v = take(xp, s["Ecomp"], m)
        xad = take(xp, s["XadIfd"], m)
        vfe = self.EX.vfe(ve) + p["KD"] * xad
        sensed = xp.where(self._lagged, self.LG.output(lg, v), v)
        vi = self.vref0 - sensed - self.WF.output(wf, vfe) + take(xp, s["vs"], m)
        efd = _efd(ve, p["KC"], xad, xp)
        f = ctx.f
        f[..., self._sls[0]] = self.LG.deriv(lg, v)
        f[..., self._sls[1]] = self.LL.deriv(ll, vi)
        f[..., self._sls[2]] = self.LA.deriv(vr, self.LL.output(ll, vi))
        f[..., self._sls[3]] = (vr - vfe) / p["TE"]
        f[..., self._sls[4]] = self.WF.deriv(wf, vfe)
        put(xp, s["vf"], m, efd)
        o = ctx.out
        o["EXAC1.vi"], o["EXAC1.VFE"], o["EXAC1.vout"] = vi, vfe, efd
