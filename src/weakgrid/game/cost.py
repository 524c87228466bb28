"""The game cost (18): ``Σ x'Qx + u'Ru − γ² w'Pw``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import ParameterError, ShapeError

__all__ = ["GameCost"]


def _sym(M, k, name, strict):
    M = np.atleast_2d(np.asarray(M, float))
    if M.shape == (1, 1) and k > 1:
        M = M[0, 0] * np.eye(k)
    if M.shape != (k, k):
        raise ShapeError(f"cost.{name}", M.shape, f"({k}, {k}) or a scalar")
    if not np.all(np.isfinite(M)):
        raise ParameterError(f"cost.{name}", M.tolist(), "weights must be finite")
    if not np.allclose(M, M.T, atol=1e-12):
        raise ParameterError(f"cost.{name}", M.tolist(), "weights must be symmetric")
    ev = np.linalg.eigvalsh(M)
    if strict and ev.min() <= 0:
        raise ParameterError(f"cost.{name}", M.tolist(), "must be positive definite")
    if not strict and ev.min() < -1e-12:
        raise ParameterError(f"cost.{name}", M.tolist(), "must be positive semidefinite")
    return 0.5 * (M + M.T)


@dataclass(frozen=True, eq=False)
class GameCost:
    """Weights of the zero-sum game cost (paper, (18)).

    Parameters
    ----------
    Q : (n, n) or scalar
        State weight, positive semidefinite.
    R : (m, m) or scalar
        Control weight, positive definite.
    P : (q, q) or scalar
        Disturbance weight, positive definite.
    gamma : float
        Attenuation level γ > 0.
    """

    Q: np.ndarray
    R: np.ndarray
    P: np.ndarray
    gamma: float

    def __post_init__(self):
        try:
            g = float(self.gamma)
        except (TypeError, ValueError):
            g = float("nan")
        if not np.isfinite(g) or g <= 0:
            raise ParameterError("cost.gamma", self.gamma, "gamma must be a positive finite number")
        for nm, strict in (("Q", False), ("R", True), ("P", True)):
            M = np.atleast_2d(np.asarray(getattr(self, nm), float))
            object.__setattr__(self, nm, _sym(M, M.shape[0], nm, strict))
        object.__setattr__(self, "gamma", g)

    @classmethod
    def for_system(cls, system, Q, R, P, gamma) -> "GameCost":
        g = float(gamma)
        if not np.isfinite(g) or g <= 0:
            raise ParameterError("cost.gamma", gamma, "gamma must be a positive finite number")
        return cls(_sym(Q, system.n_states, "Q", False), _sym(R, system.n_controls, "R", True),
                   _sym(P, system.n_disturbances, "P", True), g)

    def stage(self, x, u, w) -> np.ndarray:
        """``x'Qx + u'Ru − γ² w'Pw`` for a batch."""
        return (np.einsum("...i,ij,...j->...", x, self.Q, x)
                + np.einsum("...i,ij,...j->...", u, self.R, u)
                - self.gamma**2 * np.einsum("...i,ij,...j->...", w, self.P, w))

    def to_dict(self) -> dict:
        return {"Q": self.Q.tolist(), "R": self.R.tolist(), "P": self.P.tolist(),
                "gamma": self.gamma}

    @classmethod
    def from_dict(cls, d: dict) -> "GameCost":
        return cls(np.asarray(d["Q"], float), np.asarray(d["R"], float),
                   np.asarray(d["P"], float), float(d["gamma"]))
