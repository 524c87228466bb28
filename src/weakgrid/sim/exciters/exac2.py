"""EXAC2: IEEE type AC2 high-initial-response alternator-rectifier exciter (PSS/E EXAC2).

EXAC1 with a second regulator stage ``KB``, an exciter field-current feedback ``KH`` and a
field-current limiter ``KL (VLR - VFE)`` at a low-value gate. Block diagram (pu on the machine
base, times in s; PSS/E EXAC2 and ANDES names)::

    v --[Lag 1/(1+sTR)]--> LG
    vsen = LG if TR_used else v                           (TR_used = 0: ANDES 2.0)
    vi  = vref - vsen - VF + vs                           (vs: PSS output)
    vi  --[LeadLag (1+sTC)/(1+sTB)]--> LL
    LL  --[Lag KA/(1+sTA), non-windup VAMIN..VAMAX]--> VA
    VH  = VA - KH*VFE                                     (exciter field-current feedback)
    VL  = KL*(VLR - VFE)                                  (field-current limiter)
    VR  = clip(KB*min(VH, VL), VRMIN, VRMAX)
    VFE = KE*VE + VE*SE(VE) + KD*XadIfd
    TE dVE/dt = VR - VFE
    VFE --[Washout s*KF/(1+sTF)]--> VF                    (rate feedback)
    IN = KC*XadIfd/VE,  Efd = VE * FEX(IN)                (rectifier regulation)

``SE`` is the quadratic saturation through ``(E1, SE1)``, ``(E2, SE2)`` (``SE1 = 0``: none).
``TB = TC = 0`` pass the signal; ``TA = 0`` makes the regulator ``clip(KA*LL, VAMIN, VAMAX)``.

At initialization ``VE`` solves ``VE*FEX(KC*XadIfd/VE) = vf0``; ``VR = VFE``, the gate passes
``VH = VFE/KB``, so ``VA = VFE/KB + KH*VFE`` and ``vref = v + VA/KA``. The limiter must not hold
the gate (``KL*(VLR - VFE) >= VFE/KB``), else no steady state exists: refused naming ``VLR``.

Differences from ANDES 2.0 (documented, not copied): ANDES's EXAC2 takes the unfiltered voltage
at the summing junction as its EXAC1 does (``TR_used = 0`` reproduces it; ``from_andes(...,
conventions="andes")`` sets it); ANDES raises ``VLR`` at initialization to the value that opens the
limiter (its ``VLRx``), where weakgrid refuses the data; and ANDES sets ``vref = v + (KL*VFE +
VFE/KB)/KA`` (``KL`` where the diagram gives ``KH``), so it starts at rest only when ``KL = KH``.
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LagNonWindup, LeadLag, Washout, hard_limit
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param
from .dc_common import SATURATION_PARAMS, DCExciter
from .exac1 import _efd, ve_for_efd


class EXAC2(MachineControl):
    """IEEE AC2 exciter. Times [s]: TR, TB, TC, TA, TE, TF; gains [pu]: KA, KB, KL, KH, KF, KC, KD,
    KE; limits [pu, machine base]: VAMAX, VAMIN, VRMAX, VRMIN; VLR [pu] (field-current limit
    reference); E1, SE1, E2, SE2 (saturation)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    params = (
        Param("TR", 0.0, "s", "sensing time constant", "nonneg"),
        Param("TB", 0.0, "s", "lag time constant", "nonneg"),
        Param("TC", 0.0, "s", "lead time constant", "nonneg"),
        Param("KA", 400.0, "pu", "regulator gain", "pos"),
        Param("TA", 0.02, "s", "regulator time constant (0: no lag)", "nonneg"),
        Param("VAMAX", 8.0, "pu", "maximum regulator output", ""),
        Param("VAMIN", -8.0, "pu", "minimum regulator output", ""),
        Param("KB", 25.0, "pu", "second-stage regulator gain", "pos"),
        Param("VRMAX", 105.0, "pu", "maximum exciter field voltage", ""),
        Param("VRMIN", -95.0, "pu", "minimum exciter field voltage", ""),
        Param("TE", 0.6, "s", "exciter time constant", "pos"),
        Param("KL", 1.0, "pu", "field-current limiter gain", "nonneg"),
        Param("KH", 1.0, "pu", "exciter field-current feedback gain", "nonneg"),
        Param("KF", 0.03, "pu", "rate feedback gain", "nonneg"),
        Param("TF", 1.0, "s", "rate feedback time constant", "pos"),
        Param("KC", 0.28, "pu", "rectifier loading factor", "nonneg"),
        Param("KD", 0.35, "pu", "demagnetizing factor", "nonneg"),
        Param("KE", 1.0, "pu", "exciter constant", ""),
        Param("VLR", 4.4, "pu", "field-current limiter reference", ""),
        Param("TR_used", 1.0, "-", "1: the sensed voltage passes through TR (standard); "
              "0: the unfiltered voltage enters the summing junction (ANDES 2.0)", "flag"),
    ) + SATURATION_PARAMS
    states = ("LG", "LL", "VA", "VE", "VF")
    outputs = ("vi", "VH", "VL", "VR", "VFE", "vout")
    limit_fields = {"VA": ("VAMIN", "VAMAX")}
    #: PSS/E .dyr record after ``IBUS 'EXAC2' ID``: 23 CONs (PSS/E Model Library)
    psse_record = ("TR", "TB", "TC", "KA", "TA", "VAMAX", "VAMIN", "KB", "VRMAX", "VRMIN", "TE", "KL", "KH",
                   "KF", "TF", "KC", "KD", "KE", "VLR", "E1", "SE1", "E2", "SE2")

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.LG = Lag(1.0, p["TR"])
        self.LL = LeadLag(p["TC"], p["TB"])
        self.LA = LagNonWindup(p["KA"], p["TA"], p["VAMIN"], p["VAMAX"])
        self.EX = DCExciter(p["KE"], p["TE"], p["E1"], p["SE1"], p["E2"], p["SE2"])
        self.VF = Washout(p["KF"], p["TF"])
        self._lagged = p["TR_used"] > 0
        self._ta = p["TA"] > 0

    def limits(self):
        on = self._ta
        return [(self.idx("VA")[on], self.p["VAMIN"][on], self.p["VAMAX"][on])]

    def init(self, system, x, sig):
        p = self.p
        m = self.mach
        vf0, v, xad = sig["vf0"][m], sig["Ecomp0"][m], sig["XadIfd"][m]
        VE0 = ve_for_efd(vf0, p["KC"], xad)
        vfe0 = self.EX.vfe(VE0) + p["KD"] * xad
        VA0 = vfe0 / p["KB"] + p["KH"] * vfe0
        vi0 = VA0 / p["KA"]
        self.vref0 = v + vi0
        x[self.sl(0)] = self.LG.init(v)
        x[self.sl(1)] = self.LL.init(vi0)
        x[self.sl(2)] = VA0
        x[self.sl(3)] = VE0
        x[self.sl(4)] = self.VF.init(vfe0)
        kl = p["KL"]
        with np.errstate(divide="ignore", invalid="ignore"):
            vlr_needed = np.where(kl > 0, vfe0 + vfe0 / (p["KB"] * np.where(kl > 0, kl, 1.0)), np.inf)
        big = np.where(self._ta, np.inf, 0.0)
        inf = np.full(self.n, np.inf)
        self.initial_bounds = [
            ("VR", vfe0, p["VRMIN"], p["VRMAX"], "VRMIN", "VRMAX"),
            ("VA", VA0, p["VAMIN"] - big, p["VAMAX"] + big, "VAMIN", "VAMAX"),
            ("VLR needed at this operating point, VFE + VFE/(KB*KL)", vlr_needed, -inf, p["VLR"], "VLR", "VLR"),
        ]

    def compute(self, ctx):
        xp = self.xp
        p = self.p
        m = self._mi
        lg, ll, va, ve, vf = (ctx.x[..., s] for s in self._sls)
        s = ctx.sig
        v = take(xp, s["Ecomp"], m)
        xad = take(xp, s["XadIfd"], m)
        vfe = self.EX.vfe(ve) + p["KD"] * xad
        sensed = xp.where(self._lagged, self.LG.output(lg, v), v)
        vi = self.vref0 - sensed - self.VF.output(vf, vfe) + take(xp, s["vs"], m)
        y = self.LL.output(ll, vi)
        va_y = self.LA.output(va, y)
        vh = va_y - p["KH"] * vfe
        vl = p["KL"] * (p["VLR"] - vfe)
        vr = hard_limit(p["KB"] * xp.minimum(vh, vl), p["VRMIN"], p["VRMAX"], xp)
        efd = _efd(ve, p["KC"], xad, xp)
        f = ctx.f
        f[..., self._sls[0]] = self.LG.deriv(lg, v)
        f[..., self._sls[1]] = self.LL.deriv(ll, vi)
        f[..., self._sls[2]] = self.LA.deriv(va, y)
        f[..., self._sls[3]] = (vr - vfe) / p["TE"]
        f[..., self._sls[4]] = self.VF.deriv(vf, vfe)
        put(xp, s["vf"], m, efd)
        o = ctx.out
        o["EXAC2.vi"], o["EXAC2.VH"], o["EXAC2.VL"], o["EXAC2.VR"] = vi, vh, vl, vr
        o["EXAC2.VFE"], o["EXAC2.vout"] = vfe, efd
