"""Settings of the grid dynamic programming (:mod:`weakgrid.game.dynamic_programming`), NumPy
when used: the CLI reads their defaults without loading NumPy or SciPy."""

from __future__ import annotations

from dataclasses import dataclass

from .errors import ParameterError

__all__ = ["DPSettings"]


@dataclass(frozen=True)
class DPSettings:
    """Parameters of the grid dynamic programming.

    Parameters
    ----------
    n_points : tuple of int
        Grid nodes per state (odd, so that a box symmetric about 0 has the origin).
    hold_steps : int
        ``k`` of the lifting (inputs held ``k`` steps); 1 = the system itself.
    margin : float or tuple of float
        The grid box is Ω enlarged by this fraction of its width on each side (one
        value, or one per state).
    prior : {"riccati", "none"} or (n, n) array
        Quadratic part ``S₀``: the lifted linearization's game Riccati solution, 0,
        or a given matrix (e.g. to test that the residual is learnt).
    max_iterations : int
        Policy-iteration cap.
    tol : float
        Stop when ``max|ΔV| ≤ tol·max|V|`` on the grid between two iterations.
    newton_steps : int
        Newton steps of the saddle-point search per iteration.
    interpolation : {"cubic", "linear"}
        Of the residual: Keys' cubic convolution (C¹, exact for quadratics) or
        multilinear (monotone).
    extrapolate : float or None
        Cells beyond the grid box over which the cubic residual is continued linearly
        (with its end slope; a constant past them); 0 = a constant continuation. None
        (default): 4 for a cost with an input bound, 0 without
        (:mod:`weakgrid.game.dynamic_programming`, "Leaving the grid").
    """

    n_points: tuple = (61, 61)
    hold_steps: int = 1
    margin: float = 0.0
    prior: str = "riccati"
    max_iterations: int = 40
    tol: float = 1e-6
    newton_steps: int = 2
    interpolation: str = "cubic"
    extrapolate: float | None = None

    def __post_init__(self):
        import numpy as np   # here, not at import: the CLI reads the defaults only

        n = tuple(int(v) for v in np.atleast_1d(self.n_points))
        if any(v < 3 for v in n):
            raise ParameterError("n_points", list(n), "use at least 3 nodes per state")
        if np.prod([float(v) for v in n]) > 2e6:
            raise ParameterError("n_points", list(n), "more than 2e6 nodes: use fewer")
        object.__setattr__(self, "n_points", n)
        if int(self.hold_steps) != self.hold_steps or self.hold_steps < 1:
            raise ParameterError("hold_steps", self.hold_steps, "use an integer ≥ 1")
        mg = np.atleast_1d(np.asarray(self.margin, float))
        if mg.ndim != 1 or not (np.all(np.isfinite(mg)) and np.all(mg >= 0)):
            raise ParameterError("margin", self.margin, "use a fraction ≥ 0 (e.g. 0.2), one "
                                 "or one per state")
        object.__setattr__(self, "margin", float(mg[0]) if mg.size == 1 else
                           tuple(float(v) for v in mg))
        if isinstance(self.prior, str):
            if self.prior not in ("riccati", "none"):
                raise ParameterError("prior", self.prior, "use 'riccati', 'none' or a "
                                     "symmetric (n, n) matrix")
        else:
            S = np.asarray(self.prior, float)
            if S.ndim != 2 or S.shape[0] != S.shape[1] or not np.allclose(S, S.T):
                raise ParameterError("prior", S.tolist(), "use 'riccati', 'none' or a "
                                     "symmetric (n, n) matrix")
            object.__setattr__(self, "prior", tuple(map(tuple, S.tolist())))
        if int(self.max_iterations) != self.max_iterations or self.max_iterations < 1:
            raise ParameterError("max_iterations", self.max_iterations, "use an integer ≥ 1")
        if not (np.isfinite(self.tol) and self.tol > 0):
            raise ParameterError("tol", self.tol, "use a positive tolerance, e.g. 1e-6")
        if self.interpolation not in ("cubic", "linear"):
            raise ParameterError("interpolation", self.interpolation, "use 'cubic' or 'linear'")
        if self.interpolation == "cubic" and min(n) < 4:
            raise ParameterError("n_points", list(n), "cubic interpolation needs ≥ 4 nodes")
        if self.extrapolate is not None:
            try:
                e = float(self.extrapolate)
            except (TypeError, ValueError):
                e = float("nan")
            if not (np.isfinite(e) and 0 <= e <= 100):
                raise ParameterError("extrapolate", self.extrapolate, "use a number of cells "
                                     "in [0, 100] (0: constant continuation) or None (auto)")
            object.__setattr__(self, "extrapolate", e)
        if int(self.newton_steps) != self.newton_steps or self.newton_steps < 1:
            raise ParameterError("newton_steps", self.newton_steps, "use an integer ≥ 1")

    def to_dict(self):
        import numpy as np

        return {"n_points": list(self.n_points), "hold_steps": self.hold_steps,
                "margin": self.margin if np.ndim(self.margin) == 0 else list(self.margin),
                "prior": self.prior if isinstance(self.prior, str) else [list(r) for r in
                                                                          self.prior],
                "max_iterations": self.max_iterations, "tol": self.tol,
                "newton_steps": self.newton_steps, "interpolation": self.interpolation,
                "extrapolate": self.extrapolate}
