"""ESAC6A: IEEE 421.5 type AC6A alternator-rectifier exciter (PSS/E ESAC6A).

An AC exciter (alternator with a non-controlled rectifier) whose field is supplied by a
terminal-fed controlled rectifier: the regulator ceiling follows the terminal voltage, and an
exciter field-current limiter feeds back ahead of the exciter. Block diagram (pu on the machine
base, times in s; PSS/E ESAC6A names)::

    v --[Lag 1/(1+sTR)]--> LG
    vi  = vref - LG + vs                                        (vs: PSS output)
    KA*vi --[LeadLag (1+sTK)/(1+sTA), non-windup VAMIN..VAMAX]--> VA
    VA  --[LeadLag (1+sTC)/(1+sTB)]--> VR' ,  VR = clip(VR', Vt*VRMIN, Vt*VRMAX)
    VFE = KE*VE + VE*SE(VE) + KD*XadIfd                         (exciter field current)
    (VFE - VFELIM) --[KH (1+sTJ)/(1+sTH)]--> clip(., 0, VHMAX) = VH   (field-current limiter)
    TE dVE/dt = VR - VH - VFE,  VE >= 0 (non-windup)
    IN = KC*XadIfd/VE,  Efd = VE * FEX(IN)                      (rectifier regulation)

``SE`` is the quadratic saturation through ``(E1, SE1)``, ``(E2, SE2)`` (``SE1 = 0``: none), as in
the other AC exciters. The first block's state is held in ``VAMIN..VAMAX`` and its output
clipped there (with ``TK = 0`` it is the non-windup lag ``KA/(1+sTA)``); ``TA = 0`` makes it the
limited gain ``clip(KA*vi, VAMIN, VAMAX)``. ``TR = 0``, ``TB = TC = 0``, ``TH = TJ = 0`` pass their
signals.

At initialization ``VE`` solves ``VE*FEX(KC*XadIfd/VE) = vf0``; ``VH = clip(KH*(VFE - VFELIM), 0,
VHMAX)`` (the limiter may already conduct: a proportional feedback, still a steady state); ``VR =
VA = VFE + VH`` and ``vref = v + VA/KA``. ``VR`` outside ``Vt*VRMIN..Vt*VRMAX`` or ``VA`` outside
``VAMIN..VAMAX`` is refused at setup, naming the field.
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LeadLag, hard_limit
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param
from .dc_common import SATURATION_PARAMS, DCExciter
from .exac1 import _efd, ve_for_efd


class ESAC6A(MachineControl):
    """IEEE AC6A exciter. Times [s]: TR, TA, TK, TB, TC, TE, TH, TJ; gains [pu]: KA, KH, KC, KD,
    KE; limits [pu, machine base]: VAMAX, VAMIN, VRMAX, VRMIN (times Vt), VHMAX; VFELIM [pu]
    (field-current limiter reference); E1, SE1, E2, SE2 (exciter saturation)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    params = (
        Param("TR", 0.0, "s", "sensing time constant", "nonneg"),
        Param("KA", 536.0, "pu", "regulator gain", "pos"),
        Param("TA", 0.086, "s", "regulator lag time constant (0: static gain)", "nonneg"),
        Param("TK", 0.18, "s", "regulator lead time constant", "nonneg"),
        Param("TB", 9.0, "s", "lag time constant of the second lead-lag", "nonneg"),
        Param("TC", 3.0, "s", "lead time constant of the second lead-lag", "nonneg"),
        Param("VAMAX", 75.0, "pu", "maximum regulator output", ""),
        Param("VAMIN", -75.0, "pu", "minimum regulator output", ""),
        Param("VRMAX", 44.0, "pu", "maximum exciter field voltage (times Vt)", ""),
        Param("VRMIN", -36.0, "pu", "minimum exciter field voltage (times Vt)", ""),
        Param("TE", 1.0, "s", "exciter time constant", "pos"),
        Param("VFELIM", 19.0, "pu", "exciter field-current limiter reference", ""),
        Param("KH", 92.0, "pu", "exciter field-current limiter gain", "nonneg"),
        Param("VHMAX", 75.0, "pu", "maximum field-current limiter output", ""),
        Param("TH", 0.08, "s", "field-current limiter lag time constant", "nonneg"),
        Param("TJ", 0.02, "s", "field-current limiter lead time constant", "nonneg"),
        Param("KC", 0.173, "pu", "rectifier loading factor", "nonneg"),
        Param("KD", 1.91, "pu", "demagnetizing factor", "nonneg"),
        Param("KE", 1.6, "pu", "exciter constant", ""),
    ) + SATURATION_PARAMS
    states = ("LG", "LA", "LL", "VE", "LH")
    outputs = ("vi", "VA", "VR", "VFE", "VH", "vout")
    limit_fields = {"LA": ("VAMIN", "VAMAX"), "VE": ("VE floor (0)", "none")}
    #: PSS/E .dyr record after ``IBUS 'ESAC6A' ID``: 23 CONs (PSS/E Model Library)
    psse_record = ("TR", "KA", "TA", "TK", "TB", "TC", "VAMAX", "VAMIN", "VRMAX", "VRMIN", "TE", "VFELIM",
                   "KH", "VHMAX", "TH", "TJ", "KC", "KD", "KE", "E1", "SE1", "E2", "SE2")

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.LG = Lag(1.0, p["TR"])
        self.LA = LeadLag(p["TK"], p["TA"])                # (1+sTK)/(1+sTA) on KA*vi
        self.LL = LeadLag(p["TC"], p["TB"])
        self.LH = LeadLag(p["TJ"], p["TH"], p["KH"])       # KH (1+sTJ)/(1+sTH)
        self.EX = DCExciter(p["KE"], p["TE"], p["E1"], p["SE1"], p["E2"], p["SE2"])
        self._ta = p["TA"] > 0

    def limits(self):
        p = self.p
        inf = np.full(self.n, np.inf)
        # the lead-lag state x obeys TA dx/dt = KA*vi - x (output (TK/TA)(KA*vi - x) + x): held in
        # VAMIN..VAMAX
        on = self._ta
        return [(self.idx("LA")[on], p["VAMIN"][on], p["VAMAX"][on]),
                (self.idx("VE"), np.zeros(self.n), inf)]

    def _vh(self, lh, vfe):
        return hard_limit(self.LH.output(lh, vfe - self.p["VFELIM"]), 0.0, self.p["VHMAX"], self.xp)

    def init(self, system, x, sig):
        p = self.p
        m = self.mach
        vf0, v, vt, xad = sig["vf0"][m], sig["Ecomp0"][m], sig["Vt0"][m], sig["XadIfd"][m]
        VE0 = ve_for_efd(vf0, p["KC"], xad)
        vfe0 = self.EX.vfe(VE0) + p["KD"] * xad
        u_h = vfe0 - p["VFELIM"]
        VH0 = hard_limit(p["KH"] * u_h, 0.0, p["VHMAX"])
        VA0 = vfe0 + VH0
        vi0 = VA0 / p["KA"]
        self.vref0 = v + vi0
        x[self.sl(0)] = self.LG.init(v)
        x[self.sl(1)] = self.LA.init(VA0)
        x[self.sl(2)] = self.LL.init(VA0)
        x[self.sl(3)] = VE0
        x[self.sl(4)] = self.LH.init(u_h)
        big = np.where(self._ta, np.inf, 0.0)        # TA = 0: the static gain is clipped
        self.initial_bounds = [("VR", VA0, vt * p["VRMIN"], vt * p["VRMAX"], "Vt*VRMIN", "Vt*VRMAX"),
                               ("VA", VA0, p["VAMIN"] - big, p["VAMAX"] + big, "VAMIN", "VAMAX")]

    def compute(self, ctx):
        xp = self.xp
        p = self.p
        m = self._mi
        lg, la, ll, ve, lh = (ctx.x[..., s] for s in self._sls)
        s = ctx.sig
        v = take(xp, s["Ecomp"], m)
        vt = take(xp, s["Vt"], m)
        xad = take(xp, s["XadIfd"], m)
        vi = self.vref0 - self.LG.output(lg, v) + take(xp, s["vs"], m)
        ka_vi = p["KA"] * vi
        va = hard_limit(self.LA.output(la, ka_vi), p["VAMIN"], p["VAMAX"], xp)
        vr = hard_limit(self.LL.output(ll, va), vt * p["VRMIN"], vt * p["VRMAX"], xp)
        vfe = self.EX.vfe(ve) + p["KD"] * xad
        vh = self._vh(lh, vfe)
        efd = _efd(ve, p["KC"], xad, xp)
        f = ctx.f
        f[..., self._sls[0]] = self.LG.deriv(lg, v)
        f[..., self._sls[1]] = self.LA.deriv(la, ka_vi)
        f[..., self._sls[2]] = self.LL.deriv(ll, va)
        f[..., self._sls[3]] = (vr - vh - vfe) / p["TE"]
        f[..., self._sls[4]] = self.LH.deriv(lh, vfe - p["VFELIM"])
        put(xp, s["vf"], m, efd)
        o = ctx.out
        o["ESAC6A.vi"], o["ESAC6A.VA"], o["ESAC6A.VR"] = vi, va, vr
        o["ESAC6A.VFE"], o["ESAC6A.VH"], o["ESAC6A.vout"] = vfe, vh, efd
