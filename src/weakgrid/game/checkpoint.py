"""Checkpoints of the two-loop policy iteration: an interrupted training continues.

The state after ``k`` finished outer iterations is the control policy on the mesh,
``u⁽ᵏ⁾`` (p, m), and the records of those iterations (:class:`IterationRecord`,
each with its weights). Everything else the solver uses is recomputed from the
inputs, deterministically, so :func:`~weakgrid.game.hji.solve_hji` started from
a :class:`TrainingState` gives the same final weights, bit for bit, as a run
that was never interrupted.

A checkpoint file (``.npz``, written atomically by :mod:`weakgrid.fileio`) holds
the state and a ``key`` chosen by the caller — a content hash of everything the
training depends on — so that a checkpoint of other inputs is never resumed.
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
           "load_checkpoint", "FORMAT"]

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


def save_checkpoint(path, state: TrainingState, key: str) -> Path:
    """Write ``state`` with ``key`` to ``path`` (``.npz``) atomically; return the path."""
    meta = {"format": FORMAT, "version": _VERSION, "key": str(key), "outer": int(state.outer),
            "seconds": float(state.seconds),
            "history": [_record_dict(r) for r in state.history]}
    weights = (np.stack([np.asarray(r.weights, float) for r in state.history])
               if state.history else np.zeros((0, 0)))

    def write(tmp):
        with open(tmp, "wb") as fh:
            np.savez(fh, meta=np.array(json.dumps(meta)), policy=np.asarray(state.policy, float),
                     weights=weights)
    return replace_atomic(path, write)


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
    from .hji import IterationRecord

    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(2, "no checkpoint", str(path))
    try:
        with np.load(path, allow_pickle=False) as z:
            meta = json.loads(str(z["meta"][()]))
            policy = np.array(z["policy"], float)
            weights = np.array(z["weights"], float)
    except (zipfile.BadZipFile, ValueError, KeyError, OSError, EOFError,
            json.JSONDecodeError, TypeError) as exc:
        raise CheckpointError(path, f"{type(exc).__name__}: {exc}") from None
    if not isinstance(meta, dict) or meta.get("format") != FORMAT:
        raise CheckpointError(path, "no weakgrid checkpoint header")
    if meta.get("version") != _VERSION:
        raise CheckpointError(path, f"format version {meta.get('version')!r}, this weakgrid "
                                    f"reads {_VERSION}")
    if meta.get("key") != key:
        raise StaleCheckpointError(path, meta.get("key"), key)
    try:
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
        seconds = float(meta.get("seconds", 0.0))
    except (KeyError, TypeError, ValueError) as exc:
        raise CheckpointError(path, f"{type(exc).__name__}: {exc}") from None
    return TrainingState(outer=outer, policy=policy, history=history, seconds=seconds)
