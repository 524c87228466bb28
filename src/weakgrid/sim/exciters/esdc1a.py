"""ESDC1A: IEEE 421.5-2005 type DC1A exciter (PSS/E ESDC1A); base of ESDC2A.

Block diagram (pu, times in s)::

    v --[Lag 1/(1+sTR)]--> LG
    vsen = LG if TR_used else v                          (sensed voltage; TR_used = 0: ANDES 2.0)
    vi = vref - vsen - WF + vs                           (vs: PSS output)
    vi --[LeadLag (1+sTC)/(1+sTB)]--> LL
    LL --[Lag KA/(1+sTA), non-windup VRMIN..VRMAX]--> VR
    TE dEfd/dt = VR - (KE*Efd + Efd*SE(Efd))             (DC exciter, quadratic saturation)
    Efd --[Washout s*KF/(1+sTF1)]--> WF                  (rate feedback)

DC2A (:class:`~weakgrid.sim.exciters.esdc2a.ESDC2A`) is the same diagram with the regulator
limits scaled by the terminal voltage. ``VRMAX = 0`` means no upper limit; ``TB = TC = 0``
passes the signal; ``TR = 0`` removes the sensing lag. No under-excitation limiter (its HV
gate is absent, as in ANDES); ``Switch`` is accepted and unused (as in PSS/E). ``KE = 0``
is taken as given (PSS/E's "KE = 0: computed at initialization" is not implemented).

Differences from ANDES 2.0 (documented, not copied):

* as in its ESDC2A, ANDES feeds the unfiltered bus voltage to the summing junction (its
  ``TR`` lag is computed but unused); the flag ``TR_used = 0`` reproduces it
  (``from_andes(..., conventions="andes")``). They agree for ``TR = 0``.
* ANDES 2.0's ESDC1A derives from its ESDC2A and replaces the limits ``VRMAX*Vt``,
  ``VRMIN*Vt`` by constants after the regulator block was built, so the block keeps the
  discarded ones, which are never evaluated (value 0): ANDES stops at initialization
  (``TypeError`` in its limit adjustment) on every ESDC1A, e.g. ``ieee14_esdc1a``. The peer
  tests point ANDES's regulator block at the constant limits before its initialization
  (:func:`weakgrid.sim.peer.andes_case.fix_andes_esdc1a`), which makes it the DC1A diagram.
"""

from __future__ import annotations

import numpy as np

from ..blocks import Lag, LagNonWindup, LeadLag, Washout
from ..control_base import MachineControl
from ..namespace import put, take
from ..params import Param
from .dc_common import DCExciter, vrmax_or_unlimited


class ESDC1A(MachineControl):
    """IEEE DC1A exciter. Times [s]: TR, TA, TB, TC, TE, TF1; gains [pu]: KA, KE, KF;
    VRMAX, VRMIN [pu]; E1, SE1, E2, SE2 (saturation of the DC exciter, pu of Efd)."""

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    kind = "exciter"
    #: the voltage reference and the compensated voltage at init (ESDC2A's limit): per batch member
    batch_params = ("vref0", "_vt0")
    order = 2
    #: PSS/E .dyr record after IBUS 'MODEL' ID (ICONs, then CONs: Program Application Guide order)
    psse_record = ("TR", "KA", "TA", "TB", "TC", "VRMAX", "VRMIN", "KE", "TE", "KF", "TF1",
                   "Switch", "E1", "SE1", "E2", "SE2")
    params = (
        Param("TR", 0.01, "s", "sensing time constant", "nonneg"),
        Param("KA", 80.0, "pu", "regulator gain", "pos"),
        Param("TA", 0.04, "s", "regulator time constant", "pos"),
        Param("TB", 1.0, "s", "lag time constant", "nonneg"),
        Param("TC", 1.0, "s", "lead time constant", "nonneg"),
        Param("VRMAX", 7.3, "pu", "maximum regulator output (0: unlimited)", ""),
        Param("VRMIN", -7.3, "pu", "minimum regulator output", ""),
        Param("KE", 1.0, "pu", "exciter constant", ""),
        Param("TE", 0.8, "s", "exciter time constant", "pos"),
        Param("KF", 0.1, "pu", "rate feedback gain", "nonneg"),
        Param("TF1", 1.0, "s", "rate feedback time constant", "pos"),
        Param("Switch", 0.0, "-", "unused (PSS/E)", ""),
        Param("TR_used", 1.0, "-", "1: the sensed voltage passes through TR (IEEE 421.5); "
              "0: the unfiltered voltage enters the summing junction (ANDES 2.0)", "flag"),
        Param("E1", 0.0, "pu", "first saturation point", "nonneg"),
        Param("SE1", 0.0, "pu", "saturation at E1", "nonneg"),
        Param("E2", 0.0, "pu", "second saturation point", "nonneg"),
        Param("SE2", 0.0, "pu", "saturation at E2", "nonneg"),
    )
    states = ("LG", "LL", "VR", "Efd", "WF")
    outputs = ("vi", "vout")
    limit_fields = {"VR": ("VRMIN", "VRMAX")}

    def setup(self, system):
        super().setup(system)
        p = self.p
        self.LG = Lag(1.0, p["TR"])
        self.LL = LeadLag(p["TC"], p["TB"])
        self._vrmax = vrmax_or_unlimited(p["VRMAX"])
        self.LA = LagNonWindup(p["KA"], p["TA"], p["VRMIN"], self._vrmax)
        self.EX = DCExciter(p["KE"], p["TE"], p["E1"], p["SE1"], p["E2"], p["SE2"])
        self.WF = Washout(p["KF"], p["TF1"])
        self._lagged = p["TR_used"] > 0

    def limits(self):
        return [(self.idx("VR"), self.p["VRMIN"], self._vrmax)]

    def init(self, system, x, sig):
        m = self.mach
        vf0, v = sig["vf0"][m], sig["Ecomp0"][m]
        self._vt0 = v.copy()
        vr0 = self.EX.vr0(vf0)
        vi0 = vr0 / self.p["KA"]
        self.vref0 = v + vi0
        x[self.sl(0)] = self.LG.init(v)
        x[self.sl(1)] = self.LL.init(vi0)
        x[self.sl(2)] = vr0
        x[self.sl(3)] = vf0
        x[self.sl(4)] = self.WF.init(vf0)

    def compute(self, ctx):
        xp = self.xp
        m = self._mi
        lg, ll, vr, efd, wf = (ctx.x[..., s] for s in self._sls)
        s = ctx.sig
        v = take(xp, s["Ecomp"], m)
        sensed = xp.where(self._lagged, self.LG.output(lg, v), v)
        vi = self.vref0 - sensed - self.WF.output(wf, efd) + take(xp, s["vs"], m)
        f = ctx.f
        f[..., self._sls[0]] = self.LG.deriv(lg, v)
        f[..., self._sls[1]] = self.LL.deriv(ll, vi)
        f[..., self._sls[2]] = self.LA.deriv(vr, self.LL.output(ll, vi))
        f[..., self._sls[3]] = self.EX.deriv(efd, vr)
        f[..., self._sls[4]] = self.WF.deriv(wf, efd)
        put(xp, s["vf"], m, efd)
        o = ctx.out
        o[f"{self.type_name}.vi"], o[f"{self.type_name}.vout"] = vi, efd
