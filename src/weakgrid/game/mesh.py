"""Training meshes on the region Ω (paper, (27)–(28))."""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from .errors import ParameterError, ShapeError

__all__ = ["GridMesh", "PointMesh", "mesh_from_dict"]


@dataclass(frozen=True, eq=False)
class GridMesh:
    """A rectangular grid ``lower ≤ x ≤ upper`` with spacing ``step`` per state.

    Points along each axis are ``lower + k·step`` for ``k = 0, 1, …`` while they do
    not exceed ``upper`` (as MATLAB's ``lower:step:upper``; the paper's Ω with
    steps (0.06, 0.6) gives 34 × 34 points from −1 to 0.98 and −10 to 9.8).

    Parameters
    ----------
    lower, upper, step : sequence of float, one per state
    """

    lower: tuple
    upper: tuple
    step: tuple

    def __post_init__(self):
        arrays = []
        for nm in ("lower", "upper", "step"):
            try:
                arrays.append(np.atleast_1d(np.asarray(getattr(self, nm), float)))
            except (TypeError, ValueError):
                raise ParameterError(f"mesh.{nm}", getattr(self, nm),
                                     "must be a list of numbers, one per state") from None
        lo, hi, st = arrays
        if not (lo.shape == hi.shape == st.shape) or lo.ndim != 1:
            raise ShapeError("mesh.step", st.shape, f"one value per state, like lower {lo.shape}")
        for nm, v in (("lower", lo), ("upper", hi), ("step", st)):
            if not np.all(np.isfinite(v)):
                raise ParameterError(f"mesh.{nm}", v.tolist(), "must be finite numbers")
        if np.any(hi <= lo):
            raise ParameterError("mesh.upper", hi.tolist(), f"must exceed lower = {lo.tolist()}")
        if np.any(st <= 0):
            raise ParameterError("mesh.step", st.tolist(), "steps must be positive")
        counts = np.floor((hi - lo) / st + 1e-9).astype(int) + 1
        if np.any(counts < 3):
            raise ParameterError("mesh.step", st.tolist(),
                                 "need at least 3 points per axis: use a smaller step")
        if np.prod(counts.astype(float)) > 5e6:
            raise ParameterError("mesh.step", st.tolist(),
                                 f"{int(np.prod(counts.astype(float)))} points is too many: "
                                 "use a larger step")
        object.__setattr__(self, "lower", tuple(lo.tolist()))
        object.__setattr__(self, "upper", tuple(hi.tolist()))
        object.__setattr__(self, "step", tuple(st.tolist()))
        grids = np.meshgrid(*self.axes(), indexing="ij")
        pts = np.stack([g.ravel() for g in grids], axis=-1)
        pts.setflags(write=False)
        object.__setattr__(self, "_points", pts)

    @property
    def n_states(self) -> int:
        return len(self.lower)

    def axes(self) -> list[np.ndarray]:
        out = []
        for lo, hi, st in zip(self.lower, self.upper, self.step):
            k = int(np.floor((hi - lo) / st + 1e-9))
            out.append(lo + st * np.arange(k + 1))
        return out

    @property
    def points(self) -> np.ndarray:
        """All grid points, shape (p, n); the first state varies slowest (read-only)."""
        return self._points

    def corners_and_midpoints(self) -> np.ndarray:
        """The 3ⁿ − 1 corners, edge midpoints and face centres of the box (not its centre)."""
        lo, hi = np.array(self.lower), np.array(self.upper)
        mid = 0.5 * (lo + hi)
        pts = []
        for c in itertools.product((0, 1, 2), repeat=self.n_states):
            if all(v == 1 for v in c):
                continue
            pts.append([(lo, mid, hi)[v][i] for i, v in enumerate(c)])
        return np.array(pts)

    def contains(self, x, tol=1e-12) -> np.ndarray:
        x = np.asarray(x, float)
        return np.all((x >= np.array(self.lower) - tol) & (x <= np.array(self.upper) + tol), -1)

    def sample(self, n: int, seed: int) -> np.ndarray:
        """``n`` uniform random states of the box (explicit seed)."""
        rng = np.random.default_rng(seed)
        return rng.uniform(self.lower, self.upper, size=(n, self.n_states))

    def to_dict(self) -> dict:
        return {"kind": "grid", "lower": list(self.lower), "upper": list(self.upper),
                "step": list(self.step), "n_points": int(self.points.shape[0])}


@dataclass(frozen=True, eq=False)
class PointMesh:
    """An explicit list of mesh points, shape (p, n)."""

    points: np.ndarray

    def __post_init__(self):
        p = np.asarray(self.points, float)
        if p.ndim != 2:
            raise ShapeError("mesh.points", p.shape, "(p, n)")
        if not np.all(np.isfinite(p)):
            raise ParameterError("mesh.points", "non-finite", "mesh points must be finite")
        object.__setattr__(self, "points", p)

    @property
    def n_states(self) -> int:
        return self.points.shape[1]

    @property
    def lower(self):
        return tuple(self.points.min(0).tolist())

    @property
    def upper(self):
        return tuple(self.points.max(0).tolist())

    def to_dict(self) -> dict:
        return {"kind": "points", "points": self.points.tolist(),
                "n_points": int(self.points.shape[0])}


def mesh_from_dict(d: dict):
    """The mesh of a ``to_dict()`` record: ``{"kind": "grid", lower, upper, step}`` or
    ``{"kind": "points", points}`` (:class:`GridMesh` or :class:`PointMesh`)."""
    if d.get("kind") == "grid":
        return GridMesh(d["lower"], d["upper"], d["step"])
    if d.get("kind") == "points":
        return PointMesh(np.asarray(d["points"], float))
    raise ParameterError("mesh.kind", d.get("kind"), "use 'grid' or 'points'")
