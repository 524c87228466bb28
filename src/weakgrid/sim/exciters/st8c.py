"""ST8C: IEEE 421.5-2016 type ST8C static exciter with a field-current regulator (PSS/E ST8C).

An outer PI voltage regulator gives the field-current reference, an inner PI regulates the
field current (fed back through ``KF/(1+sTF)``), the bridge firing is a lag, and the bridge is
supplied by a potential/compound source (``VB1``) with an optional series current source
(``VB2``). Block diagram (pu on the machine base, times in s; PSS/E ST8C names)::

    v --[Lag 1/(1+sTR)]--> LG
    vi    = vref - LG + vs                                       (vs: PSS output)
    vi    --[PI KPR + KIR/s, non-windup VPIMIN..VPIMAX]--> IFDREF   (voltage regulator)
    XadIfd --[Lag KF/(1+sTF)]--> IFB                             (field-current feedback)
    (IFDREF - IFB) --[PI KPA + KIA/s, non-windup VAMIN..VAMAX]--> VA (field-current regulator)
    VA    --[Lag KA/(1+sTA), non-windup VRMIN..VRMAX]--> VR       (bridge firing)
    VE1   = |KP e^{j THETAP} Vt + j (KI1 + KP e^{j THETAP} XL) It|   (SW1 = 0 or 1: terminal source)
    VE1   = KP                                                   (SW1 = 2: independent source)
    VB1   = min(VE1 * FEX(KC1*XadIfd/VE1), VB1MAX)
    VE2   = KI2 * |It|,  VB2 = min(VE2 * FEX(KC2*XadIfd/VE2), VB2MAX)   (VB2 = 0 if KI2 = 0)
    Efd   = VR * VB1 + VB2

``Vt``, ``It`` are the terminal voltage and current phasors in pu of the machine (the current is
converted from the system base with the machine rating), ``XadIfd`` the field current.
``TR = 0``, ``TF = 0`` remove those lags; ``TA = 0`` makes the firing the limited gain
``clip(KA*VA, VRMIN, VRMAX)``. The OEL/UEL/SCL flags (PSS/E ICONs; ``< 2`` summation at the
voltage error, ``2`` take-over at the gates) are accepted; no limiter is modelled (their inputs are
absent, zero at the summing point).

At initialization ``VR = (vf0 - VB2)/VB1``, ``VA = VR/KA``, the field-current error is zero
(``IFDREF = KF*XadIfd``, the inner integrator at ``VA``) and so is the voltage error (``vref =
v``, the outer integrator at ``IFDREF``); a zero integral gain leaves its integrator a constant
offset. No source voltage (``VB1 <= 0`` at the operating point) is refused naming ``KP``.

Assumption and difference from PowerSimulationsDynamics.jl (PSID, read for structure, BSD-3):
the ``SW1`` code follows PowerSystems.jl's documentation of the PSS/E record (``< 2``: source
from the terminal voltage, ``2``: independent source, taken as the constant ``VE1 = KP``). PSID's
code instead treats ``SW1 = 1`` as the (unsupported) terminal source and every other value as the
independent source ``VE1 = KP``; its PSS/E benchmark record ``ThreeBus_ST8C.dyr`` has ``SW1 = 0``,
so there PSID uses ``VE1 = KP = 4`` where this model uses ``KP*|Vt|`` (4.08 at its operating
point). PSID implements neither ``KI1``, ``XL``, ``THETAP`` nor ``VB2`` (it refuses ``KI2 != 0``).
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LagNonWindup, hard_limit, rectifier_fex
from ..control_base import MachineControl
from ..errors import DataError
from ..namespace import NUMPY, put, take
from ..params import Param


def _rectified(VE, XadIfd, KC, VBMAX, xp=NUMPY):
    """``min(VE * FEX(KC*XadIfd/VE), VBMAX)``; 0 where ``VE <= 0`` [pu] (``xp``: the arrays'
    namespace)."""
    IN = xp.where(VE > 0, KC * XadIfd / xp.where(VE > 0, VE, 1.0), 0.0)   # VE kept off 0
    return xp.where(VE > 0, xp.minimum(VE * rectifier_fex(IN, xp), VBMAX), 0.0)


class ST8C(MachineControl):
    """IEEE ST8C static exciter. Times [s]: TR, TA, TF; gains: KPR, KPA, KA, KF, KC1, KP, KI1, KC2,
    KI2 [pu], KIR, KIA [1/s]; XL [pu]; THETAP [deg]; limits VPIMAX, VPIMIN, VAMAX, VAMIN, VRMAX,
    VRMIN, VB1MAX, VB2MAX [pu, machine base]; flags OEL, UEL, SCL (unused), SW1 (power source)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    params = (
        Param("OEL", 0.0, "-", "OEL input flag (<2 summation, 2 take-over; no OEL modelled)", ""),
        Param("UEL", 0.0, "-", "UEL input flag (<2 summation, 2 take-over; no UEL modelled)", ""),
        Param("SCL", 0.0, "-", "SCL input flag (<2 summation, 2 take-over; no SCL modelled)", ""),
        Param("SW1", 0.0, "-", "power source: <2 from the terminal voltage, 2 independent (VE1 = KP)", ""),
        Param("TR", 0.01, "s", "sensing time constant", "nonneg"),
        Param("KPR", 5.0, "pu", "voltage regulator proportional gain", "nonneg"),
        Param("KIR", 5.0, "1/s", "voltage regulator integral gain", "nonneg"),
        Param("VPIMAX", 99.0, "pu", "maximum voltage regulator output (field-current reference)", ""),
        Param("VPIMIN", 0.0, "pu", "minimum voltage regulator output", ""),
        Param("KPA", 4.0, "pu", "field-current regulator proportional gain", "nonneg"),
        Param("KIA", 0.1, "1/s", "field-current regulator integral gain", "nonneg"),
        Param("VAMAX", 99.0, "pu", "maximum field-current regulator output", ""),
        Param("VAMIN", -99.0, "pu", "minimum field-current regulator output", ""),
        Param("KA", 1.35, "pu", "bridge gain", "pos"),
        Param("TA", 0.003, "s", "bridge firing time constant (0: static)", "nonneg"),
        Param("VRMAX", 99.0, "pu", "maximum bridge output", ""),
        Param("VRMIN", -99.0, "pu", "minimum bridge output", ""),
        Param("KF", 0.5, "pu", "field-current feedback gain", "nonneg"),
        Param("TF", 0.005, "s", "field-current feedback time constant", "nonneg"),
        Param("KC1", 0.1, "pu", "rectifier loading factor of the potential source", "nonneg"),
        Param("KP", 4.0, "pu", "potential circuit (voltage) gain", "nonneg"),
        Param("KI1", 0.0, "pu", "potential circuit (current) gain", "nonneg"),
        Param("XL", 0.0, "pu", "reactance of the potential source", "nonneg"),
        Param("THETAP", 0.0, "deg", "potential circuit phase angle", ""),
        Param("VB1MAX", 99.0, "pu", "maximum potential source voltage", ""),
        Param("KC2", 0.0, "pu", "rectifier loading factor of the series current source", "nonneg"),
        Param("KI2", 0.0, "pu", "series current source gain", "nonneg"),
        Param("VB2MAX", 99.0, "pu", "maximum series current source voltage", ""),
    )
    states = ("LG", "PR", "PA", "VR", "IFB")
    outputs = ("vi", "IFDREF", "VA", "VB1", "VB2", "vout")
    #: parameter names of the limits of each limited state (for error messages)
    limit_fields = {"PR": ("VPIMIN", "VPIMAX"), "PA": ("VAMIN", "VAMAX"), "VR": ("VRMIN", "VRMAX")}
    #: PSS/E .dyr record after ``IBUS 'ST8C' ID``: 4 ICONs, then 24 CONs (PSS/E Model Library)
    psse_record = ("OEL", "UEL", "SCL", "SW1", "TR", "KPR", "KIR", "VPIMAX", "VPIMIN", "KPA", "KIA", "VAMAX",
                   "VAMIN", "KA", "TA", "VRMAX", "VRMIN", "KF", "TF", "KC1", "KP", "KI1", "XL", "THETAP",
                   "VB1MAX", "KC2", "KI2", "VB2MAX")

    def setup(self, system):
        super().setup(system)
        p = self.p
        for fld in ("OEL", "UEL", "SCL", "SW1"):
            for k in range(self.n):
                if p[fld][k] not in (0.0, 1.0, 2.0):
                    raise DataError(self.element(k), fld, float(p[fld][k]), "a PSS/E ICON flag: 0, 1 or 2")
        self.LG = Lag(1.0, p["TR"])
        self.FB = Lag(p["KF"], p["TF"])
        self.LA = LagNonWindup(p["KA"], p["TA"], p["VRMIN"], p["VRMAX"])
        self.KPC = p["KP"] * np.exp(1j * np.radians(p["THETAP"]))
        self._terminal = p["SW1"] < 2
        self._ibase = system.Sb / self.Sn               # system-base current -> machine base
        self._ta = p["TA"] > 0

    def limits(self):
        p = self.p
        on = self._ta
        return [(self.idx("PR"), p["VPIMIN"], p["VPIMAX"]), (self.idx("PA"), p["VAMIN"], p["VAMAX"]),
                (self.idx("VR")[on], p["VRMIN"][on], p["VRMAX"][on])]

    def _sources(self, V, S, xad, xp=NUMPY):
        """``(VB1, VB2)`` from the terminal voltage ``V`` and power ``S`` (system base) [pu]."""
        p = self.p
        It = xp.conj(S / V) * self._ibase
        VE1 = xp.where(self._terminal, xp.abs(self.KPC * V + 1j * (p["KI1"] + self.KPC * p["XL"]) * It), p["KP"])
        VB1 = _rectified(VE1, xad, p["KC1"], p["VB1MAX"], xp)
        VB2 = _rectified(p["KI2"] * xp.abs(It), xad, p["KC2"], p["VB2MAX"], xp)
        return VB1, VB2

    def init(self, system, x, sig):
        p = self.p
        m = self.mach
        vf0, v, xad = sig["vf0"][m], sig["Ecomp0"][m], sig["XadIfd"][m]
        V0 = sig["Vt0"][m] * np.exp(1j * sig["theta0"][m])
        VB1, VB2 = self._sources(V0, sig["Pe0"][m] + 1j * sig["Qe0"][m], xad)
        bad = VB1 <= 0
        if np.any(bad):
            k = int(np.nonzero(bad)[0][0])
            raise DataError(self.element(k), "KP", float(p["KP"][k]),
                            "the bridge has no source voltage at the operating point (VB1 = 0); "
                            "give KP > 0")
        VR0 = (vf0 - VB2) / VB1
        VA0 = VR0 / p["KA"]
        IFB0 = p["KF"] * xad
        self.vref0 = np.asarray(v, float).copy()
        x[self.sl(0)] = self.LG.init(v)
        x[self.sl(1)] = IFB0
        x[self.sl(2)] = VA0
        x[self.sl(3)] = VR0
        x[self.sl(4)] = self.FB.init(xad)
        big = np.where(self._ta, np.inf, 0.0)       # TA = 0: the static firing gain is clipped
        self.initial_bounds = [("VR", VR0, p["VRMIN"] - big, p["VRMAX"] + big, "VRMIN", "VRMAX")]

    def compute(self, ctx):
        xp, p = self.xp, self.p
        m = self._mi
        lg, pr, pa, vr, ifb = (ctx.x[..., s] for s in self._sls)
        s = ctx.sig
        v = take(xp, s["Ecomp"], m)
        xad = take(xp, s["XadIfd"], m)
        vi = self.vref0 - self.LG.output(lg, v) + take(xp, s["vs"], m)
        ifdref = hard_limit(p["KPR"] * vi + pr, p["VPIMIN"], p["VPIMAX"], xp)
        fb = self.FB.output(ifb, xad)
        ea = ifdref - fb
        va = hard_limit(p["KPA"] * ea + pa, p["VAMIN"], p["VAMAX"], xp)
        VR = self.LA.output(vr, va)
        VB1, VB2 = self._sources(take(xp, ctx.V, self.bus), take(xp, s["Pe"], m) + 1j * take(xp, s["Qe"], m),
                                 xad, xp)
        efd = VR * VB1 + VB2
        f = ctx.f
        f[..., self._sls[0]] = self.LG.deriv(lg, v)
        f[..., self._sls[1]] = p["KIR"] * vi
        f[..., self._sls[2]] = p["KIA"] * ea
        f[..., self._sls[3]] = self.LA.deriv(vr, va)
        f[..., self._sls[4]] = self.FB.deriv(ifb, xad)
        put(xp, s["vf"], m, efd)
        o = ctx.out
        o["ST8C.vi"], o["ST8C.IFDREF"], o["ST8C.VA"] = vi, ifdref, va
        o["ST8C.VB1"], o["ST8C.VB2"], o["ST8C.vout"] = VB1, VB2, efd
