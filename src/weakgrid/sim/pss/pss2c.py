"""PSS2C: IEEE 421.5-2016 dual-input stabilizer type 2C (PSS/E PSS2C).

PSS2B (:mod:`weakgrid.sim.pss.pss2b`) with a fourth lead-lag ``(1+sT12)/(1+sT13)`` and the
output logic of IEEE 421.5-2016: the output is switched off when the generator's electrical
power ``PT`` [pu on MBASE] falls to ``PSSOFF`` and back on when it reaches ``PSSON``
(hysteresis; between the two thresholds the last state holds; ``PSSON < 0`` disables the
logic). The switch state is evaluated from the state of the last accepted point (discrete
memory, updated in :meth:`accept`); at the initial point it is on unless ``PT0 <= PSSOFF``.
``Xcomp``, ``Tcomp`` belong to the compensated-frequency input (code 7), which weakgrid does not
provide (refused naming the ICON), so they are read and unused. The block diagram, input codes
and zero-parameter conventions are in :mod:`weakgrid.sim.pss._pss2`.
"""

from __future__ import annotations

from ..namespace import put, take
from ..params import Param
from ._pss2 import BASE_PARAMS, N_RTF, OUT_PARAMS, PSSE_ICONS, DualInputPSS
from .pss2b import _EXTRA, PSS2B

_EXTRA_C = (
    Param("T12", 0.0, "s", "fourth lead", "nonneg"),
    Param("T13", 0.0, "s", "fourth lag (0: the lead-lag is a unit gain)", "nonneg"),
    Param("PSSON", -1.0, "pu", "electrical power [MBASE] at which the output is switched on "
          "(< 0: no output logic)", ""),
    Param("PSSOFF", -1.0, "pu", "electrical power [MBASE] at which the output is switched off", ""),
    Param("Xcomp", 0.0, "pu", "compensating reactance of the compensated frequency (input code 7, unused)", ""),
    Param("Tcomp", 0.0, "s", "time constant of the compensated frequency (input code 7, unused)", "nonneg"),
)


class PSS2C(PSS2B):
    """Dual-input PSS type 2C. Parameters: those of PSS2B plus T12, T13 [s], the output logic
    thresholds PSSON, PSSOFF [pu on MBASE] and Xcomp, Tcomp (unused).

    PSS/E record (after ``IBUS 'PSS2C' ID``): ICONs ``ICS1 REMBUS1 ICS2 REMBUS2 M N``, CONs
    ``TW1 TW2 T6 TW3 TW4 T7 KS2 KS3 T8 T9 KS1 T1 T2 T3 T4 T10 T11 VS1MAX VS1MIN VS2MAX VS2MIN
    VSTMAX VSTMIN T12 T13 PSSON PSSOFF Xcomp Tcomp`` (6 + 29 fields).
    """

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    params = BASE_PARAMS + _EXTRA + OUT_PARAMS + _EXTRA_C
    LEAD_LAGS = (("T1", "T2"), ("T3", "T4"), ("T10", "T11"), ("T12", "T13"))
    states = DualInputPSS._HEAD + ("LL1", "LL2", "LL3", "LL4")
    outputs = DualInputPSS.outputs + ("on",)
    psse_record = PSSE_ICONS + tuple(p.name for p in BASE_PARAMS[4:] + _EXTRA + OUT_PARAMS + _EXTRA_C)

    assert len(states) == 6 + N_RTF + 4

    def init(self, system, x, sig):
        super().init(system, x, sig)
        pt0 = sig["Pe0"][self.mach] * self._pe_scale
        self._on = ~((self.p["PSSON"] >= 0) & (pt0 <= self.p["PSSOFF"]))

    def _switch(self, pt):
        xp, p = self.xp, self.p
        on = xp.where(pt >= p["PSSON"], True, xp.where(pt <= p["PSSOFF"], False, self._on))
        return xp.where(p["PSSON"] < 0, True, on)

    def compute(self, ctx):
        super().compute(ctx)
        xp, m = self.xp, self._mi
        on = self._switch(take(xp, ctx.sig["Pe"], m) * self._pe_scale)
        vs = xp.where(on, take(xp, ctx.sig["vs"], m), 0.0)
        put(xp, ctx.sig["vs"], m, vs)
        ctx.out["PSS2C.vs"], ctx.out["PSS2C.on"] = vs, xp.astype(on, xp.float64)

    def accept(self, t, ctx):
        """Keep the switch state of the accepted point (hysteresis memory)."""
        self._on = ctx.out["PSS2C.on"] > 0.5
