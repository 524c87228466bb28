"""ESAC1A: IEEE 421.5-2005 type AC1A alternator-rectifier exciter (PSS/E ESAC1A).

Block diagram (pu, times in s)::

    v --[Lag 1/(1+sTR)]--> LG
    vi = vref - LG - VF + vs                              (vs: PSS output)
    vi --[LeadLag (1+sTC)/(1+sTB)]--> LL
    LL --[Lag KA/(1+sTA), non-windup VAMIN..VAMAX]--> VA
    VR = clip(VA, VRMIN, VRMAX)                           (after the UEL/OEL gates, absent here)
    VFE = KE*VE + VE*SE(VE) + KD*XadIfd                   (alternator demagnetization)
    TE dVE/dt = VR - VFE,  VE >= 0 (non-windup)
    VFE --[Washout s*KF/(1+sTF)]--> VF                    (rate feedback)
    IN = KC*XadIfd/VE,  Efd = VE * FEX(IN)                (rectifier regulation)

The saturation ``VE*SE(VE)`` is the quadratic curve through ``(E1, SE1)``, ``(E2, SE2)``
(``SE1 = 0`` disables it), as EXAC1 and the DC exciters. At initialization ``VE`` solves
``VE*FEX(KC*XadIfd/VE) = vf0`` and ``VA = VFE``; ``TB = TC = 0`` passes the signal, ``TR = 0``
removes the sensing lag, ``TA = 0`` makes the regulator the limited gain ``clip(KA*LL,
VAMIN, VAMAX)``. ``Switch`` is accepted and unused (as in PSS/E).

Differences from ANDES 2.0 (documented, not copied), each with a flag that reproduces ANDES
(set by ``from_andes(..., conventions="andes")``):

* ``VF_used = 0``: ANDES computes the rate feedback ``VF`` but does not subtract it at the
  summing junction (its ``vi`` has no ``VF`` term);
* ``VR_limited = 0``: ANDES applies neither the regulator output limits ``VRMIN``, ``VRMAX``
  nor the floor ``VE >= 0`` of the exciter integrator.
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LagNonWindup, LeadLag, Washout, hard_limit
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param
from .dc_common import SATURATION_PARAMS, DCExciter
from .exac1 import _efd, init_ac_exciter


class ESAC1A(MachineControl):
    """IEEE AC1A exciter.

    Times [s]: TR, TB, TC, TA, TE, TF; gains [pu]: KA, KF, KC, KD, KE; limits [pu]: VAMAX,
    VAMIN (regulator), VRMAX, VRMIN (exciter field voltage); E1, SE1, E2, SE2 (saturation of
    the exciter alternator). ``XadIfd`` is the field current in pu of the machine.
    """

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("TR", "TB", "TC", "KA", "TA", "VAMAX", "VAMIN", "TE", "KF", "TF", "KC", "KD",
                   "KE", "E1", "SE1", "E2", "SE2", "VRMAX", "VRMIN")
    params = (
        Param("TR", 0.01, "s", "sensing time constant", "nonneg"),
        Param("TB", 1.0, "s", "lag time constant", "nonneg"),
        Param("TC", 1.0, "s", "lead time constant", "nonneg"),
        Param("VAMAX", 999.0, "pu", "maximum regulator output", ""),
        Param("VAMIN", -999.0, "pu", "minimum regulator output", ""),
        Param("KA", 80.0, "pu", "regulator gain", "pos"),
        Param("TA", 0.04, "s", "regulator time constant (0: no lag)", "nonneg"),
        Param("VRMAX", 7.3, "pu", "maximum exciter field voltage", ""),
        Param("VRMIN", -7.3, "pu", "minimum exciter field voltage", ""),
        Param("TE", 0.8, "s", "exciter time constant", "pos"),
        Param("KD", 0.0, "pu", "demagnetizing factor", "nonneg"),
        Param("KC", 0.1, "pu", "rectifier loading factor", "nonneg"),
        Param("KE", 1.0, "pu", "exciter constant", ""),
        Param("KF", 0.1, "pu", "rate feedback gain", "nonneg"),
        Param("TF", 1.0, "s", "rate feedback time constant", "pos"),
        Param("Switch", 0.0, "-", "unused (PSS/E)", ""),
        Param("VF_used", 1.0, "-", "1: the rate feedback enters the summing junction (IEEE 421.5); "
              "0: it is left out (ANDES 2.0)", "flag"),
        Param("VR_limited", 1.0, "-", "1: VR clipped to VRMIN..VRMAX and VE >= 0 (IEEE 421.5); "
              "0: neither (ANDES 2.0)", "flag"),
    ) + SATURATION_PARAMS
    states = ("LG", "LL", "VA", "VE", "VF")
    outputs = ("vi", "VR", "VFE", "vout")
    limit_fields = {"VA": ("VAMIN", "VAMAX"), "VE": ("VE floor (0)", "none")}

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.LG = Lag(1.0, p["TR"])
        self.LL = LeadLag(p["TC"], p["TB"])
        self.LA = LagNonWindup(p["KA"], p["TA"], p["VAMIN"], p["VAMAX"])
        self.EX = DCExciter(p["KE"], p["TE"], p["E1"], p["SE1"], p["E2"], p["SE2"])
        self.VF = Washout(p["KF"], p["TF"])
        self._fb = p["VF_used"]
        lim = p["VR_limited"] > 0
        self._vrmin = np.where(lim, p["VRMIN"], -np.inf)
        self._vrmax = np.where(lim, p["VRMAX"], np.inf)
        self._vemin = np.where(lim, 0.0, -np.inf)

    def limits(self):
        p = self.p
        return [(self.idx("VA"), p["VAMIN"], p["VAMAX"]), (self.idx("VE"), self._vemin, np.inf)]

    def init(self, system, x, sig):
        init_ac_exciter(self, x, sig, self.VF)

    def compute(self, ctx):
        xp = self.xp
        p = self.p
        m = self._mi
        lg, ll, va, ve, vf = (ctx.x[..., s] for s in self._sls)
        s = ctx.sig
        v = take(xp, s["Ecomp"], m)
        xad = take(xp, s["XadIfd"], m)
        vfe = self.EX.vfe(ve) + p["KD"] * xad
        vi = self.vref0 - self.LG.output(lg, v) - self._fb * self.VF.output(vf, vfe) + take(xp, s["vs"], m)
        y = self.LL.output(ll, vi)
        vr = hard_limit(self.LA.output(va, y), self._vrmin, self._vrmax, xp)
        efd = _efd(ve, p["KC"], xad, xp)
        f = ctx.f
        f[..., self._sls[0]] = self.LG.deriv(lg, v)
        f[..., self._sls[1]] = self.LL.deriv(ll, vi)
        f[..., self._sls[2]] = self.LA.deriv(va, y)
        f[..., self._sls[3]] = (vr - vfe) / p["TE"]
        f[..., self._sls[4]] = self.VF.deriv(vf, vfe)
        put(xp, s["vf"], m, efd)
        o = ctx.out
        o["ESAC1A.vi"], o["ESAC1A.VR"], o["ESAC1A.VFE"], o["ESAC1A.vout"] = vi, vr, vfe, efd
