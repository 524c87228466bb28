"""EXDC2: IEEE type DC2 exciter (PSS/E EXDC2, ANDES conventions).

Block diagram (signals in pu, times in s)::

    v --[Lag 1/(1+sTR)]--> LS
    vi = vref - LS - W + vs                   (vs: PSS output, 0 without PSS)
    vi --[LeadLag (1+sTC)/(1+sTB)]--> LL
    LL --[Lag KA/(1+sTA), non-windup VRMIN..VRMAX]--> vr
    TE dvp/dt = vr - KE*vp - B*(vp - A)^2       (saturation active when omega*vp >= A)
    vp --[Washout s*KF1/(1+sTF1)]--> W        (rate feedback)
    vf = omega * vp

Saturation ``A, B`` from ``(E1, SE1)``, ``(E2, SE2)`` by
:func:`~weakgrid.sim.blocks.quad_saturation_coeffs`. ``vref`` is set at
initialization so that the initial field voltage is the machine's ``vf0``.
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LagNonWindup, LeadLag, Washout, quad_saturation, quad_saturation_coeffs
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param


class EXDC2(MachineControl):
    """IEEE DC2 exciter. Parameters: TR, TA, TC, TB, TE, TF1 [s]; KA, KE, KF1 [pu];
    VRMAX, VRMIN [pu]; E1, SE1, E2, SE2 (saturation) [pu]."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("TR", "KA", "TA", "TB", "TC", "VRMAX", "VRMIN", "KE", "TE", "KF1", "TF1",
                   "_SWITCH", "E1", "SE1", "E2", "SE2")

    @classmethod
    def psse_params(cls, values, ctx):
        """PSS/E EXDC2/IEEEX1: ``KF`` -> ``KF1``; ``SWITCH`` must be 0 (this model has no switch)."""
        from ..errors import DataError

        if values["_SWITCH"] != 0:
            raise DataError(ctx.where, "SWITCH", values["_SWITCH"],
                            f"{cls.__name__} is modelled with SWITCH = 0 only; set it to 0")
        return dict(values)

    params = (
        Param("TR", 0.01, "s", "sensing time constant", "nonneg"),
        Param("TA", 0.04, "s", "regulator time constant", "pos"),
        Param("TC", 1.0, "s", "lead time constant", "nonneg"),
        Param("TB", 1.0, "s", "lag time constant", "nonneg"),
        Param("TE", 0.8, "s", "exciter time constant", "pos"),
        Param("TF1", 1.0, "s", "rate feedback time constant", "pos"),
        Param("KF1", 0.03, "pu", "rate feedback gain", "nonneg"),
        Param("KA", 40.0, "pu", "regulator gain", "pos"),
        Param("KE", 1.0, "pu", "exciter constant", ""),
        Param("VRMAX", 7.3, "pu", "regulator upper limit", ""),
        Param("VRMIN", -7.3, "pu", "regulator lower limit", ""),
        Param("E1", 0.0, "pu", "first saturation point", "nonneg"),
        Param("SE1", 0.0, "pu", "saturation at E1", "nonneg"),
        Param("E2", 1.0, "pu", "second saturation point", "nonneg"),
        Param("SE2", 1.0, "pu", "saturation at E2", "nonneg"),
    )
    states = ("LS", "LL", "VR", "vp", "W")
    outputs = ("vi", "vref", "vout")
    #: the field voltage is the speed times the exciter voltage (EXDC2); IEEEX1 outputs vp
    speed_times_vp = True

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.LS = Lag(1.0, p["TR"])
        self.LL = LeadLag(p["TC"], p["TB"])
        self.LA = LagNonWindup(p["KA"], p["TA"], p["VRMIN"], p["VRMAX"])
        self.W = Washout(p["KF1"], p["TF1"])
        self.SA, self.SB = quad_saturation_coeffs(p["E1"], p["SE1"], p["E2"], p["SE2"])
        self._nosat = bool(np.all(self.SB == 0))
        self._keys = tuple(f"{self.type_name}.{o}" for o in self.outputs)

    #: parameter names of the limits of each limited state (for error messages)
    limit_fields = {"VR": ("VRMIN", "VRMAX")}

    def limits(self):
        return [(self.idx("VR"), self.p["VRMIN"], self.p["VRMAX"])]

    def init(self, system, x, sig):
        p = self.p
        vf0 = sig["vf0"][self.mach]
        v = sig["Ecomp0"][self.mach]
        with np.errstate(divide="ignore", invalid="ignore"):
            Se0 = np.where(vf0 > self.SA, self.SB * (self.SA - vf0) ** 2 / vf0, 0.0)
        vr0 = (p["KE"] + Se0) * vf0
        vb0 = vr0 / p["KA"]
        self.vref0 = v + vb0
        x[self.sl(0)] = self.LS.init(v)
        x[self.sl(1)] = self.LL.init(vb0)
        x[self.sl(2)] = vr0
        x[self.sl(3)] = vf0
        x[self.sl(4)] = self.W.init(vf0)

    def compute(self, ctx):
        xp, p, x, m, sls = self.xp, self.p, ctx.x, self._mi, self._sls
        ls, ll, vr, vp, w = x[..., sls[0]], x[..., sls[1]], x[..., sls[2]], x[..., sls[3]], x[..., sls[4]]
        v = take(xp, ctx.sig["Ecomp"], m)
        omega = take(xp, ctx.sig["omega"], m)
        W, dw = self.W.output_deriv(w, vp)
        vi = self.vref0 - self.LS.output(ls, v) - W + take(xp, ctx.sig["vs"], m)
        vll, dll = self.LL.output_deriv(ll, vi)
        vout = omega * vp if self.speed_times_vp else vp
        sat = 0.0 if self._nosat else xp.where(vout >= self.SA, quad_saturation(vp, self.SA, self.SB, xp),
                                               0.0)
        f = ctx.f
        f[..., self._sls[0]] = self.LS.deriv(ls, v)
        f[..., self._sls[1]] = dll
        f[..., self._sls[2]] = self.LA.deriv(vr, vll)
        f[..., self._sls[3]] = (vr - p["KE"] * vp - sat) / p["TE"]
        f[..., self._sls[4]] = dw
        put(xp, ctx.sig["vf"], m, vout)
        o = ctx.out
        k = self._keys
        o[k[0]], o[k[1]], o[k[2]] = vi, self.vref0 + 0 * vi, vout
