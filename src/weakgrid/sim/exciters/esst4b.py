"""ESST4B: IEEE 421.5 type ST4B static exciter (PI regulators, potential/compound source).

ST3A's relative: the lead-lag regulator and the inner-loop lag become PI controllers.
Block diagram (pu, times in s; PSS/E ESST4B, ANDES parameter names)::

    v --[Lag 1/(1+sTR)]--> LG
    vi  = vref - LG + vs                                     (vs: PSS output)
    vi  --[PI KPR + KIR/s, non-windup VRMIN..VRMAX]--> VR    (outer voltage regulator)
    VR  --[Lag 1/(1+sTA)]--> VA
    VG  = min(KG*Efd, VGMAX)                                 (inner field-voltage feedback)
    (VA - VG) --[PI KPM + KIM/s, non-windup VMMIN..VMMAX]--> VM   (inner field regulator)
    VE  = |KP e^{j THETAP} Vt + j (KI + KP e^{j THETAP} XL) It|   (source voltage, as ESST3A)
    IN  = KC*XadIfd/VE,  VB = min(VE * FEX(IN), VBMAX)
    Efd = VB * VM

All gains and limits in pu on the machine base (the exciter's field-voltage base), times in
s, ``THETAP`` in degrees. ``Vt``, ``It`` are the terminal voltage and current phasors on the
system base (see :func:`weakgrid.sim.exciters.esst3a.source_voltage`). No under/over-excitation
limiter (their gates are open, as in ANDES). The integrators start at the outputs the operating
point needs with zero error at both PI inputs, so ``vref = v`` and the initialization holds
for ``KIR = 0`` / ``KIM = 0`` too (the integrator states are then constant offsets).

Difference from ANDES 2.0 (documented, not copied): ANDES's two PI regulators have a
*tracking* anti-windup (the integrator driven back by ``Ks = 2`` times the part of the output
the limiter cuts, ``PITrackAW``) instead of the standard non-windup limits (the integrator
held at the limit). They agree while no PI output reaches its limits, and whenever
``KIR = KIM = 0`` (ieee14_esst4b). ``PI_nonwindup = 0`` reproduces ANDES (set by
``from_andes(..., conventions="andes")``).
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, PINonWindup, PITrackAW
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param
from .esst3a import rectified_voltage, source_voltage, source_voltage0

#: tracking gain of ANDES's PITrackAW (its ESST4B config ``ksr = ksm = 2``)
ANDES_TRACKING_GAIN = 2.0


class ESST4B(MachineControl):
    """IEEE ST4B static exciter. Times [s]: TR, TA; gains [pu]: KPR, KIR [1/s], KPM, KIM [1/s],
    KG, KP, KI, KC; reactance XL [pu]; THETAP [deg]; limits VRMAX, VRMIN, VMMAX, VMMIN, VBMAX,
    VGMAX [pu, machine base]."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("TR", "KPR", "KIR", "VRMAX", "VRMIN", "TA", "KPM", "KIM", "VMMAX", "VMMIN",
                   "KG", "KP", "KI", "VBMAX", "KC", "XL", "THETAP")

    @classmethod
    def psse_params(cls, values, ctx):
        """PSS/E ESST4B (IEEE 421.5-2005 ST4B) has no VGMAX: the inner feedback is unlimited."""
        return {**values, "VGMAX": 999.0}

    params = (
        Param("TR", 0.01, "s", "sensing time constant", "nonneg"),
        Param("KPR", 1.0, "pu", "proportional gain of the voltage regulator", "nonneg"),
        Param("KIR", 0.0, "1/s", "integral gain of the voltage regulator", "nonneg"),
        Param("VRMAX", 8.0, "pu", "maximum voltage-regulator output", ""),
        Param("VRMIN", 0.0, "pu", "minimum voltage-regulator output", ""),
        Param("TA", 0.1, "s", "regulator delay time constant (0: none)", "nonneg"),
        Param("KPM", 1.0, "pu", "proportional gain of the inner field regulator", "nonneg"),
        Param("KIM", 0.0, "1/s", "integral gain of the inner field regulator", "nonneg"),
        Param("VMMAX", 8.0, "pu", "maximum inner-loop output", ""),
        Param("VMMIN", 0.0, "pu", "minimum inner-loop output", ""),
        Param("KG", 1.0, "pu", "inner-loop feedback gain", "nonneg"),
        Param("KP", 4.0, "pu", "potential circuit gain", "nonneg"),
        Param("KI", 0.1, "pu", "potential circuit (current) gain", "nonneg"),
        Param("VBMAX", 18.0, "pu", "maximum available exciter voltage", ""),
        Param("KC", 0.1, "pu", "rectifier loading factor", "nonneg"),
        Param("XL", 0.01, "pu", "reactance of the potential source", "nonneg"),
        Param("THETAP", 0.0, "deg", "potential circuit phase angle", ""),
        Param("VGMAX", 20.0, "pu", "maximum inner-loop feedback", ""),
        Param("PI_nonwindup", 1.0, "-", "1: non-windup PI limits (IEEE 421.5); 0: tracking "
              "anti-windup with gain 2 (ANDES 2.0's PITrackAW)", "flag"),
    )
    states = ("LG", "PR", "VA", "PM")
    outputs = ("vi", "VR", "VM", "VE", "VB", "vout")
    #: parameter names of the limits of each limited state (for error messages)
    limit_fields = {"PR": ("VRMIN", "VRMAX"), "PM": ("VMMIN", "VMMAX")}

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.KPC = p["KP"] * np.exp(1j * np.radians(p["THETAP"]))
        self.LG = Lag(1.0, p["TR"])
        self.PR = PINonWindup(p["KPR"], p["KIR"], p["VRMIN"], p["VRMAX"])
        self.LA = Lag(1.0, p["TA"])
        self.PM = PINonWindup(p["KPM"], p["KIM"], p["VMMIN"], p["VMMAX"])
        self.PRt = PITrackAW(p["KPR"], p["KIR"], ANDES_TRACKING_GAIN)
        self.PMt = PITrackAW(p["KPM"], p["KIM"], ANDES_TRACKING_GAIN)
        self._nw = p["PI_nonwindup"] > 0
        self._nw_all, self._nw_any = bool(np.all(self._nw)), bool(np.any(self._nw))

    def _vb(self, VE, XadIfd):
        return rectified_voltage(VE, XadIfd, self.p["KC"], self.p["VBMAX"], self.xp)

    def limits(self):
        p = self.p
        inf = np.full(self.n, np.inf)
        # non-windup integrators are held at their limits; tracking ones (ANDES) are not
        return [(self.idx("PR"), np.where(self._nw, p["VRMIN"], -inf), np.where(self._nw, p["VRMAX"], inf)),
                (self.idx("PM"), np.where(self._nw, p["VMMIN"], -inf), np.where(self._nw, p["VMMAX"], inf))]

    def init(self, system, x, sig):
        p = self.p
        m = self.mach
        vf0, v = sig["vf0"][m], sig["Ecomp0"][m]
        VE0 = source_voltage0(sig, m, self.KPC, p["KI"], p["XL"])
        VB0 = self._vb(VE0, sig["XadIfd"][m])
        VM0 = vf0 / VB0
        VR0 = np.minimum(p["KG"] * vf0, p["VGMAX"])        # VA = VG: zero inner-loop error
        self.vref0 = np.asarray(v, float).copy()             # zero voltage error
        x[self.sl(0)] = self.LG.init(v)
        x[self.sl(1)] = self.PR.init(VR0)
        x[self.sl(2)] = self.LA.init(VR0)
        x[self.sl(3)] = self.PM.init(VM0)
        # tracking-PI outputs are cut, not held: their initial values are checked here
        big = np.where(self._nw, np.inf, 0.0)
        self.initial_bounds = [("VR", VR0, p["VRMIN"] - big, p["VRMAX"] + big, "VRMIN", "VRMAX"),
                               ("VM", VM0, p["VMMIN"] - big, p["VMMAX"] + big, "VMMIN", "VMMAX")]

    def _pi(self, x, u, nw, tr, lo, hi):
        """Output and derivative of a PI: non-windup where ``PI_nonwindup``, else tracking."""
        xp = self.xp
        if self._nw_all:
            return nw.output(x, u), nw.deriv(x, u)
        if not self._nw_any:
            return tr.output(x, u, lo, hi), tr.deriv(x, u, lo, hi)
        return (xp.where(self._nw, nw.output(x, u), tr.output(x, u, lo, hi)),
                xp.where(self._nw, nw.deriv(x, u), tr.deriv(x, u, lo, hi)))

    def compute(self, ctx):
        xp = self.xp
        p = self.p
        m = self._mi
        lg, pr, va, pm = (ctx.x[..., s] for s in self._sls)
        s = ctx.sig
        v = take(xp, s["Ecomp"], m)
        vi = self.vref0 - self.LG.output(lg, v) + take(xp, s["vs"], m)
        vr, dpr = self._pi(pr, vi, self.PR, self.PRt, p["VRMIN"], p["VRMAX"])
        va_y = self.LA.output(va, vr)
        VE = source_voltage(ctx, self.mach, self.bus, self.KPC, p["KI"], p["XL"], xp)
        VB = self._vb(VE, take(xp, s["XadIfd"], m))
        # Efd = VB*VM and VG = min(KG*Efd, VGMAX) feed back into VM's own input: an algebraic
        # loop, solved in closed form on each branch of the VGMAX gate
        vm, dpm = self._inner(pm, va_y, VB)
        efd = VB * vm
        f = ctx.f
        f[..., self._sls[0]] = self.LG.deriv(lg, v)
        f[..., self._sls[1]] = dpr
        f[..., self._sls[2]] = self.LA.deriv(va, vr)
        f[..., self._sls[3]] = dpm
        put(xp, s["vf"], m, efd)
        o = ctx.out
        o["ESST4B.vi"], o["ESST4B.VR"], o["ESST4B.VM"] = vi, vr, vm
        o["ESST4B.VE"], o["ESST4B.VB"], o["ESST4B.vout"] = VE, VB, efd

    def _inner(self, pm, va, VB):
        """Inner loop ``VM = PI(VA - min(KG*VB*VM, VGMAX))`` with its algebraic feedback.

        Unlimited output on the proportional path: ``VM = KPM*(VA - VG) + PM``. With
        ``VG = KG*VB*VM`` below VGMAX: ``VM = (KPM*VA + PM)/(1 + KPM*KG*VB)``; with VG at
        VGMAX: ``VM = KPM*(VA - VGMAX) + PM``. The gate is on the branch whose VG is lower
        (min).
        """
        xp, p = self.xp, self.p
        kpm, kg = p["KPM"], p["KG"]
        vm_free = (kpm * va + pm) / (1.0 + kpm * kg * VB)
        vm_cap = kpm * (va - p["VGMAX"]) + pm
        vm_s = xp.where(kg * VB * vm_free <= p["VGMAX"], vm_free, vm_cap)
        # the PI limits act on that output (the loop map is decreasing in VM: its fixed point
        # with the limiter is the clipped one); VG from the limited VM
        vm = xp.clip(vm_s, p["VMMIN"], p["VMMAX"])
        vg = xp.minimum(kg * VB * vm, p["VGMAX"])
        u = va - vg
        return self._pi(pm, u, self.PM, self.PMt, p["VMMIN"], p["VMMAX"])
