"""ST6B: IEEE 421.5-2005 type ST6B static exciter (PSS/E ST6B).

A PID voltage regulator with an inner field-voltage loop (pre-control ``KFF`` and forward gain
``KM`` on the error to the fed-back field voltage), a field-current limiter at a low-value gate,
and a bridge supplied from the terminals. Block diagram (pu on the machine base, times in s;
PSS/E ST6B names)::

    v --[Lag 1/(1+sTR)]--> LG
    vi  = vref - LG + vs                                          (vs: PSS output)
    VA  = clip(KPA*vi + PI + s*KDA/(1+sTDA)*vi, VAMIN, VAMAX)     (PID; integrator PI = KIA/s*vi
                                                                   held in VAMIN..VAMAX, non-windup)
    VR2 = clip(KFF*VA + KM*(VA - VG), VRMIN, VRMAX)
    VR1 = max(KLR*(KCI*ILR - XadIfd), VRMIN)                      (field-current limiter)
    VR  = min(VR1, VR2)                                           (low-value gate)
    Efd = VR * Vt
    Efd --[Lag KG/(1+sTG)]--> VG                                  (inner-loop feedback)

``Vt`` is the terminal-voltage magnitude and ``XadIfd`` the field current, pu of the machine.
``TR = 0`` removes the sensing lag; ``KDA = 0`` removes the derivative channel (``KDA > 0``
needs ``TDA > 0``); ``TG = 0`` makes the feedback the static ``VG = KG*Efd``, an algebraic loop
solved in closed form (``VR2 = clip((KFF+KM)*VA/(1 + KM*KG*Vt))``, the gate's map being
decreasing in VR). The OEL input selector ``OEL`` (PSS/E ICON: 0 none, 1 before the UEL, 2 after
it) is accepted; no over-/under-excitation limiter is modelled (their inputs are absent).

At initialization ``VR = vf0/Vt``, ``VG = KG*vf0``, ``VA = (VR + KM*VG)/(KFF + KM)`` with zero
voltage error (``vref = v``, the integrator at ``VA``; with ``KIA = 0`` it is a constant offset).
The operating point must leave the field-current limiter open (``KLR*(KCI*ILR - XadIfd) >=
VR``): else no steady state exists (the gate would hold VR below the field voltage the machine
needs) and ``setup`` refuses it naming ``ILR``.

Difference from PowerSimulationsDynamics.jl (PSID, read for structure, BSD-3): PSID multiplies
``VR`` by the *sensed* voltage ``LG`` (after ``TR``), and at initialization raises ``ILR`` to ten
times the field current (with a warning) when the limiter would be active — its PSS/E benchmark
record ``ThreeBus_ST6B.dyr`` (``ILR = 2.15``, ``KCI = 1.0577``, ``KLR = 17.33``) has the limiter
active at its operating point (``KLR*(KCI*ILR - XadIfd) = 2.096 < VR = 2.111``); weakgrid refuses
it unedited (naming ``ILR``) rather than change the data. The limiter's form is IEEE 421.5's (and
Dynawo's ``BaseSt6``: ``KLR*(ILR*KCL - Ifd)``, low-limited at VRMIN), and the field current is
PSS/E's own: the same GENROU at the same operating point (PSID's SEXS benchmark, same ``.raw``)
starts at PSS/E's Efd = XadIfd = 2.15312 pu, weakgrid's 2.153116 — so in PSS/E too the limiter
binds from t = 0 (it needs ILR >= 2.15082 pu; the file has 2.15, IEEE's typical value is 4.164).
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, Washout, hard_limit
from ..control_base import MachineControl
from ..errors import DataError
from ..namespace import NUMPY, put, take
from ..params import Param


class ST6B(MachineControl):
    """IEEE ST6B static exciter. Times [s]: TR, TDA, TG; gains: KPA [pu], KIA [1/s], KDA [s], KFF,
    KM, KCI, KLR, KG [pu]; limits VAMAX, VAMIN, VRMAX, VRMIN [pu, machine base]; ILR [pu field
    current]; OEL input selector (0, 1, 2; unused)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference computed at init (from the operating point): per batch member
    batch_params = ("vref0",)
    order = 2
    params = (
        Param("OEL", 0.0, "-", "OEL input selector (0 none, 1 before UEL, 2 after UEL; no OEL modelled)", ""),
        Param("TR", 0.012, "s", "sensing time constant", "nonneg"),
        Param("KPA", 18.038, "pu", "regulator proportional gain", "nonneg"),
        Param("KIA", 45.094, "1/s", "regulator integral gain", "nonneg"),
        Param("KDA", 0.0, "s", "regulator derivative gain", "nonneg"),
        Param("TDA", 0.0, "s", "derivative channel time constant", "nonneg"),
        Param("VAMAX", 4.81, "pu", "maximum PID output", ""),
        Param("VAMIN", -3.85, "pu", "minimum PID output", ""),
        Param("KFF", 1.0, "pu", "pre-control gain of the inner loop", ""),
        Param("KM", 1.0, "pu", "forward gain of the inner loop", ""),
        Param("KCI", 1.0577, "pu", "field-current limiter conversion factor", "nonneg"),
        Param("KLR", 17.33, "pu", "field-current limiter gain", "nonneg"),
        Param("ILR", 4.164, "pu", "field-current limiter setpoint", ""),
        Param("VRMAX", 4.81, "pu", "maximum regulator output (times Vt)", ""),
        Param("VRMIN", -3.85, "pu", "minimum regulator output (times Vt)", ""),
        Param("KG", 1.0, "pu", "inner-loop feedback gain", "nonneg"),
        Param("TG", 0.02, "s", "inner-loop feedback time constant (0: static)", "nonneg"),
    )
    states = ("LG", "PI", "PD", "VG")
    outputs = ("vi", "VA", "VR", "VR1", "vout")
    #: parameter names of the limits of each limited state (for error messages)
    limit_fields = {"PI": ("VAMIN", "VAMAX")}
    #: PSS/E .dyr record after ``IBUS 'ST6B' ID``: ICON OEL, then 16 CONs (PSS/E Model Library)
    psse_record = ("OEL", "TR", "KPA", "KIA", "KDA", "TDA", "VAMAX", "VAMIN", "KFF", "KM", "KCI", "KLR",
                   "ILR", "VRMAX", "VRMIN", "KG", "TG")

    def setup(self, system):
        super().setup(system)
        p = self.p
        for k in range(self.n):
            if p["OEL"][k] not in (0.0, 1.0, 2.0):
                raise DataError(self.element(k), "OEL", float(p["OEL"][k]),
                                "OEL input selector: 0 (none), 1 (before the UEL gate) or 2 (after it)")
            if p["KDA"][k] > 0 and p["TDA"][k] <= 0:
                raise DataError(self.element(k), "TDA", float(p["TDA"][k]),
                                "a derivative channel (KDA > 0) needs TDA > 0; give TDA > 0 or KDA = 0")
            if p["KFF"][k] + p["KM"][k] == 0:
                raise DataError(self.element(k), "KM", float(p["KM"][k]),
                                "KFF + KM = 0 leaves the inner loop without forward gain; give KFF + KM != 0")
            if p["TG"][k] == 0 and p["KM"][k] * p["KG"][k] < 0:
                raise DataError(self.element(k), "TG", 0.0,
                                "TG = 0 with KM*KG < 0 makes the inner-loop algebraic loop ill-posed; "
                                "give TG > 0")
        self.LG = Lag(1.0, p["TR"])
        self.PD = Washout(p["KDA"], p["TDA"])                # s KDA/(1+sTDA)
        self.LGV = Lag(p["KG"], p["TG"])
        self._tg = p["TG"] > 0

    def limits(self):
        return [(self.idx("PI"), self.p["VAMIN"], self.p["VAMAX"])]

    def _vr1(self, xad, xp=NUMPY):
        """Field-current limiter branch of the low-value gate [pu]."""
        p = self.p
        return xp.maximum(p["KLR"] * (p["KCI"] * p["ILR"] - xad), p["VRMIN"])

    def init(self, system, x, sig):
        p = self.p
        m = self.mach
        vf0, v, vt, xad = sig["vf0"][m], sig["Ecomp0"][m], sig["Vt0"][m], sig["XadIfd"][m]
        VR0 = vf0 / vt
        VG0 = p["KG"] * vf0
        VA0 = (VR0 + p["KM"] * VG0) / (p["KFF"] + p["KM"])
        self.vref0 = np.asarray(v, float).copy()
        x[self.sl(0)] = self.LG.init(v)
        x[self.sl(1)] = VA0
        x[self.sl(2)] = self.PD.init(0.0 * VA0)
        x[self.sl(3)] = VG0
        # the field-current limiter must stay open: as a bound on ILR where the limiter has gain,
        # else on VR against the limiter's output
        gain = (p["KLR"] > 0) & (p["KCI"] > 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            ilr_needed = np.where(gain, (xad + VR0 / np.where(gain, p["KLR"], 1.0)) / np.where(gain, p["KCI"], 1.0),
                                  -np.inf)
        inf = np.full(self.n, np.inf)
        self.initial_bounds = [
            ("VR", VR0, p["VRMIN"], p["VRMAX"], "VRMIN", "VRMAX"),
            ("ILR needed at this operating point, (XadIfd + VR/KLR)/KCI", ilr_needed, -inf,
             np.where(gain, p["ILR"], inf), "ILR", "ILR"),
            ("VR", VR0, -inf, np.where(gain, inf, self._vr1(xad)), "",
             "max(KLR*(KCI*ILR - XadIfd), VRMIN) (field-current limiter, KLR or KCI = 0)"),
        ]

    def compute(self, ctx):
        xp, p = self.xp, self.p
        m = self._mi
        lg, pi, pd, vg = (ctx.x[..., s] for s in self._sls)
        s = ctx.sig
        v = take(xp, s["Ecomp"], m)
        vt = take(xp, s["Vt"], m)
        xad = take(xp, s["XadIfd"], m)
        vi = self.vref0 - self.LG.output(lg, v) + take(xp, s["vs"], m)
        va = hard_limit(p["KPA"] * vi + pi + self.PD.output(pd, vi), p["VAMIN"], p["VAMAX"], xp)
        vr1 = self._vr1(xad, xp)
        kff, km = p["KFF"], p["KM"]
        vr2_lag = kff * va + km * (va - vg)
        vr2_static = (kff + km) * va / (1.0 + km * p["KG"] * vt)       # TG = 0: VG = KG*Efd
        vr2 = hard_limit(xp.where(self._tg, vr2_lag, vr2_static), p["VRMIN"], p["VRMAX"], xp)
        vr = xp.minimum(vr1, vr2)
        efd = vr * vt
        f = ctx.f
        f[..., self._sls[0]] = self.LG.deriv(lg, v)
        f[..., self._sls[1]] = p["KIA"] * vi
        f[..., self._sls[2]] = self.PD.deriv(pd, vi)
        f[..., self._sls[3]] = self.LGV.deriv(vg, efd)
        put(xp, s["vf"], m, efd)
        o = ctx.out
        o["ST6B.vi"], o["ST6B.VA"], o["ST6B.VR"], o["ST6B.VR1"], o["ST6B.vout"] = vi, va, vr, vr1, efd
