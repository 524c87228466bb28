"""Performance metrics of a simulated response (the tables of ``weakgrid reproduce``).

All functions take sampled signals ``(t, y)`` with ``t`` in seconds. A response
is measured from ``t_start`` (e.g. the fault clearance) against its final value
``y_final`` (by default the mean over the last ``tail`` seconds).

Definitions used throughout the reports:

* **deviation** ``e(t) = y(t) − y_final``;
* **overshoot** — the peak ``max |e(t)|`` after ``t_start`` (in the signal's unit
  and, where a reference is given, in % of it): for a post-fault oscillation there
  is no step, so the peak excursion is the overshoot;
* **backswing (overshoot past the final value)** — after ``t_start`` the largest
  excursion of the sign opposite to the deviation at ``t_start``: the first swing is
  set by the fault (the controller is bypassed), the backswing by the controller;
* **settling time (2 % band)** — the last time after ``t_start`` at which
  ``|e(t)|`` exceeds 2 % of that peak, measured from ``t_start``;
* **ITAE** — ``∫ (t − t_start)·|e(t)| dt`` (trapezoid rule);
* **control cost** — ``Σ_k u_k'R u_k · T`` over the controller's samples, with ``u``
  as applied (limited to the UPQC rating; the demanded one is reported too);
* **running cost of (18)** — ``Σ_{j≤k} x_j'Qx_j + u_j'Ru_j`` along the samples;
* **definition sensitivity** (``<metric>_def_unc``, relative) — how much a metric moves when
  its own definition's parameter moves, re-measured on the same trajectory
  (:func:`definition_spread`): the settling time with the band at 1.5 % and 3 % around the
  default 2 % (:data:`SETTLING_BANDS`); the backswing against the final value (mean over the
  last ``tail``) instead of the pre-fault set-point; ITAE and the costs summed to
  ``tail`` (0.5 s) before the run's end instead of to its end. It is one half of a metric's
  measured uncertainty (the other: step halving); :mod:`weakgrid.study.ties` adds them.
"""

from __future__ import annotations

import numpy as np

from ..game.errors import ParameterError, ShapeError

__all__ = ["settling_time", "itae", "backswing", "control_cost",
           "running_cost", "stability_verdict", "definition_spread", "SETTLING_BANDS"]

#: The settling band's alternatives around the default 2 % (the definition sensitivity).
SETTLING_BANDS = (0.015, 0.03)


def _check(t, y):
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    if t.ndim != 1 or y.shape != t.shape:
        raise ShapeError("y", y.shape, f"same shape as t {t.shape}")
    if t.size < 2 or np.any(np.diff(t) < 0) or t[-1] <= t[0]:
        raise ParameterError("t", "…", "time must not decrease (repeated instants at "
                             "discontinuities are fine) and must span at least two samples")
    return t, y


def _final(t, y, tail):
    sel = t >= t[-1] - tail
    return float(np.mean(y[sel]))


def settling_time(t, y, t_start=0.0, band=0.02, y_final=None, tail=0.5) -> float:
    """Last time after ``t_start`` where ``|y − y_final| > band·peak`` (s after t_start).

    Returns ``nan`` if the response never settles inside the record (still
    outside the band in the final ``tail`` seconds).
    """
    t, y = _check(t, y)
    yf = _final(t, y, tail) if y_final is None else float(y_final)
    sel = t >= t_start
    e = np.abs(y[sel] - yf)
    ts = t[sel]
    if e.size == 0 or e.max() == 0:
        return 0.0
    thr = band * e.max()
    out = np.flatnonzero(e > thr)
    if out.size == 0:
        return 0.0
    last = out[-1]
    if ts[last] >= t[-1] - tail:
        return float("nan")
    # interpolate the crossing between the last sample outside and the next one
    if last + 1 < ts.size:
        e0, e1 = e[last], e[last + 1]
        frac = (e0 - thr) / (e0 - e1) if e0 != e1 else 0.0
        return float(ts[last] + frac * (ts[last + 1] - ts[last]) - t_start)
    return float(ts[last] - t_start)


def backswing(t, y, t_start=0.0, y_final=None, tail=0.5) -> float:
    """Largest excursion after ``t_start`` opposite in sign to the deviation at ``t_start``."""
    t, y = _check(t, y)
    yf = _final(t, y, tail) if y_final is None else float(y_final)
    sel = t >= t_start
    e = y[sel] - yf
    if e.size == 0:
        return float("nan")
    s = np.sign(e[0]) or 1.0
    return float(max(0.0, np.max(-s * e)))


def itae(t, y, t_start=0.0, y_final=None, tail=0.5) -> float:
    """``∫ (t − t_start)·|y − y_final| dt`` from ``t_start`` (trapezoid rule)."""
    t, y = _check(t, y)
    yf = _final(t, y, tail) if y_final is None else float(y_final)
    sel = t >= t_start
    tt = t[sel] - t_start
    # SciPy's trapezoid (the rule of NumPy's np.trapezoid)
    from scipy.integrate import trapezoid

    return float(trapezoid(tt * np.abs(y[sel] - yf), tt))


def control_cost(u, R, T) -> float:
    """``Σ_k u_k'R u_k · T`` for controller samples ``u`` (N, m) held for ``T`` s."""
    u = np.atleast_2d(np.asarray(u, float))
    R = np.atleast_2d(np.asarray(R, float))
    if R.shape == (1, 1):
        R = R[0, 0] * np.eye(u.shape[1])
    return float(np.einsum("ki,ij,kj->", u, R, u) * T)


def running_cost(x, u, Q, R) -> np.ndarray:
    """Cumulative ``Σ_{j≤k} x_j'Qx_j + u_j'Ru_j`` along the samples (N,)."""
    x = np.atleast_2d(np.asarray(x, float))
    u = np.atleast_2d(np.asarray(u, float))
    return np.cumsum(np.einsum("ki,ij,kj->k", x, Q, x) + np.einsum("ki,ij,kj->k", u, R, u))


def stability_verdict(t, y, t_start=0.0, tail=1.0, settled_fraction=0.05,
                      y_set=None) -> str:
    """The stability of a response after ``t_start``: ``"stable"``, ``"unstable"``,
    ``"undamped"`` or ``"too short"``.

    Two tests, in this order, with ``tail`` [s] the judging window (the last ``tail``
    seconds; the ``tail`` before it is the previous window) and ``D = max |y − y_set|`` after
    ``t_start`` the peak deviation from the set-point (the signal's unit, e.g. pu):

    1. **runaway** (a monotonic divergence, e.g. a dc link ramping away) → ``"unstable"``
       when the signal ends at its largest deviation from the set-point
       (``|y_end − y_set| ≥ (1 − settled_fraction)·D``), stays on one side of the set-point
       throughout the last window (it does not cross it: no swing about it), and its mean
       distance from the set-point over the last window exceeds that over the previous one
       by more than ``settled_fraction·D`` (it is still moving away). A decaying swing ends
       far below its peak; a sustained oscillation about the set-point crosses it within
       any window longer than half its period; a signal settled at a new operating point
       off the set-point (e.g. a droop frequency) has a steady mean distance. A signal still
       drifting away at the record's end towards an operating point it has not reached is
       judged unstable too: the record does not show it stops (lengthen the run).
    2. **oscillation**, measured about the signal's own final value (the mean of the last
       window): ``"stable"`` if its amplitude in the last window is ≤ ``settled_fraction``
       of its peak or decays (< 0.8 × the previous window's); ``"unstable"`` if it grows
       (> 1.2 ×); ``"undamped"`` otherwise (a sustained oscillation).

    Both tests see a mode whose period is at most ``2·tail`` (≥ 0.5 Hz with the default
    1 s); a slower swing can look like a runaway or a growth within one window. A record
    with non-finite samples is ``"unstable"``; a record that ends within ``tail`` of
    ``t_start`` (no previous window to compare with, e.g. a 1-s sweep run with its fault
    cleared at 0.25 s) is ``"too short"``: neither test can tell (it was ``"undamped"``
    whatever the signal did).

    Parameters
    ----------
    t, y : array_like
        Time [s] and the signal (any unit; e.g. SG speed or dc-link voltage in pu).
    t_start : float
        Judge from this time [s] on (e.g. the last disturbance's end).
    tail : float
        Window length [s].
    settled_fraction : float
        Fraction of the peak deviation [–] below which a swing is settled, and the growth of
        the mean distance from the set-point that counts as moving away.
    y_set : float, optional
        The set-point (the signal's unit; e.g. its pre-disturbance value). Default: ``y`` at
        the first sample of the record (pass it when the record starts after the
        disturbance).
    """
    t, y = _check(t, y)
    sel = t >= t_start
    tt, yy = t[sel], y[sel]
    if not np.all(np.isfinite(yy)):
        return "unstable"
    ys = float(y[0]) if y_set is None else float(y_set)
    late_w = tt >= tt[-1] - tail
    prev_w = (tt >= tt[-1] - 2 * tail) & ~late_w
    if not prev_w.any():
        return "too short"
    # 1. runaway: ends at its largest deviation, one-sided, still moving away
    d = yy - ys
    big = np.abs(d).max()
    if big > 0:
        dl = d[late_w]
        one_sided = np.all(dl > 0) or np.all(dl < 0)
        growth = np.abs(dl).mean() - np.abs(d[prev_w]).mean()
        if (abs(d[-1]) >= (1 - settled_fraction) * big and one_sided
                and growth > settled_fraction * big):
            return "unstable"
    # 2. oscillation about its own final value
    yf = _final(tt, yy, tail)
    e = np.abs(yy - yf)
    peak = e.max()
    if peak == 0:
        return "stable"
    late = e[late_w]
    amp_late = late.max()
    amp_prev = e[prev_w].max()
    if amp_late <= settled_fraction * peak:
        return "stable"
    if amp_late > 1.2 * amp_prev:
        return "unstable"
    return "undamped" if amp_late > 0.8 * amp_prev else "stable"


def definition_spread(value, alternatives) -> float:
    """``max |alt − value| / |value|`` over ``alternatives`` (the same metric re-measured
    with its definition's parameter moved), relative [–].

    ``nan`` when ``value`` is not finite, or is 0 while an alternative is not (a relative
    spread of 0 is undefined; a relative uncertainty times the value adds nothing there
    anyway); ``0`` when every alternative equals ``value``; alternatives that are not finite
    are skipped (pass a bound instead: e.g. a
    settling time that is undefined at a tighter band is at least the record's length).
    """
    value = float(value)
    if not np.isfinite(value):
        return float("nan")
    alts = [float(a) for a in alternatives if np.isfinite(a)]
    if not alts:
        return 0.0
    d = max(abs(a - value) for a in alts)
    if value == 0:
        return 0.0 if d == 0 else float("nan")
    return float(d / abs(value))
