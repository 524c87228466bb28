"""ESST3A: IEEE 421.5 type ST3A static exciter (potential/compound source, inner field loop).

Block diagram (pu, times in s; PSS/E ESST3A and ANDES conventions)::

    v --[Lag 1/(1+sTR)]--> LG
    vi  = vref - LG + vs                                   (vs: PSS output)
    vil = clip(vi, VIMIN, VIMAX)
    vil --[LeadLag (1+sTC)/(1+sTB)]--> VA
    VA  --[Lag KA/(1+sTA), non-windup VRMIN..VRMAX]--> VR
    VG  = min(KG*Efd, VGMAX)                               (inner field-voltage feedback)
    (VR - VG) --[Lag KM/(1+sTM), non-windup VMMIN..VMMAX]--> VM
    VE  = |KP e^{j THETAP} Vt + j (KI + KP e^{j THETAP} XL) It|   (source voltage)
    IN  = KC*XadIfd/VE,  VB = min(VE * FEX(IN), VBMAX)
    Efd = VB * VM

``TA = 0`` (as in ANDES's ieee14 data) makes the regulator the limited gain
``VR = clip(KA*VA, VRMIN, VRMAX)`` (the state ``VR`` is then unused).

``Vt``, ``It`` are the machine terminal voltage and current phasors on the
system base (the magnitude does not depend on the reference frame, so the
network frame is used). No under-excitation limiter (the UEL input is -inf,
as in ANDES). ``vref`` is set at initialization so that ``Efd = vf0``.
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LagNonWindup, LeadLag, hard_limit, rectifier_fex
from ..control_base import MachineControl
from ..namespace import NUMPY, put, take
from ..params import Param


def source_voltage(ctx, mach, bus, KPC, KI, XL, xp=NUMPY):
    """``|KPC*Vt + j(KI + KPC*XL)*It|`` of machines ``mach`` at buses ``bus`` (system-base pu;
    ``xp``: the arrays' namespace)."""
    s = ctx.sig
    V = take(xp, ctx.V, bus)
    S = take(xp, s["Pe"], mach) + 1j * take(xp, s["Qe"], mach)
    It = xp.conj(S / V)
    return xp.abs(KPC * V + 1j * (KI + KPC * XL) * It)


def rectified_voltage(VE, XadIfd, KC, VBMAX, xp=NUMPY):
    """Available exciter voltage ``VB = min(VE * FEX(IN), VBMAX)``, ``IN = KC*XadIfd/VE`` [pu]
    (``xp``: the arrays' namespace; ``VE`` is kept off 0 where ``IN`` is not used)."""
    on = VE > 0
    IN = xp.where(on, KC * XadIfd / xp.where(on, VE, 1.0), 0.0)
    return xp.minimum(VE * rectifier_fex(IN, xp), VBMAX)


def source_voltage0(sig, mach, KPC, KI, XL):
    """:func:`source_voltage` at the power-flow point, from the initial signals ``sig``."""
    V = sig["Vt0"][mach] * np.exp(1j * sig["theta0"][mach])
    It = np.conj((sig["Pe0"][mach] + 1j * sig["Qe0"][mach]) / V)
    return np.abs(KPC * V + 1j * (KI + KPC * XL) * It)


class ESST3A(MachineControl):
    """IEEE ST3A static exciter. Times [s]: TR, TC, TB, TA, TM; gains [pu]: KA, KM, KG, KP, KI, KC;
    reactance XL [pu]; THETAP [deg]; limits VIMAX, VIMIN, VRMAX, VRMIN, VMMAX, VMMIN, VBMAX, VGMAX [pu]."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("TR", "VIMAX", "VIMIN", "KM", "TC", "TB", "KA", "TA", "VRMAX", "VRMIN", "KG",
                   "KP", "KI", "VBMAX", "KC", "XL", "VGMAX", "THETAP", "TM", "VMMAX", "VMMIN")
    params = (
        Param("TR", 0.01, "s", "sensing time constant", "nonneg"),
        Param("VIMAX", 0.8, "pu", "maximum input error", ""),
        Param("VIMIN", -0.1, "pu", "minimum input error", ""),
        Param("KM", 500.0, "pu", "forward gain of the inner loop", "pos"),
        Param("TC", 3.0, "s", "lead time constant", "nonneg"),
        Param("TB", 15.0, "s", "lag time constant", "nonneg"),
        Param("KA", 50.0, "pu", "regulator gain", "pos"),
        Param("TA", 0.1, "s", "regulator time constant (0: no lag)", "nonneg"),
        Param("VRMAX", 8.0, "pu", "maximum regulator output", ""),
        Param("VRMIN", 0.0, "pu", "minimum regulator output", ""),
        Param("KG", 1.0, "pu", "inner-loop feedback gain", "nonneg"),
        Param("KP", 4.0, "pu", "potential circuit gain", "nonneg"),
        Param("KI", 0.1, "pu", "potential circuit (current) gain", "nonneg"),
        Param("VBMAX", 18.0, "pu", "maximum available exciter voltage", ""),
        Param("KC", 0.1, "pu", "rectifier loading factor", "nonneg"),
        Param("XL", 0.01, "pu", "reactance of the potential source", "nonneg"),
        Param("VGMAX", 4.0, "pu", "maximum inner-loop feedback", ""),
        Param("THETAP", 0.0, "deg", "potential circuit phase angle", ""),
        Param("TM", 0.1, "s", "inner-loop time constant", "pos"),
        Param("VMMAX", 1.0, "pu", "maximum inner-loop output", ""),
        Param("VMMIN", 0.1, "pu", "minimum inner-loop output", ""),
    )
    states = ("LG", "LL", "VR", "VM")
    outputs = ("vi", "VE", "VB", "vout")

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.KPC = p["KP"] * np.exp(1j * np.radians(p["THETAP"]))
        self.LG = Lag(1.0, p["TR"])
        self.LL = LeadLag(p["TC"], p["TB"])
        self.LA = LagNonWindup(p["KA"], p["TA"], p["VRMIN"], p["VRMAX"])
        self.LM = LagNonWindup(p["KM"], p["TM"], p["VMMIN"], p["VMMAX"])

    def limits(self):
        p = self.p
        return [(self.idx("VR"), p["VRMIN"], p["VRMAX"]), (self.idx("VM"), p["VMMIN"], p["VMMAX"])]

    def _vb(self, VE, XadIfd):
        return rectified_voltage(VE, XadIfd, self.p["KC"], self.p["VBMAX"], self.xp)

    def init(self, system, x, sig):
        p = self.p
        m = self.mach
        vf0, v = sig["vf0"][m], sig["Ecomp0"][m]
        VE0 = source_voltage0(sig, m, self.KPC, p["KI"], p["XL"])
        VB0 = self._vb(VE0, sig["XadIfd"][m])
        VM0 = vf0 / VB0
        VR0 = VM0 / p["KM"] + np.minimum(p["KG"] * vf0, p["VGMAX"])
        VA0 = VR0 / p["KA"]
        self.vref0 = v + VA0
        x[self.sl(0)] = self.LG.init(v)
        x[self.sl(1)] = self.LL.init(VA0)
        x[self.sl(2)] = VR0
        x[self.sl(3)] = VM0

    def compute(self, ctx):
        xp = self.xp
        p = self.p
        m = self._mi
        lg, ll, vr, vm = (ctx.x[..., s] for s in self._sls)
        s = ctx.sig
        v = take(xp, s["Ecomp"], m)
        vi = self.vref0 - self.LG.output(lg, v) + take(xp, s["vs"], m)
        vil = hard_limit(vi, p["VIMIN"], p["VIMAX"], xp)
        va = self.LL.output(ll, vil)
        VE = source_voltage(ctx, self.mach, self.bus, self.KPC, p["KI"], p["XL"], xp)
        VB = self._vb(VE, take(xp, s["XadIfd"], m))
        efd = VB * vm
        vg = xp.minimum(p["KG"] * efd, p["VGMAX"])
        vr_out = self.LA.output(vr, va)           # = vr unless TA = 0 (then clip(KA*va))
        f = ctx.f
        f[..., self._sls[0]] = self.LG.deriv(lg, v)
        f[..., self._sls[1]] = self.LL.deriv(ll, vil)
        f[..., self._sls[2]] = self.LA.deriv(vr, va)
        f[..., self._sls[3]] = self.LM.deriv(vm, vr_out - vg)
        put(xp, s["vf"], m, efd)
        o = ctx.out
        o["ESST3A.vi"], o["ESST3A.VE"], o["ESST3A.VB"], o["ESST3A.vout"] = vi, VE, VB, efd
