"""Is a run stable? The one definition the claim table and the sweep maps judge by.

A run is *not stable* when it failed (voltage collapse, loss of synchronism, Newton failure,
…: ``failed``/``status`` and its ``failure``; :func:`weakgrid.study.failure.failure_kind`), or
when the stability verdict of its SG speed or dc-link voltage (``speed_verdict``,
``vdc_verdict``, from :func:`weakgrid.study.metrics.stability_verdict`) is ``unstable`` (it
grows or runs away from its set-point) or ``undamped`` (a sustained oscillation), or when
that signal is **not back**: it never enters its 2 % settling band (``<signal>_settling_s``
recorded but undefined) and ends farther than :data:`RETURN_FRACTION` of its peak deviation
from its set-point (``<signal>_final_dev_pu`` against ``<signal>_peak_dev_pu``). The last
rule catches what the verdict's two windows cannot: a large swing that shrinks from one
window to the next while its mean drifts away (an EMT run of case 1 whose SG speed ends
1.3 % off after swinging 2.3 %, its dc link swinging ±0.4 pu, is "stable" to the verdict
and not back here); a swing still decaying near its set-point at the end of a short record
(case 1's 0.5-Hz mode ends 4–12 % of its peak away after 3 s) is back. A signal a run does
not record, or whose record is ``too short`` to judge (a 1-s quick-sweep run), is not
evidence either way.
"""

from __future__ import annotations

import math

from .failure import failure_kind

__all__ = ["RETURN_FRACTION", "STABILITY_SIGNALS", "metric", "run_failed", "run_instability"]

#: The signals whose stability a run is judged on: metric prefix → name in the verdict text
#: (the runner's ``<prefix>_verdict``).
STABILITY_SIGNALS = (("speed", "SG speed"), ("vdc", "dc link"))

#: A signal that never settles counts as not back when it ends farther than this fraction of
#: its peak deviation from its set-point [–] (a judgement: a run half-way back or worse at
#: its end cannot be credited with a cost or a win).
RETURN_FRACTION = 0.5


def metric(r, key):
    """Metric ``key`` of run ``r`` (a dict or a table row; None: no run), or None when it is
    missing or NaN (undefined for the run)."""
    v = r.get(key) if r is not None else None
    return None if v is None or (isinstance(v, float) and math.isnan(v)) else v


def run_failed(r) -> bool:
    """Whether run ``r`` (its metrics: a dict, or a sweep table's row) did not finish: its
    ``failed`` flag, or a sweep row's ``status`` other than ``"ok"``."""
    if r is None:
        return False
    status = metric(r, "status")
    return bool(metric(r, "failed")) or (status is not None and status != "ok")


def run_instability(r) -> str:
    """Why run ``r`` (its metrics: a dict, or a sweep table's row) is not stable, or ``""``
    when nothing says so.

    ``"failed: <cause>"`` for a run that did not finish; ``"not stable: <signal>
    unstable|undamped"`` for a stability verdict other than stable, ``"not stable: <signal>
    not back (ends … pu from its set-point, … % of its peak deviation)"`` for a signal that
    never settles and ends beyond :data:`RETURN_FRACTION` of its peak (signals joined by
    ", "). Keys a run does not record are skipped (``{}`` and None are stable: nothing says
    otherwise), and so is a signal whose verdict is ``too short``.
    """
    if run_failed(r):
        return f"failed: {failure_kind(metric(r, 'failure')) or 'failed'}"
    why = []
    for key, name in STABILITY_SIGNALS:
        v = metric(r, f"{key}_verdict")
        if v in ("unstable", "undamped"):
            why.append(f"{name} {v}")
        elif v != "too short" and r is not None and f"{key}_settling_s" in r \
                and metric(r, f"{key}_settling_s") is None:
            fin, pk = metric(r, f"{key}_final_dev_pu"), metric(r, f"{key}_peak_dev_pu")
            if fin is not None and pk and abs(fin) > RETURN_FRACTION * pk:
                why.append(f"{name} not back (ends {abs(fin):.3g} pu from its set-point, "
                           f"{abs(fin) / pk * 100:.0f} % of its peak deviation)")
    return "not stable: " + ", ".join(why) if why else ""
