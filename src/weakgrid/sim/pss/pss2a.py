"""PSS2A: IEEE 421.5 dual-input stabilizer type 2A (PSS/E PSS2A).

Two inputs (ICONs ``ICS1``, ``ICS2``: 1 speed deviation, 3 electrical power on MBASE, 5 terminal
voltage), each through two washouts and a transducer lag; the ramp-tracking filter
``[(1+sT8)/(1+sT9)^M]^N`` acts on ``yt1 + KS3*yt2``, the second input is subtracted after it
(the "integral of accelerating power" signal), then the gain ``KS1``, two lead-lags and the
output limits ``[VSTMIN, VSTMAX]``. The block diagram, input codes and zero-parameter
conventions are in :mod:`weakgrid.sim.pss._pss2`.
"""

from __future__ import annotations

from ._pss2 import BASE_PARAMS, N_RTF, OUT_PARAMS, PSSE_ICONS, DualInputPSS


class PSS2A(DualInputPSS):
    """Dual-input PSS type 2A. Parameters: ICS1, ICS2 (input codes), M, N (ramp-tracking filter
    orders); TW1..TW4, T1..T4, T6..T9 [s]; KS1, KS2, KS3 [pu]; VSTMAX, VSTMIN [pu].

    PSS/E record (after ``IBUS 'PSS2A' ID``): ICONs ``ICS1 REMBUS1 ICS2 REMBUS2 M N``, CONs
    ``TW1 TW2 T6 TW3 TW4 T7 KS2 KS3 T8 T9 KS1 T1 T2 T3 T4 VSTMAX VSTMIN`` (6 + 17 fields).
    """

    array_api = True      # its evaluation runs on any array namespace (weakgrid.sim.namespace)

    params = BASE_PARAMS + OUT_PARAMS
    LEAD_LAGS = (("T1", "T2"), ("T3", "T4"))
    states = DualInputPSS._HEAD + ("LL1", "LL2")
    psse_record = PSSE_ICONS + tuple(p.name for p in BASE_PARAMS[4:] + OUT_PARAMS)

    assert len(states) == 6 + N_RTF + 2
