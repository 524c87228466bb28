"""One tie rule for the claim table and the maps: a difference below the measured uncertainty.

The uncertainty of one run's metric ``m`` is relative and the sum of two measured parts:

* **step halving** — ``|m(T) − m(T/2)| / |m(T)|`` of the study's ``[sweep.dt_check]`` runs
  (:func:`weakgrid.study.sweep_maps.metric_uncertainty`; per map row in the maps);
* **definition** — ``<metric>_def_unc``, the metric re-measured on the run's own trajectory
  with its definition's parameter moved (the settling band 1.5 %/3 % around 2 %, …;
  :func:`weakgrid.study.metrics.definition_spread`), recorded with every run.

Two runs a and b tie on ``m`` when ``|m_a − m_b| ≤ u_a·|m_a| + u_b·|m_b|``. A part not
measured counts 0; with neither measured, no tie is possible (a strict comparison).
"""

from __future__ import annotations

import math

__all__ = ["DEF_SUFFIX", "run_uncertainty", "compare", "unc_text"]

#: Column (metric key) suffix of a metric's definition sensitivity.
DEF_SUFFIX = "_def_unc"


def _finite(v):
    try:
        v = float(v)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def run_uncertainty(row, metric: str, step=None) -> float:
    """Relative uncertainty [–] of ``metric`` of one run: ``step`` (step halving, or None when
    not measured) + the run's own ``<metric>_def_unc`` (``row``: its metrics, a dict or a
    table row). Not measured parts count 0."""
    d = _finite(row.get(metric + DEF_SUFFIX)) if row is not None else None
    s = _finite(step)
    return (s or 0.0) + (d or 0.0)


def compare(va, vb, ua=0.0, ub=0.0) -> tuple[str, float]:
    """``("a", tol)`` if ``va < vb`` beyond the uncertainty, ``("b", tol)`` if ``vb < va``,
    ``("tie", tol)`` if ``|va − vb| ≤ tol = ua·|va| + ub·|vb|`` (``ua``, ``ub`` relative);
    ``("n/a", nan)`` if a value is missing."""
    va, vb = _finite(va), _finite(vb)
    if va is None or vb is None:
        return "n/a", math.nan
    tol = (ua or 0.0) * abs(va) + (ub or 0.0) * abs(vb)
    if abs(va - vb) <= tol:
        return "tie", tol
    return ("a" if va < vb else "b"), tol


def unc_text(va, vb, tol) -> str:
    """``"|Δ| 0.012 ≤ uncertainty 0.031"``-style words for a comparison (the claim table)."""
    d = abs(float(va) - float(vb))
    rel = tol / abs(float(vb)) if vb else math.nan
    return (f"|Δ| {d:.3g} {'≤' if d <= tol else '>'} uncertainty {tol:.3g}"
            + (f" (±{rel * 100:.2g} % of the baseline)" if math.isfinite(rel) else ""))
