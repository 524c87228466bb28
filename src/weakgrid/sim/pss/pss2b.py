"""PSS2B: IEEE 421.5 dual-input stabilizer type 2B (PSS/E PSS2B).

PSS2A (:mod:`weakgrid.sim.pss.pss2a`) with input limits — each raw input clipped to
``[VS1MIN, VS1MAX]`` / ``[VS2MIN, VS2MAX]`` before its washouts — and a third lead-lag
``(1+sT10)/(1+sT11)``. The block diagram, input codes and zero-parameter conventions are in
:mod:`weakgrid.sim.pss._pss2`. ``T11 = 0`` makes the third lead-lag a unit gain.
"""

from __future__ import annotations

from ..params import Param
from ._pss2 import BASE_PARAMS, N_RTF, OUT_PARAMS, PSSE_ICONS, DualInputPSS

_EXTRA = (
    Param("T10", 0.0, "s", "third lead", "nonneg"),
    Param("T11", 0.0, "s", "third lag (0: the lead-lag is a unit gain)", "nonneg"),
    Param("VS1MAX", 999.0, "pu", "input 1 upper limit", ""),
    Param("VS1MIN", -999.0, "pu", "input 1 lower limit", ""),
    Param("VS2MAX", 999.0, "pu", "input 2 upper limit", ""),
    Param("VS2MIN", -999.0, "pu", "input 2 lower limit", ""),
)


class PSS2B(DualInputPSS):
    """Dual-input PSS type 2B. Parameters: those of PSS2A plus T10, T11 [s] (third lead-lag)
    and the input limits VS1MAX, VS1MIN, VS2MAX, VS2MIN [pu, in the input's unit].

    PSS/E record (after ``IBUS 'PSS2B' ID``): ICONs ``ICS1 REMBUS1 ICS2 REMBUS2 M N``, CONs
    ``TW1 TW2 T6 TW3 TW4 T7 KS2 KS3 T8 T9 KS1 T1 T2 T3 T4 T10 T11 VS1MAX VS1MIN VS2MAX VS2MIN
    VSTMAX VSTMIN`` (6 + 23 fields).
    """

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    params = BASE_PARAMS + _EXTRA + OUT_PARAMS
    LEAD_LAGS = (("T1", "T2"), ("T3", "T4"), ("T10", "T11"))
    states = DualInputPSS._HEAD + ("LL1", "LL2", "LL3")
    psse_record = PSSE_ICONS + tuple(p.name for p in BASE_PARAMS[4:] + _EXTRA + OUT_PARAMS)

    assert len(states) == 6 + N_RTF + 3

    def _limit_inputs(self, u1, u2):
        xp, p = self.xp, self.p
        return (xp.minimum(xp.maximum(u1, p["VS1MIN"]), p["VS1MAX"]),
                xp.minimum(xp.maximum(u2, p["VS2MIN"]), p["VS2MAX"]))
