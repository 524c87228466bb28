"""EXPIC1: proportional/integral excitation system (PSS/E EXPIC1).

A PI voltage regulator, a regulator filter, a rate feedback from the regulator output, a
potential/compound source multiplying the regulator output, and an exciter with saturation.
Block diagram (pu on the machine base, times in s; PSS/E EXPIC1 names)::

    v --[Lag 1/(1+sTR)]--> LG
    ev  = vref - LG - VF + vs                                   (vs: PSS output)
    ev  --[PI KA (1+sTA1)/s = KA*TA1 + KA/s, non-windup VR2..VR1]--> VA
    VA  --[Lag 1/(1+sTA2)]--> X1 --[LeadLag (1+sTA3)/(1+sTA4)]--> VR' ,  VR = clip(VR', VRMIN, VRMAX)
    VR  --[Lag 1/(1+sTF1)]--> VF1 ,  VF = s*KF/(1+sTF2) VF1      (rate feedback sKF/((1+sTF1)(1+sTF2)))
    VE  = |KP*Vt + j*KI*It|,  VB = VE * FEX(KC*XadIfd/VE)       (VB = 1 if KP = KI = 0)
    E0  = clip(VB*VR, EFDMIN, EFDMAX)
    TE dEfd/dt = E0 - (KE*Efd + Efd*SE(Efd))                   (TE = 0: Efd = E0)

``Vt``, ``It`` are the terminal voltage and current phasors in pu of the machine, ``XadIfd`` the
field current; ``SE`` is the quadratic saturation through ``(E1, SE1)``, ``(E2, SE2)`` (``SE1 =
0``: none), as in the DC exciters. ``TR``, ``TA2``, ``TA4`` equal to zero pass their signals; a
rate feedback (``KF > 0``) needs ``TF1 > 0`` (PowerWorld raises a zero ``TF1`` to the step). The
structure follows the PSS/E/PowerWorld EXPIC1 diagram as transcribed by GridKit's model notes
(ORNL, read for reference); the PI's lead ``TA1`` and the limits VRMAX/VRMIN on the regulator
output are in the PowerWorld parameter list.

At initialization ``E0 = KE*vf0 + vf0*SE(vf0)`` (``vf0`` if ``TE = 0``), ``VR = VA = E0/VB``, the
feedback at rest (``VF = 0``) and zero voltage error (``vref = v``, the PI integrator at ``VA``).
``VA`` outside ``VR2..VR1``, ``VR`` outside ``VRMIN..VRMAX`` or ``E0`` outside ``EFDMIN..EFDMAX``
is refused at setup naming the field; so is a source with no voltage (``VB = 0``, naming ``KP``).
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LeadLag, PINonWindup, hard_limit, rectifier_fex
from ..control_base import MachineControl
from ..errors import DataError
from ..namespace import NUMPY, put, take
from ..params import Param
from .dc_common import SATURATION_PARAMS, DCExciter


class EXPIC1(MachineControl):
    """Proportional/integral exciter. Times [s]: TR, TA1, TA2, TA3, TA4, TF1, TF2, TE; gains: KA
    [1/s], KF, KE, KP, KI, KC [pu]; limits [pu, machine base]: VR1, VR2 (PI), VRMAX, VRMIN
    (regulator), EFDMAX, EFDMIN (exciter input); E1, SE1, E2, SE2 (exciter saturation)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    params = (
        Param("TR", 0.0, "s", "sensing time constant", "nonneg"),
        Param("KA", 1.0, "1/s", "PI regulator (integral) gain", "pos"),
        Param("TA1", 0.0, "s", "PI lead time constant (proportional gain KA*TA1)", "nonneg"),
        Param("VR1", 1.0, "pu", "PI maximum output", ""),
        Param("VR2", -1.0, "pu", "PI minimum output", ""),
        Param("TA2", 0.0, "s", "regulator filter lag time constant", "nonneg"),
        Param("TA3", 0.0, "s", "regulator filter lead time constant", "nonneg"),
        Param("TA4", 0.0, "s", "regulator filter second lag time constant", "nonneg"),
        Param("VRMAX", 1.0, "pu", "maximum regulator output", ""),
        Param("VRMIN", -1.0, "pu", "minimum regulator output", ""),
        Param("KF", 0.0, "pu", "rate feedback gain", "nonneg"),
        Param("TF1", 1.0, "s", "rate feedback first time constant", "nonneg"),
        Param("TF2", 0.0, "s", "rate feedback second time constant", "nonneg"),
        Param("EFDMAX", 5.0, "pu", "maximum exciter input", ""),
        Param("EFDMIN", -5.0, "pu", "minimum exciter input", ""),
        Param("KE", 1.0, "pu", "exciter constant", ""),
        Param("TE", 0.5, "s", "exciter time constant (0: Efd = E0)", "nonneg"),
        Param("KP", 0.0, "pu", "potential source gain (KP = KI = 0: VB = 1)", "nonneg"),
        Param("KI", 0.0, "pu", "current source gain", "nonneg"),
        Param("KC", 0.0, "pu", "rectifier loading factor", "nonneg"),
    ) + SATURATION_PARAMS
    states = ("LG", "PI", "X1", "LL", "VF1", "VF", "EFD")
    outputs = ("ev", "VA", "VR", "VB", "E0", "vout")
    limit_fields = {"PI": ("VR2", "VR1")}
    #: PSS/E .dyr record after ``IBUS 'EXPIC1' ID``: 24 CONs (PSS/E Model Library)
    psse_record = ("TR", "KA", "TA1", "VR1", "VR2", "TA2", "TA3", "TA4", "VRMAX", "VRMIN", "KF", "TF1", "TF2",
                   "EFDMAX", "EFDMIN", "KE", "TE", "E1", "SE1", "E2", "SE2", "KP", "KI", "KC")

    def setup(self, system):
        super().setup(system)
        p = self.p
        for k in range(self.n):
            if p["KF"][k] > 0 and p["TF1"][k] <= 0:
                raise DataError(self.element(k), "TF1", float(p["TF1"][k]),
                                "a rate feedback (KF > 0) needs TF1 > 0 (its derivative acts on a lag of "
                                "VR); give TF1 > 0 or KF = 0")
            through = p["TA2"][k] == 0 and (p["TA4"][k] == 0 or p["TA3"][k] > 0)   # VA reaches VR at once
            if p["KF"][k] > 0 and p["TF2"][k] == 0 and p["TA1"][k] > 0 and through:
                raise DataError(self.element(k), "TA2", 0.0,
                                "with TA2 = 0 (and TA4 = 0 or TA3 > 0), TF2 = 0, KA*TA1 > 0 and KF > 0 the "
                                "rate feedback closes an algebraic loop; give TA2 > 0 (e.g. 0.01 s) or TF2 > 0")
        self.LG = Lag(1.0, p["TR"])
        self.PIr = PINonWindup(p["KA"] * p["TA1"], p["KA"], p["VR2"], p["VR1"])
        self.X1 = Lag(1.0, p["TA2"])
        self.LL = LeadLag(p["TA3"], p["TA4"])
        self.FB1 = Lag(1.0, p["TF1"])
        self.FB2 = Lag(1.0, p["TF2"])
        self.EX = DCExciter(p["KE"], p["TE"], p["E1"], p["SE1"], p["E2"], p["SE2"])
        self._te = p["TE"] > 0
        self._te_s = np.where(self._te, p["TE"], 1.0)
        self._nosrc = (p["KP"] == 0) & (p["KI"] == 0)
        self._ibase = system.Sb / self.Sn

    def limits(self):
        return [(self.idx("PI"), self.p["VR2"], self.p["VR1"])]

    def _vb(self, V, S, xad, xp=NUMPY):
        p = self.p
        It = xp.conj(S / V) * self._ibase
        VE = xp.abs(p["KP"] * V + 1j * p["KI"] * It)
        IN = xp.where(VE > 0, p["KC"] * xad / xp.where(VE > 0, VE, 1.0), 0.0)   # VE kept off 0
        return xp.where(self._nosrc, 1.0, VE * rectifier_fex(IN, xp))

    def init(self, system, x, sig):
        p = self.p
        m = self.mach
        vf0, v, xad = sig["vf0"][m], sig["Ecomp0"][m], sig["XadIfd"][m]
        V0 = sig["Vt0"][m] * np.exp(1j * sig["theta0"][m])
        VB = self._vb(V0, sig["Pe0"][m] + 1j * sig["Qe0"][m], xad)
        if np.any(VB <= 0):
            k = int(np.nonzero(VB <= 0)[0][0])
            raise DataError(self.element(k), "KP", float(p["KP"][k]),
                            "the source has no voltage at the operating point (VB = 0: KC*XadIfd >= VE); "
                            "raise KP/KI or lower KC")
        E00 = np.where(self._te, self.EX.vfe(vf0), vf0)
        VR0 = E00 / VB
        self.vref0 = np.asarray(v, float).copy()
        x[self.sl(0)] = self.LG.init(v)
        x[self.sl(1)] = self.PIr.init(VR0)
        x[self.sl(2)] = VR0
        x[self.sl(3)] = self.LL.init(VR0)
        x[self.sl(4)] = VR0
        x[self.sl(5)] = 0.0 * VR0
        x[self.sl(6)] = vf0
        self.initial_bounds = [("VR", VR0, p["VRMIN"], p["VRMAX"], "VRMIN", "VRMAX"),
                               ("E0", E00, p["EFDMIN"], p["EFDMAX"], "EFDMIN", "EFDMAX")]

    def compute(self, ctx):
        xp, p = self.xp, self.p
        m = self._mi
        lg, pi, x1, ll, vf1, vf, efd_x = (ctx.x[..., s] for s in self._sls)
        s = ctx.sig
        v = take(xp, s["Ecomp"], m)
        xad = take(xp, s["XadIfd"], m)
        # rate feedback output: the VF state where TF2 > 0, else KF*dVF1/dt, static in VR; VR does
        # not depend on ev then (setup refuses the direct path), so it is evaluated with ev = 0
        vr_now = hard_limit(self.LL.output(ll, self.X1.output(x1, self.PIr.output(pi, 0.0 * v))),
                            p["VRMIN"], p["VRMAX"], xp)
        dvf1 = self.FB1.deriv(vf1, vr_now)
        vf_out = xp.where(p["TF2"] > 0, vf, p["KF"] * dvf1)
        ev = self.vref0 - self.LG.output(lg, v) - vf_out + take(xp, s["vs"], m)
        va = self.PIr.output(pi, ev)
        y1 = self.X1.output(x1, va)
        vr = hard_limit(self.LL.output(ll, y1), p["VRMIN"], p["VRMAX"], xp)
        VB = self._vb(take(xp, ctx.V, self.bus), take(xp, s["Pe"], m) + 1j * take(xp, s["Qe"], m), xad, xp)
        e0 = hard_limit(VB * vr, p["EFDMIN"], p["EFDMAX"], xp)
        efd = xp.where(self._te, efd_x, e0)
        dvf1 = self.FB1.deriv(vf1, vr)
        f = ctx.f
        f[..., self._sls[0]] = self.LG.deriv(lg, v)
        f[..., self._sls[1]] = self.PIr.deriv(pi, ev)
        f[..., self._sls[2]] = self.X1.deriv(x1, va)
        f[..., self._sls[3]] = self.LL.deriv(ll, y1)
        f[..., self._sls[4]] = dvf1
        f[..., self._sls[5]] = self.FB2.deriv(vf, p["KF"] * dvf1)
        f[..., self._sls[6]] = xp.where(self._te, (e0 - self.EX.vfe(efd_x)) / self._te_s, 0.0)
        put(xp, s["vf"], m, efd)
        o = ctx.out
        o["EXPIC1.ev"], o["EXPIC1.VA"], o["EXPIC1.VR"] = ev, va, vr
        o["EXPIC1.VB"], o["EXPIC1.E0"], o["EXPIC1.vout"] = VB, e0, efd
