"""AC8B: IEEE 421.5 type AC8B alternator-rectifier exciter with a PID regulator.

Block diagram (pu on the machine base, times in s; ANDES parameter names, PSS/E's
``KPR, KIR, KDR, TDR, VPIDMAX, VPIDMIN`` are ``kP, kI, kD, Td, VPMAX, VPMIN``)::

    v --[Lag 1/(1+sTR)]--> LG
    vi   = vref - LG + vs                                      (vs: PSS output)
    vi   --[PID kP + kI/s + s kD/(1+sTd), non-windup VPMIN..VPMAX]--> VPID
    VPID --[Lag KA/(1+sTA), non-windup VRMIN..VRMAX]--> VR
    VFE  = KE*VE + VE*SE(VE) + KD*XadIfd                       (exciter field current)
    (VR - VFE) --[Integrator 1/(sTE), non-windup VEMIN..VEMAX]--> VE
    VEMAX = (VFEMAX - KD*XadIfd) / (KE + SE(VE))               (field-current limit VFE <= VFEMAX)
    IN = KC*XadIfd/VE,  Efd = VE * FEX(IN)                     (rectifier regulation)

``SE`` is the quadratic saturation through ``(E1, SE1)``, ``(E2, SE2)`` (``SE1 = 0``: none).
At initialization ``VE`` solves ``VE*FEX(KC*XadIfd/VE) = vf0``; the PID starts with zero error
(``vref = v``), its integrator at ``VFE/KA`` (and its derivative filter at rest).

Differences from ANDES 2.0 (documented, not copied), each reproduced by a flag that
``from_andes(..., conventions="andes")`` sets:

* ANDES's PID has a *tracking* anti-windup (integrator driven back by ``Ks = 2`` times the part
  of the output its limiter cuts, ``PIDTrackAW``) instead of non-windup limits (as IEEE
  421.5-2016 draws VPIDMAX, VPIDMIN in AC8C):
  ``PID_nonwindup = 0``. They agree while the PID output stays inside ``VPMIN..VPMAX``.
* ANDES does not apply ``VEMIN`` and ``VFEMAX`` (its ``VE`` integrator is unlimited):
  ``VE_limited = 0``. They agree while ``VE`` stays above ``VEMIN`` and ``VFE`` below
  ``VFEMAX`` (ANDES's ieee14 data: -999 and 999).

Not reproduced: with ``TA = 0`` the regulator here is ``clip(KA*VPID, VRMIN, VRMAX)``, while
ANDES's anti-windup is not enforced on a zero time constant and its regulator output leaves
the limits (54.6 and -30.6 pu with ``VRMAX = 7.3``, ``VRMIN = 1`` on ieee14_ac8b, census fault;
3.4e-4 pu of speed apart).
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LagNonWindup, PITrackAW, Washout, hard_limit
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param
from .dc_common import SATURATION_PARAMS, DCExciter
from .esst4b import ANDES_TRACKING_GAIN
from .exac1 import _efd, ve_for_efd


class AC8B(MachineControl):
    """IEEE AC8B exciter. Times [s]: TR, Td, TA, TE; gains: kP [pu], kI [1/s], kD [s], KA, KE,
    KD, KC [pu]; limits VPMAX, VPMIN, VRMAX, VRMIN, VFEMAX, VEMIN [pu, machine base];
    E1, SE1, E2, SE2 (saturation)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    order = 2
    params = (
        Param("TR", 0.01, "s", "sensing time constant", "nonneg"),
        Param("kP", 10.0, "pu", "PID proportional gain", "nonneg"),
        Param("kI", 10.0, "1/s", "PID integral gain", "nonneg"),
        Param("kD", 10.0, "s", "PID derivative gain", "nonneg"),
        Param("Td", 0.2, "s", "PID derivative time constant", "pos"),
        Param("VPMAX", 999.0, "pu", "maximum PID output", ""),
        Param("VPMIN", -999.0, "pu", "minimum PID output", ""),
        Param("VRMAX", 7.3, "pu", "maximum regulator output", ""),
        Param("VRMIN", 1.0, "pu", "minimum regulator output", ""),
        Param("VFEMAX", 999.0, "pu", "exciter field current limit", ""),
        Param("VEMIN", -999.0, "pu", "minimum exciter voltage", ""),
        Param("TA", 0.04, "s", "regulator time constant (0: no lag)", "nonneg"),
        Param("KA", 40.0, "pu", "regulator gain", "pos"),
        Param("TE", 0.8, "s", "exciter time constant", "pos"),
        Param("KE", 1.0, "pu", "exciter constant", ""),
        Param("KD", 0.0, "pu", "demagnetizing factor", "nonneg"),
        Param("KC", 0.1, "pu", "rectifier loading factor", "nonneg"),
        Param("PID_nonwindup", 1.0, "-", "1: non-windup PID limits (IEEE 421.5); 0: tracking "
              "anti-windup with gain 2 (ANDES 2.0's PIDTrackAW)", "flag"),
        Param("VE_limited", 1.0, "-", "1: VE held in VEMIN..VEMAX (IEEE 421.5); 0: VE unlimited "
              "(ANDES 2.0 ignores VEMIN, VFEMAX)", "flag"),
    ) + SATURATION_PARAMS
    states = ("LG", "PI", "PD", "VR", "VE")
    outputs = ("vi", "VPID", "VFE", "vout")
    limit_fields = {"PI": ("VPMIN", "VPMAX"), "VR": ("VRMIN", "VRMAX"),
                    "VE": ("VEMIN", "VEMAX = (VFEMAX - KD*XadIfd)/(KE + SE(VE))")}

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.LG = Lag(1.0, p["TR"])
        self.PDf = Washout(p["kD"], p["Td"])                 # s kD/(1+sTd)
        self.PIt = PITrackAW(p["kP"], p["kI"], ANDES_TRACKING_GAIN)
        self.LA = LagNonWindup(p["KA"], p["TA"], p["VRMIN"], p["VRMAX"])
        self.EX = DCExciter(p["KE"], p["TE"], p["E1"], p["SE1"], p["E2"], p["SE2"])
        self._nw = p["PID_nonwindup"] > 0
        self._vel = p["VE_limited"] > 0

    def _vemax(self, ve, xad):
        """Upper limit of VE at which ``VFE = VFEMAX`` [pu] (+inf where VE is not limited)."""
        p = self.p
        with np.errstate(divide="ignore", invalid="ignore"):
            se = np.where(ve > 0, (self.EX.vfe(ve) - self.EX.KE * ve) / ve, 0.0)   # SE(VE)
            k = self.EX.KE + se
            vm = np.where(k > 0, (p["VFEMAX"] - p["KD"] * xad) / k, np.inf)
        return np.where(self._vel, vm, np.inf)

    def limits(self):
        p = self.p
        inf = np.full(self.n, np.inf)
        return [(self.idx("PI"), np.where(self._nw, p["VPMIN"], -inf), np.where(self._nw, p["VPMAX"], inf)),
                (self.idx("VR"), p["VRMIN"], p["VRMAX"]),
                (self.idx("VE"), np.where(self._vel, p["VEMIN"], -inf), self._vemax(self._ve0, self._xad0))]

    def limit_values(self, ctx):
        """Current limits of the held states (only VEMAX moves: with XadIfd and SE(VE))."""
        p = self.p
        inf = np.full(self.n, np.inf)
        ve = ctx.x[..., self._sls[4]]
        xad = ctx.sig["XadIfd"][..., self._mi]
        lo = np.concatenate([np.where(self._nw, p["VPMIN"], -inf), np.broadcast_to(p["VRMIN"], (self.n,)),
                             np.where(self._vel, p["VEMIN"], -inf)])
        hi = np.concatenate([np.where(self._nw, p["VPMAX"], inf), np.broadcast_to(p["VRMAX"], (self.n,)),
                             self._vemax(ve, xad)])
        return lo, hi

    def init(self, system, x, sig):
        p = self.p
        m = self.mach
        vf0, v, xad = sig["vf0"][m], sig["Ecomp0"][m], sig["XadIfd"][m]
        VE0 = ve_for_efd(vf0, p["KC"], xad)
        vfe0 = self.EX.vfe(VE0) + p["KD"] * xad
        vpid0 = vfe0 / p["KA"]
        self.vref0 = np.asarray(v, float).copy()
        self._ve0, self._xad0 = VE0, np.asarray(xad, float).copy()
        x[self.sl(0)] = self.LG.init(v)
        x[self.sl(1)] = vpid0
        x[self.sl(2)] = self.PDf.init(0.0 * vpid0)
        x[self.sl(3)] = vfe0
        x[self.sl(4)] = VE0
        big = np.where(self._nw, np.inf, 0.0)   # a tracking PID's output is cut, not held
        self.initial_bounds = [("VPID", vpid0, p["VPMIN"] - big, p["VPMAX"] + big, "VPMIN", "VPMAX")]

    def compute(self, ctx):
        xp = self.xp
        p = self.p
        m = self._mi
        lg, xi, xd, vr, ve = (ctx.x[..., s] for s in self._sls)
        s = ctx.sig
        v = take(xp, s["Ecomp"], m)
        xad = take(xp, s["XadIfd"], m)
        vi = self.vref0 - self.LG.output(lg, v) + take(xp, s["vs"], m)
        ys = p["kP"] * vi + xi + self.PDf.output(xd, vi)     # PID before its limiter
        vpid = hard_limit(ys, p["VPMIN"], p["VPMAX"], xp)
        dxi = xp.where(self._nw, p["kI"] * vi, self.PIt.Ki * (vi - self.PIt.Ks * (ys - vpid)))
        vfe = self.EX.vfe(ve) + p["KD"] * xad
        efd = _efd(ve, p["KC"], xad, xp)
        f = ctx.f
        f[..., self._sls[0]] = self.LG.deriv(lg, v)
        f[..., self._sls[1]] = dxi
        f[..., self._sls[2]] = self.PDf.deriv(xd, vi)
        f[..., self._sls[3]] = self.LA.deriv(vr, vpid)
        f[..., self._sls[4]] = (self.LA.output(vr, vpid) - vfe) / p["TE"]
        put(xp, s["vf"], m, efd)
        o = ctx.out
        o["AC8B.vi"], o["AC8B.VPID"], o["AC8B.VFE"], o["AC8B.vout"] = vi, vpid, vfe, efd
