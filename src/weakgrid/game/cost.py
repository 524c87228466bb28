"""The game cost (18): ``Σ x'Qx + u'Ru − γ² w'Pw`` — or, with an input bound,
``Σ x'Qx + W(u) − γ² w'Pw`` with the constrained-input penalty W of
:mod:`weakgrid.game.input_bound` in place of ``u'Ru``."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import ParameterError, ShapeError
from .input_bound import InputBound

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
    bound : InputBound or None
        The admissible control set; its penalty ``W(u)`` replaces ``u'Ru``
        (beyond the paper; None: the paper's cost).
    """

    Q: np.ndarray
    R: np.ndarray
    P: np.ndarray
    gamma: float
    bound: InputBound | None = None

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
    def for_system(cls, system, Q, R, P, gamma, bound=None, bound_shape="disk") -> "GameCost":
        """Checked weights; ``bound`` an :class:`InputBound`, a limit ``ū`` or None."""
        g = float(gamma)
        if not np.isfinite(g) or g <= 0:
            raise ParameterError("cost.gamma", gamma, "gamma must be a positive finite number")
        Rm = _sym(R, system.n_controls, "R", True)
        if bound is not None and not isinstance(bound, InputBound):
            bound = InputBound.for_inputs(system.n_controls, bound, bound_shape)
        if bound is not None:
            if bound.shape == "box" and bound.limit.size != system.n_controls:
                raise ParameterError("cost.u_bound", bound.limit.tolist(),
                                     f"give one value or one per input ({system.n_controls})")
            bound.check_weight(Rm)
        return cls(_sym(Q, system.n_states, "Q", False), Rm,
                   _sym(P, system.n_disturbances, "P", True), g, bound)

    def with_bound(self, bound) -> "GameCost":
        """The same weights with another input bound (an :class:`InputBound` or None)."""
        if bound is not None:
            bound.check_weight(self.R)
        return GameCost(self.Q, self.R, self.P, self.gamma, bound)

    def control_penalty(self, u) -> np.ndarray:
        """``u'Ru``, or ``W(u)`` with an input bound, for a batch ``(..., m)``."""
        if self.bound is None:
            return np.einsum("...i,ij,...j->...", u, self.R, u)
        return self.bound.penalty(u, self.R)

    def stage(self, x, u, w) -> np.ndarray:
        """``x'Qx + u'Ru − γ² w'Pw`` (``W(u)`` for ``u'Ru`` with a bound) for a batch."""
        return (np.einsum("...i,ij,...j->...", x, self.Q, x)
                + self.control_penalty(u)
                - self.gamma**2 * np.einsum("...i,ij,...j->...", w, self.P, w))

    def to_dict(self) -> dict:
        d = {"Q": self.Q.tolist(), "R": self.R.tolist(), "P": self.P.tolist(),
             "gamma": self.gamma}
        if self.bound is not None:
            d["u_bound"] = self.bound.to_dict()
        return d

    @classmethod
    def from_dict(cls, d: dict) -> "GameCost":
        R = np.asarray(d["R"], float)
        bound = InputBound.from_dict(d["u_bound"], R.shape[0]) if d.get("u_bound") else None
        return cls(np.asarray(d["Q"], float), R,
                   np.asarray(d["P"], float), float(d["gamma"]), bound)
