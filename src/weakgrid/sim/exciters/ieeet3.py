"""IEEET3: IEEE (1968) type 3 static compound-source exciter (PSS/E IEEET3).

Block diagram (pu, times in s)::

    v --[Lag 1/(1+sTR)]--> LG
    vi = vref - LG + vs                                   (vs: PSS output)
    (vi - VF) --[Lag KA/(1+sTA), non-windup VRMIN..VRMAX]--> VR
    VE = |KP*Vt + j*KI*It|                                (potential + current source)
    VB = sqrt(VE^2 - (0.78*XadIfd)^2), 0 where negative   (= VE*sqrt(1 - A^2), A = 0.78*XadIfd/VE)
    TE dEfd/dt = clip(VR + VB, 0, VBMAX) - KE*Efd         (exciter 1/(KE + sTE))
    Efd --[Washout s*KF/(1+sTF)]--> VF                    (rate feedback)

``Vt``, ``It`` are the terminal voltage and current phasors on the system base (the magnitude
``VE`` does not depend on the reference frame), ``XadIfd`` the field current in pu of the
machine. ``VRMAX = 0`` means no upper regulator limit; ``TR = 0`` removes the sensing lag;
``TA = 0`` makes the regulator the limited gain ``clip(KA*(vi - VF), VRMIN, VRMAX)``. At
initialization ``VR = KE*vf0 - VB`` (and ``0 <= KE*vf0 <= VBMAX``).

ANDES 2.0's IEEET3 follows the same diagram (no departure found).
"""

from __future__ import annotations

from ..blocks import Lag, LagNonWindup, Washout, hard_limit
from ..control_base import MachineControl
from ..namespace import NUMPY, put, take
from ..params import Param
from .dc_common import vrmax_or_unlimited
from .esst3a import source_voltage, source_voltage0


class IEEET3(MachineControl):
    """IEEE type 3 exciter. Times [s]: TR, TA, TE, TF; gains [pu]: KA, KE, KF, KP, KI;
    limits [pu]: VRMAX, VRMIN (regulator), VBMAX (exciter input)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    params = (
        Param("TR", 0.02, "s", "sensing time constant", "nonneg"),
        Param("KA", 5.0, "pu", "regulator gain", "pos"),
        Param("TA", 0.04, "s", "regulator time constant (0: no lag)", "nonneg"),
        Param("VRMAX", 7.3, "pu", "maximum regulator output (0: unlimited)", ""),
        Param("VRMIN", -7.3, "pu", "minimum regulator output", ""),
        Param("VBMAX", 18.0, "pu", "maximum exciter input VR + VB", ""),
        Param("KE", 1.0, "pu", "exciter constant", ""),
        Param("TE", 1.0, "s", "exciter time constant", "pos"),
        Param("KF", 0.1, "pu", "rate feedback gain", "nonneg"),
        Param("TF", 1.0, "s", "rate feedback time constant", "pos"),
        Param("KP", 4.0, "pu", "potential circuit gain", "nonneg"),
        Param("KI", 0.1, "pu", "current circuit gain", "nonneg"),
    )
    states = ("LG", "VR", "Efd", "VF")
    outputs = ("vi", "VE", "VB", "vout")
    limit_fields = {"VR": ("VRMIN", "VRMAX")}

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.LG = Lag(1.0, p["TR"])
        self._vrmax = vrmax_or_unlimited(p["VRMAX"])
        self.LA = LagNonWindup(p["KA"], p["TA"], p["VRMIN"], self._vrmax)
        self.VF = Washout(p["KF"], p["TF"])

    def limits(self):
        return [(self.idx("VR"), self.p["VRMIN"], self._vrmax)]

    @staticmethod
    def _vb(VE, xad, xp=NUMPY):
        """Rectified compound-source voltage ``sqrt(max(VE^2 - (0.78*XadIfd)^2, 0))`` [pu]."""
        return xp.sqrt(xp.maximum(VE * VE - (0.78 * xad) ** 2, 0.0))

    def init(self, system, x, sig):
        p = self.p
        m = self.mach
        vf0, v = sig["vf0"][m], sig["Ecomp0"][m]
        VB0 = self._vb(source_voltage0(sig, m, p["KP"], p["KI"], 0.0), sig["XadIfd"][m])
        VR0 = p["KE"] * vf0 - VB0
        self.vref0 = v + VR0 / p["KA"]
        x[self.sl(0)] = self.LG.init(v)
        x[self.sl(1)] = VR0
        x[self.sl(2)] = vf0
        x[self.sl(3)] = self.VF.init(vf0)

    def compute(self, ctx):
        xp, p = self.xp, self.p
        m = self._mi
        lg, vr, efd, vf = (ctx.x[..., s] for s in self._sls)
        s = ctx.sig
        v = take(xp, s["Ecomp"], m)
        vi = self.vref0 - self.LG.output(lg, v) + take(xp, s["vs"], m)
        u = vi - self.VF.output(vf, efd)
        VE = source_voltage(ctx, self.mach, self.bus, p["KP"], p["KI"], 0.0, xp)
        VB = self._vb(VE, take(xp, s["XadIfd"], m), xp)
        vx = hard_limit(self.LA.output(vr, u) + VB, 0.0, p["VBMAX"], xp)
        f = ctx.f
        f[..., self._sls[0]] = self.LG.deriv(lg, v)
        f[..., self._sls[1]] = self.LA.deriv(vr, u)
        f[..., self._sls[2]] = (vx - p["KE"] * efd) / p["TE"]
        f[..., self._sls[3]] = self.VF.deriv(vf, efd)
        put(xp, s["vf"], m, efd)
        o = ctx.out
        o["IEEET3.vi"], o["IEEET3.VE"], o["IEEET3.VB"], o["IEEET3.vout"] = vi, VE, VB, efd
