"""ESST1A: IEEE 421.5-2005 type ST1A potential-source controlled-rectifier exciter (PSS/E ESST1A).

Block diagram (pu, times in s)::

    v --[Lag 1/(1+sTR)]--> LG
    vi  = vref - LG - VF + vs*(VOSc == 1)                  (vs: PSS output at the summing junction)
    vil = clip(vi, VIMIN, VIMAX)
    vil --[LeadLag (1+sTC)/(1+sTB)]--> LL --[LeadLag (1+sTC1)/(1+sTB1)]--> LL1
    LL1 --[Lag KA/(1+sTA), non-windup VAMIN..VAMAX]--> VA
    ILR_out = max(KLR*(XadIfd - ILR), 0)                   (field-current limiter)
    vas = VA + vs*(VOSc == 2) - ILR_out                    (PSS at the regulator output)
    Efd = clip(vas, Vt*VRMIN, Vt*VRMAX - KC*XadIfd)        (output limits follow Vt and the field current)
    vas --[Washout s*KF/(1+sTF)]--> VF                     (rate feedback, before the output limiter)

``Vt`` is the terminal-voltage magnitude (unfiltered) and ``XadIfd`` the field current, both in
pu of the machine. No under-/over-excitation limiter (the gates' UEL/OEL inputs are absent,
``UELc`` is accepted and unused, as in ANDES). ``TB = TC = 0`` (and ``TB1 = TC1 = 0``) pass the
signal; ``TA = 0`` makes the regulator the limited gain ``clip(KA*LL1, VAMIN, VAMAX)``;
``TR = 0`` removes the sensing lag; ``TF = 0`` removes the rate feedback (as ANDES).

At initialization ``VA = vf0 + ILR_out`` and ``vref = Vt + VA/KA`` (``vs = 0``).

Difference from ANDES 2.0 (documented, not copied): ANDES always adds the PSS output at the
summing junction (its ``VOSc = 2`` path is a constant zero). ``from_andes(...,
conventions="andes")`` reproduces it by setting ``VOSc = 1``. They agree for ``VOSc = 1``
(ANDES's ``ieee14_esst1a``). The rate feedback takes the signal ahead of the output limiter in
both (PSS/E's diagram).
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LagNonWindup, LeadLag, Washout, hard_limit
from ..control_base import MachineControl
from ..errors import DataError
from ..namespace import put, take
from ..params import Param


class ESST1A(MachineControl):
    """IEEE ST1A static exciter.

    Times [s]: TR, TB, TC, TB1, TC1, TA, TF; gains [pu]: KA, KF, KC, KLR; limits [pu]:
    VIMAX, VIMIN (input error), VAMAX, VAMIN (regulator), VRMAX, VRMIN (output, times Vt);
    ILR [pu field current, machine base]; UELc, VOSc: input codes (PSS/E).
    """

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("UELc", "VOSc", "TR", "VIMAX", "VIMIN", "TC", "TB", "TC1", "TB1", "KA", "TA",
                   "VAMAX", "VAMIN", "VRMAX", "VRMIN", "KC", "KF", "TF", "KLR", "ILR")
    params = (
        Param("TR", 0.01, "s", "sensing time constant", "nonneg"),
        Param("VIMAX", 0.8, "pu", "maximum input error", ""),
        Param("VIMIN", -0.1, "pu", "minimum input error", ""),
        Param("TB", 1.0, "s", "lag time constant of the first lead-lag", "nonneg"),
        Param("TC", 1.0, "s", "lead time constant of the first lead-lag", "nonneg"),
        Param("TB1", 1.0, "s", "lag time constant of the second lead-lag", "nonneg"),
        Param("TC1", 1.0, "s", "lead time constant of the second lead-lag", "nonneg"),
        Param("VAMAX", 999.0, "pu", "maximum regulator output", ""),
        Param("VAMIN", -999.0, "pu", "minimum regulator output", ""),
        Param("KA", 80.0, "pu", "regulator gain", "pos"),
        Param("TA", 0.04, "s", "regulator time constant (0: no lag)", "nonneg"),
        Param("ILR", 1.0, "pu", "field-current limit reference", ""),
        Param("KLR", 1.0, "pu", "field-current limiter gain", "nonneg"),
        Param("VRMAX", 7.3, "pu", "maximum output at Vt = 1 (before KC*XadIfd)", ""),
        Param("VRMIN", -7.3, "pu", "minimum output at Vt = 1", ""),
        Param("KF", 0.1, "pu", "rate feedback gain", "nonneg"),
        Param("TF", 1.0, "s", "rate feedback time constant (0: no feedback)", "nonneg"),
        Param("KC", 0.1, "pu", "rectifier loading factor", "nonneg"),
        Param("UELc", 1.0, "-", "UEL input code (1-3; no UEL modelled)", ""),
        Param("VOSc", 1.0, "-", "PSS input code: 1 summing junction, 2 regulator output", ""),
    )
    states = ("LG", "LL", "LL1", "VA", "VF")
    outputs = ("vi", "vas", "vout")
    limit_fields = {"VA": ("VAMIN", "VAMAX")}

    def setup(self, system):
        super().setup(system)
        p = self.p
        for k, v in enumerate(p["VOSc"]):
            if v not in (1.0, 2.0):
                raise DataError(self.element(k), "VOSc", float(v),
                                "1 (PSS output at the summing junction) or 2 (at the regulator output)")
        loop = (p["TA"] == 0) & (p["KF"] > 0) & (p["TF"] > 0)
        if np.any(loop):
            k = int(np.nonzero(loop)[0][0])
            raise DataError(self.element(k), "TA", 0.0,
                            "TA = 0 with an active rate feedback (KF > 0, TF > 0) closes an algebraic "
                            "loop; give TA > 0 (e.g. 0.01 s) or KF = 0")
        self.LG = Lag(1.0, p["TR"])
        self.LL = LeadLag(p["TC"], p["TB"])
        self.LL1 = LeadLag(p["TC1"], p["TB1"])
        self.LA = LagNonWindup(p["KA"], p["TA"], p["VAMIN"], p["VAMAX"])
        self.VF = Washout(p["KF"], p["TF"])
        self._vs_in = p["VOSc"] == 1.0

    def limits(self):
        return [(self.idx("VA"), self.p["VAMIN"], self.p["VAMAX"])]

    def _ilr(self, xad):
        """Field-current limiter output ``max(KLR*(XadIfd - ILR), 0)`` [pu]."""
        return self.xp.maximum(self.p["KLR"] * (xad - self.p["ILR"]), 0.0)

    def init(self, system, x, sig):
        m = self.mach
        vf0, v = sig["vf0"][m], sig["Ecomp0"][m]
        VA0 = vf0 + self._ilr(sig["XadIfd"][m])
        vi0 = VA0 / self.p["KA"]
        self.vref0 = v + vi0
        x[self.sl(0)] = self.LG.init(v)
        x[self.sl(1)] = self.LL.init(vi0)
        x[self.sl(2)] = self.LL1.init(vi0)
        x[self.sl(3)] = VA0
        x[self.sl(4)] = self.VF.init(vf0)

    def compute(self, ctx):
        xp = self.xp
        p = self.p
        m = self._mi
        lg, ll, ll1, va, vf = (ctx.x[..., s] for s in self._sls)
        s = ctx.sig
        v = take(xp, s["Ecomp"], m)
        xad = take(xp, s["XadIfd"], m)
        vs = take(xp, s["vs"], m)
        ilr = self._ilr(xad)
        vs2 = xp.where(self._vs_in, 0.0, vs)
        # rate feedback from the regulator state (setup() refuses TA = 0 with an active feedback,
        # an algebraic loop; where TA = 0 the feedback output is zero)
        vas_fb = va + vs2 - ilr
        vi = self.vref0 - self.LG.output(lg, v) - self.VF.output(vf, vas_fb) + xp.where(self._vs_in, vs, 0.0)
        vil = hard_limit(vi, p["VIMIN"], p["VIMAX"], xp)
        y1 = self.LL.output(ll, vil)
        y2 = self.LL1.output(ll1, y1)
        vas = self.LA.output(va, y2) + vs2 - ilr          # = vas_fb unless TA = 0
        efd = hard_limit(vas, v * p["VRMIN"], v * p["VRMAX"] - p["KC"] * xad, xp)
        f = ctx.f
        f[..., self._sls[0]] = self.LG.deriv(lg, v)
        f[..., self._sls[1]] = self.LL.deriv(ll, vil)
        f[..., self._sls[2]] = self.LL1.deriv(ll1, y1)
        f[..., self._sls[3]] = self.LA.deriv(va, y2)
        f[..., self._sls[4]] = self.VF.deriv(vf, vas)
        put(xp, s["vf"], m, efd)
        o = ctx.out
        o["ESST1A.vi"], o["ESST1A.vas"], o["ESST1A.vout"] = vi, vas, efd
