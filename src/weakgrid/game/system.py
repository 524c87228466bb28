"""Discrete-time control-affine systems ``x+ = f(x) + g(x)·u + h(x)·w``.

Names follow hj_reachability: ``open_loop_dynamics`` (f), ``control_directions``
(g) and ``disturbance_directions`` (h). Every method takes a batch of states of
shape ``(..., n)`` and returns ``(..., n)``, ``(..., n, m)`` and ``(..., n, q)``.
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from .errors import NonFiniteError, ParameterError, ShapeError

__all__ = ["ControlAffineSystem", "LinearSystem", "FunctionSystem", "register_system",
           "system_from_dict"]

_REGISTRY: dict[str, Callable[[dict], "ControlAffineSystem"]] = {}


def register_system(kind: str, factory: Callable[[dict], "ControlAffineSystem"]) -> None:
    """Register a factory that rebuilds a system of ``kind`` from its ``to_dict()``.

    Controller files record the system as a dictionary; loading them looks the
    ``kind`` up here. Higher layers (e.g. :mod:`weakgrid.models`) register theirs.
    """
    _REGISTRY[kind] = factory


def system_from_dict(d: dict) -> "ControlAffineSystem":
    """The system of a ``to_dict()`` record, built by the factory registered for ``d["kind"]``
    (see :func:`register_system`)."""
    kind = d.get("kind")
    if kind not in _REGISTRY:
        raise ParameterError(
            "model.kind", kind,
            f"unknown system kind; known: {sorted(_REGISTRY)} (import the module that "
            "registers it, e.g. weakgrid.models)",
        )
    return _REGISTRY[kind](d)


class ControlAffineSystem:
    """Base class: subclasses implement the three direction maps.

    Attributes
    ----------
    n_states, n_controls, n_disturbances : int
    state_names : list of str
    """

    n_states: int
    n_controls: int
    n_disturbances: int
    state_names: list[str]
    kind = "abstract"

    # -- interface -------------------------------------------------------
    def open_loop_dynamics(self, x: np.ndarray) -> np.ndarray:  # f
        raise NotImplementedError

    def control_directions(self, x: np.ndarray) -> np.ndarray:  # g
        raise NotImplementedError

    def disturbance_directions(self, x: np.ndarray) -> np.ndarray:  # h
        raise NotImplementedError

    def to_dict(self) -> dict:
        """A JSON-able description from which :func:`system_from_dict` rebuilds it."""
        raise NotImplementedError(f"{type(self).__name__} cannot be written to a file")

    # -- derived ---------------------------------------------------------
    def check_states(self, x, name: str = "x") -> np.ndarray:
        x = np.asarray(x, dtype=float)
        if x.ndim == 0 or x.shape[-1] != self.n_states:
            raise ShapeError(name, x.shape, f"(..., {self.n_states})")
        if not np.all(np.isfinite(x)):
            raise NonFiniteError(f"{name} contains NaN or inf")
        return x

    def step(self, x, u=None, w=None) -> np.ndarray:
        """``x+ = f(x) + g(x)u + h(x)w`` for a batch; ``u`` or ``w`` None means zero."""
        x = self.check_states(x)
        out = self.open_loop_dynamics(x)
        if u is not None:
            u = np.broadcast_to(np.asarray(u, float), x.shape[:-1] + (self.n_controls,))
            out = out + np.einsum("...ij,...j->...i", self.control_directions(x), u)
        if w is not None:
            w = np.broadcast_to(np.asarray(w, float), x.shape[:-1] + (self.n_disturbances,))
            out = out + np.einsum("...ij,...j->...i", self.disturbance_directions(x), w)
        return out

    def open_loop_jacobian(self, x: np.ndarray) -> np.ndarray:
        """∂f/∂x at a batch of states, shape (..., n, n); central differences by default."""
        x = np.asarray(x, float)
        n = self.n_states
        eps = 1e-6 * np.maximum(1.0, np.abs(x))
        out = np.empty(x.shape + (n,))
        for j in range(n):
            e = np.zeros(n)
            e[j] = 1.0
            d = eps[..., j : j + 1] * e
            out[..., :, j] = (self.open_loop_dynamics(x + d) - self.open_loop_dynamics(x - d)) / (
                2 * eps[..., j : j + 1]
            )
        return out

    def linearize(self, x0=None):
        """Linearization ``x+ ≈ A x + B u + E w`` about ``x0`` (default the origin).

        Returns ``A = ∂f/∂x(x0)``, ``B = g(x0)``, ``E = h(x0)``. The affine offset
        ``f(x0) − A x0`` is not returned; at an equilibrium it is ``x0 − A x0``.
        """
        x0 = np.zeros(self.n_states) if x0 is None else self.check_states(x0, "x0")
        if x0.shape != (self.n_states,):
            raise ShapeError("x0", x0.shape, f"({self.n_states},)")
        return (
            self.open_loop_jacobian(x0),
            self.control_directions(x0),
            self.disturbance_directions(x0),
        )


class LinearSystem(ControlAffineSystem):
    """``x+ = A x + B u + E w``.

    Parameters
    ----------
    A : (n, n), B : (n, m), E : (n, q)
    """

    kind = "linear"

    def __init__(self, A, B, E, state_names=None):
        A = np.atleast_2d(np.asarray(A, float))
        B = np.asarray(B, float)
        E = np.asarray(E, float)
        n = A.shape[0]
        if A.shape != (n, n):
            raise ShapeError("A", A.shape, "(n, n)")
        if B.ndim == 1:
            B = B[:, None]
        if E.ndim == 1:
            E = E[:, None]
        if B.ndim != 2 or B.shape[0] != n:
            raise ShapeError("B", B.shape, f"({n}, m)")
        if E.ndim != 2 or E.shape[0] != n:
            raise ShapeError("E", E.shape, f"({n}, q)")
        for nm, M in (("A", A), ("B", B), ("E", E)):
            if not np.all(np.isfinite(M)):
                raise NonFiniteError(f"{nm} contains NaN or inf")
        self.A, self.B, self.E = A, B, E
        self.n_states, self.n_controls, self.n_disturbances = n, B.shape[1], E.shape[1]
        self.state_names = list(state_names or [f"x{i + 1}" for i in range(n)])

    def open_loop_dynamics(self, x):
        return np.asarray(x, float) @ self.A.T

    def open_loop_jacobian(self, x):
        x = np.asarray(x, float)
        return np.broadcast_to(self.A, x.shape[:-1] + self.A.shape).copy()

    def control_directions(self, x):
        x = np.asarray(x, float)
        return np.broadcast_to(self.B, x.shape[:-1] + self.B.shape)

    def disturbance_directions(self, x):
        x = np.asarray(x, float)
        return np.broadcast_to(self.E, x.shape[:-1] + self.E.shape)

    def to_dict(self):
        return {"kind": self.kind, "A": self.A.tolist(), "B": self.B.tolist(),
                "E": self.E.tolist(), "state_names": self.state_names}


register_system("linear", lambda d: LinearSystem(d["A"], d["B"], d["E"], d.get("state_names")))


class FunctionSystem(ControlAffineSystem):
    """A control-affine system from three vectorized callables (not serializable).

    Parameters
    ----------
    f : callable, (..., n) -> (..., n)
    g : callable, (..., n) -> (..., n, m)
    h : callable, (..., n) -> (..., n, q)
    n_states, n_controls, n_disturbances : int
    """

    kind = "function"

    def __init__(self, f, g, h, n_states, n_controls, n_disturbances, state_names=None):
        self._f, self._g, self._h = f, g, h
        self.n_states, self.n_controls, self.n_disturbances = n_states, n_controls, n_disturbances
        self.state_names = list(state_names or [f"x{i + 1}" for i in range(n_states)])

    def open_loop_dynamics(self, x):
        return self._f(np.asarray(x, float))

    def control_directions(self, x):
        return self._g(np.asarray(x, float))

    def disturbance_directions(self, x):
        return self._h(np.asarray(x, float))
