"""The smallest attenuation level γ the HJI policy iteration accepts (bisection).

The paper names the nonlinear H∞ attenuation level but does not compute it. Here a
γ is *accepted* when

1. the two-loop policy iteration (:func:`~weakgrid.game.hji.solve_hji`) converges,
2. ``Yw = h'∇²J h − 2γ²P ≺ 0`` at every mesh point of Ω (and ``Yu ≻ 0``), and
3. the closed loop under the trained saddle point, ``x+ = f + g·u*(x) + h·w*(x)``
   (the worst-case disturbance feeding back), started from the corners, edge
   midpoints and face centres of Ω, stays inside Ω enlarged ``escape_factor``
   times about its centre and returns to within ``return_fraction`` of Ω's
   half-widths of the origin in ``rollout_steps`` steps.

The lower end of the bracket is the attenuation limit of the linearization at the
origin (:func:`~weakgrid.game.lq.attenuation_limit` on ``system.linearize()`` with
the cost's Q, R, P): near the origin the nonlinear game is its linearization, so
no γ below it can be admissible. The upper end is the problem's own γ if it is
accepted, otherwise the first accepted γ found by doubling it.

Start of the policy iteration (the choice that makes the search work)
---------------------------------------------------------------------
Policy iteration starts from a fixed policy ``u⁽⁰⁾`` and its first inner loop
maximizes the cost over ``w`` against that policy: it diverges (Yw loses
negativity) unless γ exceeds the attenuation limit *of that policy*
(:func:`~weakgrid.game.lq.policy_attenuation_limit` in the LQ case), which for a
fixed LQR-like start can be far above the game's own limit. So each γ is tried
from up to three starts, in this order, and accepted at the first that passes:

* ``continuation`` — the saddle-point control ``u*`` of the controller trained at
  the smallest γ accepted so far (a larger γ); it attenuates disturbances almost
  as well as the saddle policy at the new γ, so the inner loop is well posed;
* ``game-riccati`` — ``u = −K(γ)x``, the saddle-point gain of the linearization's
  game Riccati equation at this very γ (exists for every γ above the lower
  bound); for a linear system with a quadratic basis this policy's own
  attenuation limit is below γ, so the search recovers the game-Riccati limit;
* ``initial`` — the problem's initial policy.

Acceptance is assumed monotone in γ (true for the LQ game); for the nonlinear
approximate method it is an assumption, and the history shows every decision.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .cost import GameCost
from .errors import WeakgridError
from .hji import SolverSettings, solve_hji
from .lq import attenuation_limit, solve_game_riccati
from .policies import LinearPolicy
from .gamma_settings import SearchSettings

__all__ = ["GammaTrial", "GammaSearchResult", "SearchSettings", "search_min_gamma",
           "worst_case_rollout_check"]


@dataclass
class GammaTrial:
    """One γ tried by the search.

    Attributes
    ----------
    gamma : float
    accepted : bool
    reason : str
        Why it was accepted (the start that worked) or rejected (every start's failure).
    start : str or None
        The start that was accepted.
    outer, max_inner : int or None
        Iterations of the accepted run.
    max_eig_Yw : float or None
        Largest eigenvalue of Yw on the mesh for the accepted run.
    final_norm : float or None
        Largest final normalized state of the worst-case rollouts.
    seconds : float
    """

    gamma: float
    accepted: bool
    reason: str
    start: str | None = None
    outer: int | None = None
    max_inner: int | None = None
    max_eig_Yw: float | None = None
    final_norm: float | None = None
    seconds: float = 0.0

    def to_dict(self):
        return dict(self.__dict__)


@dataclass
class GammaSearchResult:
    """The outcome of :func:`search_min_gamma`.

    Attributes
    ----------
    gamma_star : float
        The smallest accepted γ (upper end of the final bracket).
    bracket : (float, float)
        ``(γ_lo, γ_hi)``: γ_lo rejected (or the linear lower bound), γ_hi accepted.
    linear_limit : float
        The game-Riccati attenuation limit of the linearization (the lower bound).
    history : list of GammaTrial
    controller : GameController
        Trained at γ*.
    settings : SearchSettings
    seconds : float
    """

    gamma_star: float
    bracket: tuple
    linear_limit: float
    history: list
    controller: object
    settings: SearchSettings
    seconds: float
    converged: bool = True
    meta: dict = field(default_factory=dict)

    def to_dict(self):
        return {"gamma_star": self.gamma_star, "bracket": list(self.bracket),
                "linear_limit": self.linear_limit, "converged": self.converged,
                "settings": self.settings.to_dict(), "seconds": self.seconds,
                "history": [t.to_dict() for t in self.history], **self.meta}


def _box(mesh):
    return np.asarray(mesh.lower, float), np.asarray(mesh.upper, float)


def _starts_of(mesh):
    if hasattr(mesh, "corners_and_midpoints"):
        return mesh.corners_and_midpoints()
    from .mesh import GridMesh

    lo, hi = _box(mesh)
    return GridMesh(lo, hi, (hi - lo) / 2).corners_and_midpoints()


def worst_case_rollout_check(controller, mesh, steps, escape_factor=10.0, return_fraction=0.05):
    """Roll the closed loop out under ``(u*, w*)`` from the corners/edge midpoints of Ω.

    Returns
    -------
    ok : bool
    final_norm : float
        Largest final state in units of Ω's half-widths (∞-norm).
    reason : str
    """
    lo, hi = _box(mesh)
    centre, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
    x = _starts_of(mesh)
    system = controller.system
    for k in range(int(steps)):
        u, w = controller.saddle_point(x)
        x = system.step(x, u, w)
        if not np.all(np.isfinite(x)):
            return False, float("inf"), f"the worst-case closed loop gave NaN/inf at step {k + 1}"
        dev = np.abs((x - centre) / half).max()
        if dev > escape_factor:
            return False, float(np.abs(x / half).max()), (
                f"the worst-case closed loop left Ω enlarged {escape_factor:g}× at step {k + 1}")
    final = float(np.abs(x / half).max())
    if final > return_fraction:
        return False, final, (f"the worst-case closed loop did not return: after {steps} steps "
                              f"the state is {final:.3g} half-widths of Ω from the origin "
                              f"(> {return_fraction:g})")
    return True, final, "bounded and returns"


def search_min_gamma(system, basis, cost: GameCost, mesh, initial_policy,
                     solver: SolverSettings | None = None,
                     settings: SearchSettings | None = None, *,
                     problem: dict | None = None,
                     progress: Callable[[GammaTrial], None] | None = None,
                     resume=None,
                     checkpoint: Callable | None = None) -> GammaSearchResult:
    """Bisect for the smallest γ accepted by the HJI policy iteration (see the module).

    Parameters
    ----------
    system, basis, cost, mesh, initial_policy, solver
        As for :func:`~weakgrid.game.hji.solve_hji`; ``cost.gamma`` is the first
        upper-bound candidate.
    settings : SearchSettings
    problem : dict, optional
        Recorded in the controller file.
    progress : callable, optional
        Called with each :class:`GammaTrial` as it is decided (not with the trials
        taken from ``resume``).
    resume : SearchState, optional
        Continue an interrupted search of the same inputs
        (:mod:`weakgrid.game.checkpoint`): its decided trials are replayed, not run
        again, and the trial that was running continues its training; the result is
        the same (γ*, bracket, history, controller weights) as that of a search that
        was never interrupted.
    checkpoint : callable, optional
        ``checkpoint(state, finished)`` with a :class:`~weakgrid.game.checkpoint.SearchState`
        after each decided trial and after each failed start of a trial
        (``finished=True``: a unit of work is finished, save it now) and after each
        finished outer iteration of a trial's training (``finished=False``).

    Returns
    -------
    GammaSearchResult

    Raises
    ------
    ConvergenceError
        No accepted γ was found while doubling from ``cost.gamma``.
    CheckpointError
        ``resume`` does not fit this search.
    """
    from .checkpoint import CheckpointError, RunningTrial, SearchState
    from .errors import ConvergenceError

    solver = solver or SolverSettings()
    settings = settings or SearchSettings()
    t0 = time.perf_counter()
    A, B, E = system.linearize()
    g_lin = attenuation_limit(A, B, E, cost.Q, cost.R, cost.P, rtol=min(1e-8, settings.rtol))
    history: list[GammaTrial] = []
    best = {"gamma": None, "controller": None}

    def cost_at(gamma):
        return GameCost(cost.Q, cost.R, cost.P, float(gamma), cost.bound)

    replay = list(resume.trials) if resume is not None else []
    running = resume.running if resume is not None else None
    kept = resume.best if resume is not None else None
    if isinstance(kept, dict):  # the record of a controller: rebuilt on these very objects
        kept = _controller_of(kept, system, basis, cost_at)

    def replayed(gamma):
        """The decided trial at ``gamma`` from ``resume`` (None when there is none left)."""
        if not replay:
            return None
        rec = replay.pop(0)
        if rec.gamma != float(gamma):
            raise CheckpointError("(resume)", f"its trial {len(history) + 1} is at gamma = "
                                  f"{rec.gamma!r}, this search tries {float(gamma)!r}: "
                                  "start over (--restart)")
        ctl = kept if (rec.accepted and kept is not None
                       and kept.cost.gamma == rec.gamma) else None
        return rec, ctl

    def save(decided, current=None):
        if checkpoint is not None:
            checkpoint(SearchState(list(history), best["controller"], current), decided)

    def policy_for(start, gamma):
        if start == "continuation":
            ctl = best["controller"]
            return None if ctl is None else _SaddleControl(ctl)
        if start == "game-riccati":
            try:
                sol = solve_game_riccati(A, B, E, cost.Q, cost.R, cost.P, gamma)
            except WeakgridError:
                return None
            return LinearPolicy(sol.K, name=f"game-Riccati gain of the linearization at "
                                            f"gamma={gamma:.6g}")
        return initial_policy

    def trial(gamma):
        nonlocal running
        done = replayed(gamma)
        if done is not None:
            return done
        t1 = time.perf_counter()
        c = cost_at(gamma)
        reasons, before, go_on, spent = [], None, None, 0.0
        if running is not None:
            if running.gamma != float(gamma) or running.start not in settings.starts:
                raise CheckpointError("(resume)", f"the running trial is at gamma = "
                                      f"{running.gamma!r} ({running.start}), this search "
                                      f"tries {float(gamma)!r}: start over (--restart)")
            reasons, before = list(running.reasons), running.start
            go_on, spent = running.training, running.seconds
            running = None

        def failed(start, why):
            """Record why ``start`` failed; save that the next start is due."""
            reasons.append(f"[{start}] {why}")
            nxt = settings.starts[settings.starts.index(start) + 1:]
            if nxt:
                save(True, RunningTrial(float(gamma), nxt[0], list(reasons),
                                        spent + time.perf_counter() - t1, None))
        for start in settings.starts:
            if before is not None:  # resumed: the starts before this one failed already
                if start != before:
                    continue
                before = None
            pol = policy_for(start, gamma)
            if pol is None:
                continue

            def keep(state, start=start):
                save(False, RunningTrial(float(gamma), start, list(reasons),
                                         spent + time.perf_counter() - t1, state))
            try:
                ctl = solve_hji(system, basis, c, mesh, pol, solver, problem=problem,
                                start=go_on, checkpoint=keep)
            except WeakgridError as exc:
                failed(start, f"{type(exc).__name__}: {_short(exc)}")
                continue
            finally:
                go_on = None
            eu, ew = ctl.block_eigenvalues(mesh.points)
            if not (ew.max() < 0 and eu.min() > 0):
                failed(start, f"Yw not ≺ 0 or Yu not ≻ 0 on the mesh (max eig Yw "
                              f"{ew.max():.3g}, min eig Yu {eu.min():.3g})")
                continue
            ok, final, why = worst_case_rollout_check(
                ctl, mesh, settings.rollout_steps, settings.escape_factor,
                settings.return_fraction)
            if not ok:
                failed(start, why)
                continue
            rec = GammaTrial(float(gamma), True, f"[{start}] converged, Yw ≺ 0 on the mesh, "
                             f"worst-case closed loop {why}", start, ctl.iterations["outer"],
                             max(ctl.iterations["inner"]), float(ew.max()), final,
                             spent + time.perf_counter() - t1)
            return rec, ctl
        rec = GammaTrial(float(gamma), False, "; ".join(reasons) or "no start available",
                         seconds=spent + time.perf_counter() - t1)
        return rec, None

    def record(rec, ctl):
        new = len(history) >= n_replay
        history.append(rec)
        if rec.accepted and (best["gamma"] is None or rec.gamma < best["gamma"]):
            best["gamma"], best["controller"] = rec.gamma, ctl
        if new:
            save(True)
            if progress is not None:
                progress(rec)

    n_replay = len(replay)

    # upper end: the problem's gamma, doubled until accepted
    hi = max(float(cost.gamma), g_lin * (1 + 2 * settings.rtol))
    while True:
        rec, ctl = trial(hi)
        record(rec, ctl)
        if rec.accepted:
            break
        if len(history) > _MAX_DOUBLINGS or len(history) >= settings.max_trials:
            raise ConvergenceError(
                f"no accepted gamma found up to {hi:g} ({len(history)} trials doubling the "
                f"problem's gamma; last reason: {rec.reason}). Check the initial policy and "
                "the training region, or start from a larger gamma", history)
        hi *= 2.0
    lo = g_lin
    converged = True
    while hi - lo > settings.rtol * hi:
        if len(history) >= settings.max_trials:
            converged = False
            break
        mid = np.sqrt(lo * hi) if hi / lo > 2.0 else 0.5 * (lo + hi)
        rec, ctl = trial(mid)
        record(rec, ctl)
        if rec.accepted:
            hi = mid
        else:
            lo = mid
    if replay or running is not None:
        raise CheckpointError("(resume)", "it holds more trials than this search makes: "
                              "start over (--restart)")
    ctl = best["controller"]
    ctl.problem["gamma_search"] = {"gamma_star": hi, "bracket": [lo, hi],
                                   "linear_limit": g_lin, "settings": settings.to_dict()}
    return GammaSearchResult(hi, (lo, hi), g_lin, history, ctl, settings,
                             time.perf_counter() - t0, converged)


_MAX_DOUBLINGS = 10


def _controller_of(record, system, basis, cost_at):
    """The controller of a record (``to_dict()``) on the search's own system and basis
    (so that its u* is the same, bit for bit, as the one trained in this process)."""
    from .controller import GameController
    from .hji import IterationRecord

    hist = [IterationRecord(**{**h, "weights": np.asarray(h["weights"], float)})
            for h in record.get("history", [])]
    return GameController(system, basis, np.asarray(record["weights"], float),
                          cost_at(record["problem"]["cost"]["gamma"]),
                          problem=record["problem"], history=hist,
                          train_seconds=record["train_seconds"],
                          iterations=record["iterations"])


class _SaddleControl:
    """``u*`` of a trained controller as an initial policy (recorded by its γ)."""

    def __init__(self, controller):
        self.controller = controller

    def __call__(self, x):
        return self.controller.control(x)

    def to_dict(self):
        return {"kind": "continuation", "name": "saddle-point control u* of the controller "
                f"trained at gamma = {self.controller.cost.gamma:.9g}",
                "gamma": self.controller.cost.gamma}


def _short(exc, n=220):
    s = str(exc)
    return s if len(s) <= n else s[: n - 1] + "…"
