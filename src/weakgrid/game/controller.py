"""The trained game controller: the saddle point (u*, w*) of (23)–(24), J and ∇J, and its file.

At a state ``x`` the deployed control and worst-case disturbance are the joint
solution of the block system (from (23)–(24); docs/theory.md, "The saddle point")::

    [[Yu, g'∇²J h], [h'∇²J g, Yw]] · [u; w] = −[g'(∇J + ∇²J(f − x)); h'(∇J + ∇²J(f − x))]

with ``Yu = g'∇²J g + 2R`` and ``Yw = h'∇²J h − 2γ²P``.

With an input bound in the cost (beyond the paper), ``u'Ru`` is ``W(u)``: for each u
the maximizing w is still affine, ``w(u) = −Yw⁻¹ h'[∇J + ∇²J(f + g·u − x)]``, and u*
minimizes the resulting ``½u'M u + b'u + W(u)`` (``M = g'∇²J g − g'∇²J h Yw⁻¹ h'∇²J g``)
over the bound (:meth:`~weakgrid.game.input_bound.InputBound.minimize`); then
``w* = w(u*)``.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .bases import PolynomialBasis
from .cost import GameCost
from .errors import ParameterError, ShapeError
from .input_bound import minimize_points
from .rowwise import matmul, matvec, vecmat
from .system import ControlAffineSystem, system_from_dict
from ..fileio import write_json_atomic
from ..hashing import checksum

__all__ = ["GameController", "load_controller", "FILE_FORMAT"]

FILE_FORMAT = "weakgrid-controller/1"


def _package_version():
    from .._version import __version__

    return __version__


@dataclass(eq=False)
class GameController:
    """``J(x) = W'σ(x)`` and the saddle-point policies it defines.

    Attributes
    ----------
    system : ControlAffineSystem
    basis : PolynomialBasis
    weights : ndarray (L,)
    cost : GameCost
    problem : dict
        The description recorded in the file (model, cost, mesh, basis, …).
    history : list of IterationRecord
    train_seconds : float
    """

    system: ControlAffineSystem
    basis: PolynomialBasis
    weights: np.ndarray
    cost: GameCost
    problem: dict = field(default_factory=dict)
    history: list = field(default_factory=list)
    train_seconds: float = float("nan")
    iterations: dict | None = None

    def __post_init__(self):
        self.weights = np.asarray(self.weights, float)
        if self.weights.shape != (self.basis.size,):
            raise ShapeError("weights", self.weights.shape, f"({self.basis.size},)")
        if self.iterations is None:
            self.iterations = {"outer": len(self.history),
                               "inner": [r.inner for r in self.history]}

    # ----------------------------------------------------------- the cost
    def value(self, x) -> np.ndarray:
        """``J(x)``, shape (...)."""
        return self.basis(x) @ self.weights

    def gradient(self, x) -> np.ndarray:
        """``∇J(x)``, shape (..., n): the saddle point's
        (:meth:`~weakgrid.game.bases.PolynomialBasis.weighted_derivatives`)."""
        return self.basis.weighted_derivatives(x, self.weights)[0]

    def hessian(self, x) -> np.ndarray:
        """``∇²J(x)``, shape (..., n, n) (the saddle point's)."""
        return self.basis.weighted_derivatives(x, self.weights)[1]

    # ------------------------------------------------------- saddle point
    def _terms(self, x, weights=None):
        x = self.system.check_states(x)
        w = self.weights if weights is None else weights
        gJ, HJ = self.basis.weighted_derivatives(x, w)   # ∇J, ∇²J
        f = self.system.open_loop_dynamics(x)
        g = np.asarray(self.system.control_directions(x), float)
        h = np.asarray(self.system.disturbance_directions(x), float)
        return x, f, g, h, gJ, HJ

    def saddle_point(self, x, rowwise: bool = False):
        """Joint saddle point ``(u*, w*)`` at one state ``(n,)`` or a batch ``(..., n)``.

        The contractions are term by term (:mod:`weakgrid.game.rowwise`) and each matrix is
        solved on its own, so the floats of a state do not depend on the batch it is in;
        ``rowwise``: the input bound's minimization too (:meth:`rows`), point by point
        whatever the count (:meth:`~weakgrid.game.input_bound.InputBound.minimize`'s
        ``pointwise``; with at most 2 inputs).
        """
        return self._saddle_point(x, None, None, rowwise)

    def _saddle_point(self, x, weights, bounds, rowwise):
        """:meth:`saddle_point` with the weights ``weights`` (``(..., L)``, a row each; None:
        this controller's) and the input bounds ``bounds`` (one per row; None: this
        controller's) — each row's floats those of the controller with that row's weights and
        bound (:meth:`rows_of`)."""
        x, f, g, h, gJ, HJ = self._terms(x, weights)
        m, q = g.shape[-1], h.shape[-1]
        B = np.concatenate([g, h], axis=-1)  # (..., n, m+q)
        M = matmul(np.swapaxes(B, -1, -2), matmul(HJ, B))    # B'∇²J B
        reg = np.zeros((m + q, m + q))
        reg[:m, :m] = 2 * self.cost.R
        reg[m:, m:] = -2 * self.cost.gamma**2 * self.cost.P
        rhs = vecmat(gJ + matvec(HJ, f - x), B)               # B'[∇J + ∇²J(f − x)]
        if self.cost.bound is not None:
            return self._bounded_saddle_point(M, rhs, m, rowwise, bounds)
        M = M + reg
        z = -np.linalg.solve(M, rhs[..., None])[..., 0]
        return z[..., :m], z[..., m:]

    def _bounded_saddle_point(self, M, rhs, m, rowwise=False, bounds=None):
        """``u* = argmin_{bound} max_w`` of (22) with ``W(u)``; ``M = B'∇²J B``, ``rhs = B'r``."""
        c = self.cost
        Yw = M[..., m:, m:] - 2 * c.gamma**2 * c.P
        Ghg = M[..., m:, :m]
        Xs = np.linalg.solve(Yw, np.concatenate([Ghg, rhs[..., m:, None]], -1))
        Xg, Xr = Xs[..., :m], Xs[..., m]
        Meff = M[..., :m, :m] - matmul(M[..., :m, m:], Xg)
        beff = rhs[..., :m] - matvec(M[..., :m, m:], Xr)
        Msym = 0.5 * (Meff + np.swapaxes(Meff, -1, -2))
        if bounds is None:
            u = c.bound.minimize(Msym, beff, c.R, pointwise=True if rowwise else None)
        else:       # a bound per row (rows_of), point by point as rowwise
            u = minimize_points(bounds, Msym, beff, c.R)
        w = -(Xr + matvec(Xg, u))
        return u, w

    def unbounded_control(self, x) -> np.ndarray:
        """The saddle point of (24) with ``u'Ru`` from this J (what the bound changes)."""
        if self.cost.bound is None:
            return self.control(x)
        ctl = GameController(self.system, self.basis, self.weights,
                             self.cost.with_bound(None), self.problem)
        return ctl.control(x)

    def bound_activity(self, x) -> dict:
        """Where the input bound acts, at states ``x`` (e.g. the mesh of Ω).

        ``fraction_binding``: the share of states where the unbounded saddle point of
        the same J lies outside the bound; ``fraction_saturated``: where ``u*`` uses
        ≥ 90 % of it; ``max_ratio``: the largest ``‖u*‖/ū`` (≤ 1 by construction).
        """
        if self.cost.bound is None:
            raise ParameterError("cost.u_bound", None, "this controller has no input bound")
        b = self.cost.bound
        r_unb = b.ratio(self.unbounded_control(x))
        r = b.ratio(self.control(x))
        return {"bound": b.to_dict(), "n_points": int(r.size),
                "fraction_binding": float(np.mean(r_unb > 1.0)),
                "fraction_saturated": float(np.mean(r >= 0.9)),
                "max_ratio": float(r.max()), "max_unbounded_ratio": float(r_unb.max())}

    def control(self, x) -> np.ndarray:
        """``u*(x)``."""
        return self.saddle_point(x)[0]

    def disturbance(self, x) -> np.ndarray:
        """Worst-case ``w*(x)``."""
        return self.saddle_point(x)[1]

    __call__ = control

    def rows(self, x) -> np.ndarray:
        """``u*`` at each row of ``x`` (..., n), each row's floats those of :meth:`control` on
        that row alone, however many rows (what a batched simulation calls for the members
        that share this law; ``saddle_point(x, rowwise=True)``)."""
        return self.saddle_point(x, rowwise=True)[0]

    def family_key(self) -> str:
        """Controllers with equal keys differ at most in their weights and in the limits and
        shape of their input bound (the same design model, basis, Q, R, P, γ, and a bound or
        none): :meth:`rows_of` evaluates them in one call. The SHA-256 of their canonical
        description (a design model that cannot be written to a file: its identity).
        Computed once (what it reads is not changed after training)."""
        got = self.__dict__.get("_family_key")
        if got is not None and got[0] is self.system and got[1] is self.cost:
            return got[2]
        try:
            system = self.system.to_dict()
        except NotImplementedError:
            system = f"object:{id(self.system)}"
        key = checksum({"class": f"{type(self).__module__}.{type(self).__qualname__}",
                        "system": [type(self.system).__qualname__, system],
                        "basis": self.basis.to_dict(),
                        "cost": self.cost.with_bound(None).to_dict(),
                        "bounded": self.cost.bound is not None})
        self.__dict__["_family_key"] = (self.system, self.cost, key)
        return key

    @staticmethod
    def rows_of(controllers, x) -> np.ndarray:
        """``controllers[i].rows(x[i])`` for every row of ``x`` (n, n_states) in one call:
        the controllers share :meth:`family_key` (they differ at most in their weights and
        input bounds, e.g. one trained at each UPQC rating), and row ``i``'s floats are those
        of ``controllers[i]`` on that row alone (its weights and bound, rowwise
        arithmetic). With an input bound and more than 2 inputs (whose minimization is not
        point by point), each controller is called on its own rows. Returns ``u*`` (n, m)."""
        ctls = list(controllers)
        x = np.asarray(x, float)
        if x.ndim != 2 or x.shape[0] != len(ctls) or not ctls:
            raise ShapeError("x", x.shape, f"({len(ctls)}, n_states): a row per controller")
        first = ctls[0]
        key = first.family_key()
        for i, c in enumerate(ctls[1:], 1):
            if c is not first and c.family_key() != key:
                raise ParameterError(f"controllers[{i}]", type(c).__name__,
                                     "differs from controllers[0] in more than its weights and "
                                     "input bound: evaluate it with its own rows()")
        if all(c is first for c in ctls):
            return first.rows(x)
        if first.cost.bound is not None and first.system.n_controls > 2:
            # the bound's minimization goes point by point for at most 2 inputs only: each
            # controller on its own rows, as separate calls would
            U = np.empty((len(ctls), first.system.n_controls))
            groups: dict = {}
            for i, c in enumerate(ctls):
                groups.setdefault(id(c), (c, []))[1].append(i)
            for c, idx in groups.values():
                U[idx] = c.rows(x[idx])
            return U
        W = np.stack([c.weights for c in ctls])
        bounds = [c.cost.bound for c in ctls] if first.cost.bound is not None else None
        return first._saddle_point(x, W, bounds, True)[0]

    def hamiltonian(self, x, u, w) -> np.ndarray:
        """The approximate Hamiltonian (22) ``∇J'Δx + ½Δx'∇²JΔx + Q(x) + u'Ru − γ²w'Pw``."""
        x, f, g, h, gJ, HJ = self._terms(x)
        u = np.asarray(u, float)
        w = np.asarray(w, float)
        dx = (f + np.einsum("...nm,...m->...n", g, u) + np.einsum("...nq,...q->...n", h, w) - x)
        return (np.einsum("...n,...n->...", gJ, dx)
                + 0.5 * np.einsum("...i,...ij,...j->...", dx, HJ, dx)
                + self.cost.stage(x, u, w))

    def block_eigenvalues(self, x):
        """Smallest eigenvalue of Yu and largest of Yw at states ``x`` (Yu ≻ 0, Yw ≺ 0 wanted)."""
        x, f, g, h, gJ, HJ = self._terms(x)
        Yu = np.einsum("...ni,...nk,...kj->...ij", g, HJ, g) + 2 * self.cost.R
        Yw = np.einsum("...ni,...nk,...kj->...ij", h, HJ, h) - 2 * self.cost.gamma**2 * self.cost.P
        return np.linalg.eigvalsh(Yu)[..., 0], np.linalg.eigvalsh(Yw)[..., -1]

    def diagnostics(self, x) -> dict:
        """The conditions of the method at states ``x`` (e.g. the mesh): Yu ≻ 0, Yw ≺ 0, J ≥ 0."""
        eu, ew = self.block_eigenvalues(x)
        J = self.value(x)
        xa = np.asarray(x, float)
        radial = np.einsum("...n,...n->...", xa, self.gradient(xa))  # x·∇J: J grows outward
        d = {"min_eig_Yu": float(eu.min()), "max_eig_Yw": float(ew.max()),
             "min_J": float(J.min()), "n_points": int(xa.shape[0]),
             "n_bad_Yu": int((eu <= 0).sum()), "n_bad_Yw": int((ew >= 0).sum()),
             "n_negative_J": int((J < 0).sum()),
             "n_radial_decrease": int(((radial <= 0) & (np.abs(xa).sum(-1) > 0)).sum())}
        if self.cost.bound is not None:
            d["bound"] = self.bound_activity(x)
        return d

    # -------------------------------------------------------------- files
    def to_dict(self) -> dict:
        return {
            "format": FILE_FORMAT,
            "weakgrid_version": _package_version(),
            "problem": self.problem,
            "basis_labels": self.basis.labels(getattr(self.system, "state_names", None)),
            "weights": self.weights.tolist(),
            "iterations": self.iterations,
            "train_seconds": self.train_seconds,
            "history": [r.to_dict() for r in self.history],
        }

    def save(self, path) -> Path:
        """Write the controller to a JSON file (atomically)."""
        if self.problem.get("model", {}).get("serializable") is False:
            raise ParameterError("system", self.system.kind,
                                 "this system has no to_dict(): it cannot be saved to a file")
        return write_json_atomic(path, self.to_dict())


def _field(d, key, where):
    if not isinstance(d, dict) or key not in d:
        raise ParameterError(f"{where}{key}", None,
                             "missing: the file is not a complete controller file; write it "
                             "again with `weakgrid train --output FILE`")
    return d[key]


def _numbers(v, field):
    try:
        a = np.asarray(v, float)
    except (TypeError, ValueError):
        raise ParameterError(field, v, "must be numbers") from None
    if not np.all(np.isfinite(a)):
        raise ParameterError(field, v if a.size < 20 else "…", "must be finite numbers "
                             "(NaN or infinity found): write the file again with `weakgrid "
                             "train`")
    return a


def controller_from_dict(d: dict, system: ControlAffineSystem | None = None) -> GameController:
    """Rebuild a controller from its record, validating every field on the way."""
    if not isinstance(d, dict):
        raise ParameterError("controller file", type(d).__name__,
                             "must be a JSON object written by `weakgrid train`")
    if d.get("format") != FILE_FORMAT:
        raise ParameterError("format", d.get("format"),
                             f"not a weakgrid controller file (expected {FILE_FORMAT!r})")
    problem = _field(d, "problem", "")
    model = _field(problem, "model", "problem.")
    if not isinstance(model, dict):
        raise ParameterError("problem.model", model, "must be an object with a 'kind'")
    system = system or system_from_dict(model)
    b = _field(problem, "basis", "problem.")
    exps = _numbers(_field(b, "exponents", "problem.basis."), "problem.basis.exponents")
    if exps.ndim != 2 or exps.shape[1] != system.n_states or np.any(exps < 0) \
            or np.any(exps != np.round(exps)):
        raise ParameterError("problem.basis.exponents", exps.tolist(),
                             f"one row of {system.n_states} whole numbers ≥ 0 per basis term")
    basis = PolynomialBasis.from_dict(b)
    c = _field(problem, "cost", "problem.")
    for k in ("Q", "R", "P", "gamma"):
        _numbers(_field(c, k, "problem.cost."), f"problem.cost.{k}")
    gamma = float(c["gamma"]) if np.ndim(c["gamma"]) == 0 else np.nan
    if not gamma > 0:
        raise ParameterError("problem.cost.gamma", c["gamma"], "the attenuation level gamma "
                             "must be a number > 0")
    cost = GameCost.from_dict(c)
    w = _numbers(_field(d, "weights", ""), "weights")
    if w.shape != (basis.size,):
        raise ShapeError("weights", w.shape, f"({basis.size},): one weight per basis term "
                         f"({basis.size} in problem.basis)")
    return GameController(system=system, basis=basis, weights=w,
                          cost=cost, problem=problem, history=[],
                          train_seconds=float(d.get("train_seconds") or float("nan")),
                          iterations=d.get("iterations"))


def load_controller(path, system: ControlAffineSystem | None = None) -> GameController:
    """Read a controller file; the system is rebuilt from its record unless given.

    Systems of :mod:`weakgrid.models` are rebuilt once that module is imported
    (``weakgrid.models.load_controller`` does it for you). Every field is
    validated (finite weights, gamma > 0, sizes consistent with the basis, known
    model kind); errors name the file and the field.
    """
    path = Path(path)
    if not path.exists():
        raise FileNotFoundError(2, "controller file does not exist", str(path))
    try:
        d = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as exc:
        raise ParameterError("controller file", str(path), f"is not valid JSON ({exc})") from None
    except UnicodeDecodeError:
        raise ParameterError("controller file", str(path), "is not UTF-8 text (JSON written "
                             "by `weakgrid train` expected)") from None
    try:
        return controller_from_dict(d, system)
    except (ParameterError, ShapeError) as exc:
        raise _in_file(exc, path) from None


def _in_file(exc, path):
    """The same error with the file named in front."""
    exc.args = (f"{path}: {exc.args[0]}",) + exc.args[1:]
    return exc
