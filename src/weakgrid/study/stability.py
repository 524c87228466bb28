"""Is a run stable? The one definition the claim table and the sweep maps judge by.

A run is *not stable* when it failed (voltage collapse, loss of synchronism, Newton failure,
…: ``failed``/``status`` and its ``failure``; :func:`weakgrid.study.failure.failure_kind`), or
when the stability verdict of its SG speed or dc-link voltage (``speed_verdict``,
``vdc_verdict``, from :func:`weakgrid.study.metrics.stability_verdict`) is ``unstable`` (it
grows or runs away from its set-point) or ``undamped`` (a sustained oscillation). A signal a
run does not record, or whose record is ``too short`` to judge (a 1-s quick-sweep run), is
not evidence either way.
"""

from __future__ import annotations

import math

from .failure import failure_kind

__all__ = ["STABILITY_SIGNALS", "run_failed", "run_instability"]

#: The signals whose stability a run is judged on: metric prefix → name in the verdict text
#: (the runner's ``<prefix>_verdict``).
STABILITY_SIGNALS = (("speed", "SG speed"), ("vdc", "dc link"))


def _get(r, key):
    v = r.get(key) if r is not None else None
    return None if v is None or (isinstance(v, float) and math.isnan(v)) else v


def run_failed(r) -> bool:
    """Whether run ``r`` (its metrics: a dict, or a sweep table's row) did not finish: its
    ``failed`` flag, or a sweep row's ``status`` other than ``"ok"``."""
    if r is None:
        return False
    status = _get(r, "status")
    return bool(_get(r, "failed")) or (status is not None and status != "ok")


def run_instability(r) -> str:
    """Why run ``r`` (its metrics: a dict, or a sweep table's row) is not stable, or ``""``
    when nothing says so.

    ``"failed: <cause>"`` for a run that did not finish; ``"not stable: <signal>
    unstable|undamped"`` (signals joined by ", ") for a stability verdict other than stable.
    Keys a run does not record are skipped (``{}`` and None are stable: nothing says
    otherwise).
    """
    if run_failed(r):
        return f"failed: {failure_kind(_get(r, 'failure')) or 'failed'}"
    why = [f"{name} {v}" for key, name in STABILITY_SIGNALS
           if (v := _get(r, f"{key}_verdict")) in ("unstable", "undamped")]
    return "not stable: " + ", ".join(why) if why else ""
