"""Checkpoints of long computations: an interrupted training, γ search or DP continues.

Training (the two-loop policy iteration)
----------------------------------------

The state after ``k`` finished outer iterations is the control policy on the mesh,
``u⁽ᵏ⁾`` (p, m), and the records of those iterations (:class:`IterationRecord`,
each with its weights). Everything else the solver uses is recomputed from the
inputs, deterministically, so :func:`~weakgrid.game.hji.solve_hji` started from
a :class:`TrainingState` gives the same final weights, bit for bit, as a run
that was never interrupted.

A checkpoint file (``.npz``, written atomically by :mod:`weakgrid.fileio`) holds
the state and a ``key`` chosen by the caller — a content hash of everything the
training depends on — so that a checkpoint of other inputs is never resumed.

The γ search and the dynamic programming
----------------------------------------
A :class:`SearchState` holds the decided trials of a γ bisection, the controller at
the smallest accepted γ (the next trials start from it) and the training of the
trial in progress; the bisection is deterministic, so replaying the decided trials
leads to the same next γ. A :class:`DPState` holds the grid policies and value of
the last finished DP policy iteration. Both files have the same layout (a JSON
``meta`` with the format, version and key, and float arrays) and are written by the
same atomic writer.
"""

from __future__ import annotations

import json
import math
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..fileio import replace_atomic
from .errors import WeakgridError

__all__ = ["TrainingState", "CheckpointError", "StaleCheckpointError", "save_checkpoint",
           "load_checkpoint", "FORMAT", "SearchState", "RunningTrial", "save_search_checkpoint",
           "load_search_checkpoint", "DPState", "save_dp_checkpoint", "load_dp_checkpoint"]

FORMAT = "weakgrid-hji-checkpoint"
_VERSION = 1


class CheckpointError(WeakgridError):
    """A checkpoint file cannot be read (damaged, truncated, not a checkpoint)."""

    def __init__(self, path, reason: str):
        self.path, self.reason = str(path), reason
        super().__init__(f"checkpoint '{path}' is damaged or not a checkpoint ({reason})")


class StaleCheckpointError(CheckpointError):
    """A valid checkpoint made from other inputs (another key)."""

    def __init__(self, path, key, expected):
        self.key, self.expected = key, expected
        WeakgridError.__init__(self, f"checkpoint '{path}' was made from other inputs "
                                     f"(key {key} ≠ {expected})")
        self.path, self.reason = str(path), "other inputs"


@dataclass
class TrainingState:
    """The finished part of a policy iteration.

    Attributes
    ----------
    outer : int
        Outer iterations finished.
    policy : ndarray (p, m)
        The control policy on the mesh after them (``u⁽ᵒᵘᵗᵉʳ⁾``).
    history : list of IterationRecord
        One record per finished outer iteration.
    seconds : float
        Training time spent on them, s.
    """

    outer: int
    policy: np.ndarray
    history: list = field(default_factory=list)
    seconds: float = 0.0

    @property
    def converged_with(self):
        """``max|Δu|`` of the last finished iteration (inf before the first)."""
        return self.history[-1].max_du if self.history else math.inf


def _record_dict(rec) -> dict:
    d = rec.to_dict()
    d.pop("weights")
    return d


def _plain(obj):
    """numpy scalars and arrays as Python numbers and lists (for ``json.dumps``)."""
    if hasattr(obj, "tolist"):
        return obj.tolist()
    raise TypeError(f"{type(obj).__name__} is not JSON serializable")


def _write(path, meta: dict, arrays: dict) -> Path:
    """``meta`` (JSON) and ``arrays`` into the ``.npz`` file ``path``, atomically."""
    def write(tmp):
        with open(tmp, "wb") as fh:
            np.savez(fh, meta=np.array(json.dumps(meta, default=_plain)), **arrays)
    return replace_atomic(path, write)


def _read(path, fmt: str, version: int, key: str):
    """``(meta, arrays)`` of a checkpoint of format ``fmt`` saved with ``key``.

    Raises FileNotFoundError, StaleCheckpointError or CheckpointError (see
    :func:`load_checkpoint`).
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(2, "no checkpoint", str(path))
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"][()]))
            arrays = {k: np.array(z[k], float) for k in z.files if k != "meta"}
    except (zipfile.BadZipFile, ValueError, KeyError, OSError, EOFError,
            json.JSONDecodeError, TypeError) as exc:
        raise CheckpointError(path, f"{type(exc).__name__}: {exc}") from None
    if not isinstance(meta, dict) or meta.get("format") != fmt:
        raise CheckpointError(path, "no weakgrid checkpoint header" if not isinstance(
            meta, dict) or not str(meta.get("format", "")).startswith("weakgrid-") else
            f"a {meta.get('format')} file, not a {fmt} file")
    if meta.get("version") != version:
        raise CheckpointError(path, f"format version {meta.get('version')!r}, this weakgrid "
                                    f"reads {version}")
    if meta.get("key") != key:
        raise StaleCheckpointError(path, meta.get("key"), key)
    return meta, arrays


def _training_parts(state: TrainingState):
    """The JSON part and the arrays (policy, weights) of a :class:`TrainingState`."""
    meta = {"outer": int(state.outer), "seconds": float(state.seconds),
            "history": [_record_dict(r) for r in state.history]}
    weights = (np.stack([np.asarray(r.weights, float) for r in state.history])
               if state.history else np.zeros((0, 0)))
    return meta, {"policy": np.asarray(state.policy, float), "weights": weights}


def _training_from_parts(meta, policy, weights) -> TrainingState:
    from .hji import IterationRecord

    outer = int(meta["outer"])
    hist = meta["history"]
    if len(hist) != outer or weights.shape[0] != outer:
        raise ValueError(f"{outer} iterations but {len(hist)} records and "
                         f"{weights.shape[0]} weight vectors")
    if policy.ndim != 2 or not np.all(np.isfinite(policy)):
        raise ValueError("the policy is not a finite (points × controls) array")
    if not np.all(np.isfinite(weights)):
        raise ValueError("non-finite weights")
    history = [IterationRecord(**{**h, "weights": weights[k]}) for k, h in enumerate(hist)]
    return TrainingState(outer=outer, policy=policy, history=history,
                         seconds=float(meta.get("seconds", 0.0)))


def save_checkpoint(path, state: TrainingState, key: str) -> Path:
    """Write ``state`` with ``key`` to ``path`` (``.npz``) atomically; return the path."""
    meta, arrays = _training_parts(state)
    return _write(path, {"format": FORMAT, "version": _VERSION, "key": str(key), **meta},
                  arrays)


def load_checkpoint(path, key: str) -> TrainingState:
    """The :class:`TrainingState` in ``path`` if it was saved with ``key``.

    Raises
    ------
    FileNotFoundError
        No checkpoint.
    StaleCheckpointError
        A checkpoint of other inputs.
    CheckpointError
        The file is damaged or is not a checkpoint.
    """
    meta, arrays = _read(path, FORMAT, _VERSION, key)
    try:
        return _training_from_parts(meta, arrays["policy"], arrays["weights"])
    except (KeyError, TypeError, ValueError) as exc:
        raise CheckpointError(path, f"{type(exc).__name__}: {exc}") from None


# ------------------------------------------------------- the gamma search (bisection)
SEARCH_FORMAT = "weakgrid-gamma-search-checkpoint"


@dataclass
class RunningTrial:
    """The γ trial that was running: the starts already failed and its training so far.

    Attributes
    ----------
    gamma : float
    start : str
        The start of the policy iteration being trained (or due next, if ``training``
        is None).
    reasons : list of str
        Why the starts before it failed.
    seconds : float
        Time spent on the trial, s.
    training : TrainingState or None
        The finished outer iterations of the training from ``start``.
    """

    gamma: float
    start: str
    reasons: list
    seconds: float
    training: TrainingState | None = None


@dataclass
class SearchState:
    """The finished part of a γ bisection (:func:`~weakgrid.game.gamma_search.search_min_gamma`).

    Attributes
    ----------
    trials : list of GammaTrial
        The decided trials, in order.
    best : GameController or dict or None
        The controller at the smallest accepted γ (its record, ``to_dict()``, once read
        from a file).
    running : RunningTrial or None
        The trial in progress, if its training had finished outer iterations.
    """

    trials: list
    best: object = None
    running: RunningTrial | None = None


def save_search_checkpoint(path, state: SearchState, key: str) -> Path:
    """Write a :class:`SearchState` with ``key`` to ``path`` (``.npz``) atomically."""
    best = state.best
    if best is not None and not isinstance(best, dict):
        best = best.to_dict()
    meta = {"format": SEARCH_FORMAT, "version": _VERSION, "key": str(key),
            "trials": [t.to_dict() for t in state.trials], "best": best, "running": None}
    arrays = {}
    r = state.running
    if r is not None:
        meta["running"] = {"gamma": float(r.gamma), "start": r.start,
                           "reasons": list(r.reasons), "seconds": float(r.seconds),
                           "training": None}
        if r.training is not None:
            tmeta, tarr = _training_parts(r.training)
            meta["running"]["training"] = tmeta
            arrays = {"running_policy": tarr["policy"], "running_weights": tarr["weights"]}
    return _write(path, meta, arrays)


def load_search_checkpoint(path, key: str) -> SearchState:
    """The :class:`SearchState` in ``path`` if it was saved with ``key`` (raises as
    :func:`load_checkpoint`); ``best`` is the controller's record (a dict)."""
    from .gamma_search import GammaTrial

    meta, arrays = _read(path, SEARCH_FORMAT, _VERSION, key)
    try:
        trials = [GammaTrial(**t) for t in meta["trials"]]
        best = meta["best"]
        if best is not None and not isinstance(best, dict):
            raise TypeError("best is not a controller record")
        if best is not None and not any(t.accepted and t.gamma == best["problem"]["cost"][
                "gamma"] for t in trials):
            raise ValueError("the kept controller is of no accepted trial")
        running = None
        if meta["running"] is not None:
            r = meta["running"]
            running = RunningTrial(float(r["gamma"]), str(r["start"]), list(r["reasons"]),
                                   float(r["seconds"]), None if r["training"] is None else
                                   _training_from_parts(r["training"],
                                                        arrays["running_policy"],
                                                        arrays["running_weights"]))
    except (KeyError, TypeError, ValueError) as exc:
        raise CheckpointError(path, f"{type(exc).__name__}: {exc}") from None
    return SearchState(trials, best, running)


# ------------------------------------------------------ the dynamic-programming ground truth
DP_FORMAT = "weakgrid-dp-checkpoint"


@dataclass
class DPState:
    """The finished iterations of the grid dynamic programming
    (:func:`~weakgrid.game.dynamic_programming.solve_game_dp`).

    Attributes
    ----------
    iteration : int
        Policy iterations finished.
    policy : ndarray (N, m+q)
        The held ``(u, w)`` at every grid node after them.
    residual : ndarray (N,)
        The value residual ``r`` of that policy.
    value : ndarray (N,)
        ``V`` on the nodes (``x'S₀x + r``).
    history : list of dict
        One record per finished iteration.
    seconds : float
    """

    iteration: int
    policy: np.ndarray
    residual: np.ndarray
    value: np.ndarray
    history: list = field(default_factory=list)
    seconds: float = 0.0


def save_dp_checkpoint(path, state: DPState, key: str) -> Path:
    """Write a :class:`DPState` with ``key`` to ``path`` (``.npz``) atomically."""
    meta = {"format": DP_FORMAT, "version": _VERSION, "key": str(key),
            "iteration": int(state.iteration), "history": list(state.history),
            "seconds": float(state.seconds)}
    return _write(path, meta, {"policy": np.asarray(state.policy, float),
                               "residual": np.asarray(state.residual, float),
                               "value": np.asarray(state.value, float)})


def load_dp_checkpoint(path, key: str) -> DPState:
    """The :class:`DPState` in ``path`` if it was saved with ``key`` (raises as
    :func:`load_checkpoint`)."""
    meta, a = _read(path, DP_FORMAT, _VERSION, key)
    try:
        it = int(meta["iteration"])
        if len(meta["history"]) != it or it < 0:
            raise ValueError(f"{it} iterations but {len(meta['history'])} records")
        Z, r, V = a["policy"], a["residual"], a["value"]
        if Z.ndim != 2 or r.shape != (Z.shape[0],) or V.shape != r.shape:
            raise ValueError(f"arrays of shapes {Z.shape}, {r.shape}, {V.shape}")
        if not (np.all(np.isfinite(Z)) and np.all(np.isfinite(r)) and np.all(np.isfinite(V))):
            raise ValueError("non-finite policy or value")
        return DPState(it, Z, r, V, list(meta["history"]), float(meta.get("seconds", 0.0)))
    except (KeyError, TypeError, ValueError) as exc:
        raise CheckpointError(path, f"{type(exc).__name__}: {exc}") from None
