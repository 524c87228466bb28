"""Two-loop policy iteration for the approximate HJI equation (paper, Section IV, Fig. 4).

The cost is approximated by ``J(x) = W'σ(x)`` and the weights are fitted by
weighted residuals on a mesh of the training region Ω (27)–(28). The outer loop
updates the control by (24), the inner loop the disturbance by (23)::

    u⁽⁰⁾ = an initial stabilizing policy;  i = 0
    repeat (outer):
        w⁽ⁱ'⁰⁾ = 0
        repeat (inner): fit J⁽ⁱ'ʲ⁾ from (u⁽ⁱ⁾, w⁽ⁱ'ʲ⁾);  w⁽ⁱ'ʲ⁺¹⁾ from (23)
        until max|Δw| ≤ δw
        u⁽ⁱ⁺¹⁾ from (24) with the last J and w
    until max|Δu| ≤ δu

With an input bound in the cost (:mod:`weakgrid.game.input_bound`, beyond the paper)
the stage cost charges ``W(u)`` instead of ``u'Ru`` in the regression (27)–(28) and
the control update minimizes ``½u'(g'∇²J g)u + u'g'[∇J + ∇²J(f + h·w − x)] + W(u)``
over the bounded set at each mesh point in place of (24); the initial policy is
mapped into the set by ``ū·tanh(·/ū)`` (identical to first order at the origin).

Everything that does not change across iterations (f, g, h and the basis
derivatives at the mesh) is evaluated once. Each fit solves the least-squares
problem by a QR factorization of the regression matrix with normalized columns
(for a monomial basis, scaling the states is a diagonal column scaling, so the
normalization subsumes it); the normal equations are never formed (docs/theory.md, "Two-loop policy iteration").
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass
from typing import Callable

import numpy as np
from scipy.linalg import get_lapack_funcs

from .bases import PolynomialBasis
from .controller import GameController
from .cost import GameCost
from .errors import (
    ControlHessianError,
    ConvergenceError,
    GammaTooSmallError,
    InitialPolicyError,
    NonFiniteError,
    ParameterError,
    ShapeError,
)
from .policies import describe_policy
from .system import ControlAffineSystem

__all__ = ["SolverSettings", "IterationRecord", "solve_hji", "closed_loop_spectral_radius"]


@dataclass(frozen=True)
class SolverSettings:
    """Tolerances and caps of the two-loop policy iteration.

    Parameters
    ----------
    tol_u, tol_w : float
        δu and δw: stop when ``max|Δu| ≤ δu`` (outer) and ``max|Δw| ≤ δw`` (inner),
        the maximum over all mesh points and components.
    max_outer, max_inner : int
        Iteration caps (the outer loop of case 1 is not monotone: keep it generous).
    check_initial_policy : bool
        Refuse an initial policy whose linearized closed loop at the origin is not Schur.
    """

    tol_u: float = 1e-7
    tol_w: float = 1e-7
    max_outer: int = 500
    max_inner: int = 500
    check_initial_policy: bool = True

    def __post_init__(self):
        for nm in ("tol_u", "tol_w"):
            v = getattr(self, nm)
            if not (np.isfinite(v) and v > 0):
                raise ParameterError(f"settings.{nm}", v, "tolerances must be positive")
        for nm in ("max_outer", "max_inner"):
            v = getattr(self, nm)
            if int(v) != v or v < 1:
                raise ParameterError(f"settings.{nm}", v, "iteration caps must be integers ≥ 1")

    def to_dict(self):
        return {"tol_u": self.tol_u, "tol_w": self.tol_w, "max_outer": self.max_outer,
                "max_inner": self.max_inner}


@dataclass
class IterationRecord:
    """One outer iteration of the policy iteration.

    Attributes
    ----------
    outer : int
        Outer iteration index (1-based).
    inner : int
        Inner iterations done in it.
    max_du : float
        ``max|u⁽ⁱ⁺¹⁾ − u⁽ⁱ⁾|`` over the mesh.
    max_dw : list of float
        ``max|w⁽ⁱ'ʲ⁺¹⁾ − w⁽ⁱ'ʲ⁾|`` of every inner iteration.
    residual : float
        Relative residual ``‖XW + Y‖ / ‖Y‖`` of the last fit.
    weights : ndarray
        Weights of the last fit.
    min_J : float
        Smallest ``J`` on the mesh (must be ≥ 0).
    max_eig_Yw : float
        Largest eigenvalue of ``Yw`` on the mesh (must be < 0).
    min_eig_Yu : float
        Smallest eigenvalue of ``Yu`` on the mesh (must be > 0).
    bound_active : float or None
        With an input bound: the fraction of the mesh where the unbounded update (24)
        from the same J and w would leave the bound (None without a bound).
    """

    outer: int
    inner: int
    max_du: float
    max_dw: list
    residual: float
    weights: np.ndarray
    min_J: float
    max_eig_Yw: float
    min_eig_Yu: float
    bound_active: float | None = None

    def to_dict(self):
        d = {"outer": self.outer, "inner": self.inner, "max_du": self.max_du,
             "max_dw": list(self.max_dw), "residual": self.residual,
             "weights": self.weights.tolist(), "min_J": self.min_J,
             "max_eig_Yw": self.max_eig_Yw, "min_eig_Yu": self.min_eig_Yu}
        if self.bound_active is not None:
            d["bound_active"] = self.bound_active
        return d


def closed_loop_spectral_radius(system: ControlAffineSystem, policy, x0=None, eps=1e-6):
    """Spectral radius of the linearization of ``x ↦ f(x) + g(x)π(x)`` at ``x0`` (default 0)."""
    n = system.n_states
    x0 = np.zeros(n) if x0 is None else np.asarray(x0, float)
    d = eps * np.eye(n)
    pts = np.concatenate([x0 + d, x0 - d])

    def F(x):
        return system.step(x, u=policy(x))

    Fx = F(pts)
    Acl = (Fx[:n] - Fx[n:]).T / (2 * eps)
    if not np.all(np.isfinite(Acl)):
        raise NonFiniteError("the initial policy gives NaN or inf near the origin")
    return float(np.max(np.abs(np.linalg.eigvals(Acl))))


def _solve_planes(A, b):
    """Solve ``A[:, :, p] x[:, p] = b[:, p]`` for every point p; A (k, k, p), b (k, p).

    1×1 and 2×2 blocks in closed form (the common case), larger ones by LAPACK.
    """
    k = A.shape[0]
    if k == 1:
        return b / A[0]
    if k == 2:
        det = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
        return np.stack([(A[1, 1] * b[0] - A[0, 1] * b[1]) / det,
                         (A[0, 0] * b[1] - A[1, 0] * b[0]) / det])
    return np.linalg.solve(np.moveaxis(A, -1, 0), b.T[..., None])[..., 0].T


def _extreme_eig(A, which):
    """Smallest ('min') or largest ('max') eigenvalue of each symmetric block, A (k, k, p)."""
    k = A.shape[0]
    if k == 1:
        return A[0, 0]
    if k == 2:
        mean = 0.5 * (A[0, 0] + A[1, 1])
        rad = np.sqrt((0.5 * (A[0, 0] - A[1, 1])) ** 2 + A[0, 1] * A[1, 0])
        return mean - rad if which == "min" else mean + rad
    e = np.linalg.eigvalsh(np.moveaxis(A, -1, 0))
    return e[:, 0] if which == "min" else e[:, -1]


def _quad_planes(M, v):
    """``v'Mv`` at every point, v (k, p)."""
    return ((M @ v) * v).sum(0)


class _Problem:
    """Everything that does not change across iterations, evaluated once at the mesh.

    With ``d = f(x) − x`` and ``v = g·u + h·w`` (the input's effect on the next
    state), the regression row (27) is

        ∇σ'(d + v) + ½(d + v)'∇²σ(d + v) = c0 + Σ_i A_i v_i + ½ Σ_ij D_ij v_i v_j,
        c0 = ∇σ'd + ½ d'∇²σ d,  A_i = ∂_iσ + (∇²σ d)_i,  D_ij = ∂_ij σ,

    a polynomial of degree two in v whose coefficient planes (L, p) are fixed. Only
    the rows ``i`` that some input reaches ("live" rows, one for the paper's model)
    take part. With ``Ws`` the weights, ``∇J + ∇²J d = Ws·A`` and ``∇²J = Ws·D``, so
    the updates (23) and (24) need one matrix-vector product per fit.
    """

    def __init__(self, system, basis, cost, X):
        F = system.open_loop_dynamics(X) - X  # f(x) − x, (p, n)
        G = np.asarray(system.control_directions(X), float)  # (p, n, m)
        H = np.asarray(system.disturbance_directions(X), float)  # (p, n, q)
        for nm, v in (("open_loop_dynamics", F), ("control_directions", G),
                      ("disturbance_directions", H)):
            if not np.all(np.isfinite(v)):
                raise NonFiniteError(f"{nm} gives NaN or inf on the mesh")
        p, n = X.shape
        if G.shape != (p, n, system.n_controls):
            raise ShapeError("control_directions(x)", G.shape, f"({p}, {n}, m)")
        if H.shape != (p, n, system.n_disturbances):
            raise ShapeError("disturbance_directions(x)", H.shape, f"({p}, {n}, q)")
        m, q = G.shape[-1], H.shape[-1]
        live = [i for i in range(n) if np.any(G[:, i]) or np.any(H[:, i])]
        if not live:
            raise ParameterError("control_directions", 0.0,
                                 "no input reaches any state: nothing to optimize")
        self.live, nl = live, len(live)
        mono = basis.planes(np.ascontiguousarray(X.T))  # (K, L, p)
        self.phi = mono[0].T
        dphi = mono[1 : 1 + n]
        d2 = [[None] * n for _ in range(n)]
        for k_, (j, k) in enumerate(basis.second_derivative_pairs()):
            d2[j][k] = d2[k][j] = mono[1 + n + k_]
        Ft = np.ascontiguousarray(F.T)
        d2F = [sum(d2[i][j] * Ft[j] for j in range(n)) for i in range(n)]  # ∇²σ(f − x)
        self.c0 = sum(dphi[i] * Ft[i] + 0.5 * d2F[i] * Ft[i] for i in range(n))
        self.A = np.stack([dphi[i] + d2F[i] for i in live])  # (nl, L, p)
        self.D = np.stack([np.stack([d2[i][j] for j in live]) for i in live])  # (nl, nl, L, p)
        self.G = np.ascontiguousarray(G[:, live].transpose(1, 2, 0))  # (nl, m, p)
        self.H = np.ascontiguousarray(H[:, live].transpose(1, 2, 0))  # (nl, q, p)
        self.m, self.q, self.nl = m, q, nl
        self.pairs = [(i, j) for i in range(nl) for j in range(i, nl)]
        self.Qx = _quad_planes(cost.Q, X.T)
        self.R2 = 2.0 * cost.R[:, :, None]
        self.g2P = 2.0 * cost.gamma**2 * cost.P[:, :, None]
        self.p, self.L = p, basis.size

    def set_column_scale(self, u):
        """Fix the column scaling of the fit from the rows of (27) at (u, w = 0).

        The planes are multiplied once by ``s_l = 1/‖column l‖`` and the iterations
        work with the scaled weights ``Ws = W/s`` (for monomials a diagonal column
        scaling is what scaling the states does: this is QR "on scaled states and
        normalized columns", with the scales of the initial policy).
        """
        X0 = self.rows(np.stack([self.c0] + list(self.A)
                                + [self.D[i, j] * (0.5 if i == j else 1.0)
                                   for i, j in self.pairs]), self.input_effect(u, None))
        norms = np.sqrt(np.einsum("lp,lp->l", X0, X0))
        if not norms.min() > 0.0:
            bad = np.flatnonzero(~(norms > 0)).tolist()
            raise ParameterError(
                "basis", bad, "these basis terms give zero (or non-finite) regression columns "
                "on the mesh (the mesh does not excite them): drop them or widen the mesh")
        s = 1.0 / norms
        sc = s[:, None]
        nl, L, p = self.nl, self.L, self.p
        self.C = np.stack([self.c0 * sc] + [self.A[i] * sc for i in range(nl)]
                          + [self.D[i, j] * sc * (0.5 if i == j else 1.0) for i, j in self.pairs])
        # one (L, ·) matrix: Ws @ AD_L gives ∇J + ∇²J(f−x) on the live rows, then ∇²J
        AD = np.concatenate([self.A.reshape(nl, L, p), self.D.reshape(nl * nl, L, p)]) * sc
        self.AD_L = np.ascontiguousarray(AD.transpose(1, 0, 2)).reshape(L, -1)
        self.phi_s = self.phi * s
        return s

    def input_effect(self, u, w):
        """``v = g·u + h·w`` on the live rows, (nl, p); ``u`` (m, p), ``w`` (q, p) or None."""
        v = (self.G * u).sum(1)
        if w is not None:
            v = v + (self.H * w).sum(1)
        return v

    def rows(self, C, v):
        """Rows of (27) (L, p) for the input effect ``v`` (nl, p)."""
        feats = np.empty((len(C), self.p))
        feats[0] = 1.0
        feats[1 : 1 + self.nl] = v
        for k, (i, j) in enumerate(self.pairs):
            feats[1 + self.nl + k] = v[i] * v[j]
        return np.einsum("klp,kp->lp", C, feats)

    def derivatives(self, Ws):
        """``a = ∇J + ∇²J(f − x)`` (nl, p) and ``HJ = ∇²J`` (nl, nl, p) on the live rows."""
        nl = self.nl
        t = (Ws @ self.AD_L).reshape(nl + nl * nl, self.p)
        return t[:nl], t[nl:].reshape(nl, nl, self.p)

    def best_disturbance_system(self, a, HJ, vu):
        """(23): ``Yw`` (q, q, p) and ``h'[∇J + ∇²J(f + g·u − x)]`` (q, p)."""
        Hd = self.H
        if self.nl == 1:  # one live row (e.g. a swing equation): scalar ∇²J
            H0, h = HJ[0, 0], Hd[0]
            grad = a[0] + H0 * vu[0]
            Yw = (h[:, None] * h[None]) * H0 - self.g2P
            return Yw, h * grad
        HJH = (HJ[:, :, None, :] * Hd[None]).sum(1)  # (nl, q, p): ∇²J h
        Yw = (Hd[:, :, None, :] * HJH[:, None, :, :]).sum(0) - self.g2P
        grad = a + (HJ * vu[None]).sum(1)  # ∇J + ∇²J(f + g·u − x), (nl, p)
        return Yw, (Hd * grad[:, None]).sum(0)

    def best_control_system(self, a, HJ, vw):
        """(24): ``Yu`` (m, m, p) and ``g'[∇J + ∇²J(f + h·w − x)]`` (m, p)."""
        Gd = self.G
        if self.nl == 1:
            H0, g = HJ[0, 0], Gd[0]
            grad = a[0] + H0 * vw[0]
            return (g[:, None] * g[None]) * H0 + self.R2, g * grad
        HJG = (HJ[:, :, None, :] * Gd[None]).sum(1)  # (nl, m, p)
        Yu = (Gd[:, :, None, :] * HJG[:, None, :, :]).sum(0) + self.R2
        grad = a + (HJ * vw[None]).sum(1)
        return Yu, (Gd * grad[:, None]).sum(0)


_geqrf, _ormqr, _trtrs = get_lapack_funcs(("geqrf", "ormqr", "trtrs"), (np.zeros((2, 2)),))


def _lstsq(At, b, check_rank=True):
    """Least squares ``A x ≈ b`` by Householder QR (LAPACK geqrf/ormqr/trtrs).

    ``At`` is ``A`` transposed (L, p), C-ordered, so that ``At.T`` is Fortran-ordered
    for LAPACK; it is overwritten. Columns should be normalized by the caller.

    Returns
    -------
    x : ndarray (L,) or None
        None if ``A`` is numerically rank deficient.
    rank : int
        The numerical rank (L unless ``check_rank`` found less).
    residual : float
        ``‖A x − b‖`` (from the QR factorization, no extra product).
    """
    An = At.T
    p, L = An.shape
    qr, tau, _, info = _geqrf(An, overwrite_a=1)
    rank = L
    if check_rank:
        diag = np.abs(qr.diagonal())
        rank = int(np.count_nonzero(diag > diag.max() * p * _EPS))
        if rank < L:
            return None, rank, np.nan
    cq, _, info = _ormqr("L", "T", qr, tau, b[:, None], lwork=64 * L)
    z, info = _trtrs(qr[:L, :L], cq[:L], lower=0)
    if info > 0:  # an exactly zero pivot
        return None, info - 1, np.nan
    return z[:, 0], rank, float(np.sqrt(np.dot(cq[L:, 0], cq[L:, 0])))


_EPS = float(np.finfo(float).eps)
_ROUNDOFF = 1e4 * _EPS  # changes below this fraction of the magnitude are round-off


def check_mesh_for_basis(mesh, basis):
    """Refuse a grid with too few points along an axis for the basis' degree in that state.

    A polynomial of degree d in x_k is determined by the values at d + 1 distinct
    x_k; with fewer, the regression (27) is underdetermined or ill-conditioned
    and its failures later look like a convexity or gamma problem.
    """
    axes = getattr(mesh, "axes", None)
    if axes is None:
        return
    deg = np.asarray(basis.exponents).max(axis=0)
    for k, ax in enumerate(axes()):
        if len(ax) < deg[k] + 1:
            width = mesh.upper[k] - mesh.lower[k]
            raise ParameterError(
                "mesh.step", list(mesh.step),
                f"only {len(ax)} mesh points along state {k + 1} for a basis of degree "
                f"{int(deg[k])} in it: the regression (27) is underdetermined/ill-conditioned "
                f"(too few mesh points for the basis, not a convexity or gamma problem). Use "
                f"at least {int(deg[k]) + 1} points: step ≤ {width / deg[k]:.3g} along state "
                f"{k + 1} (a few times more points is safer)")


def solve_hji(
    system: ControlAffineSystem,
    basis: PolynomialBasis,
    cost: GameCost,
    mesh,
    initial_policy: Callable[[np.ndarray], np.ndarray],
    settings: SolverSettings | None = None,
    *,
    problem: dict | None = None,
    progress: Callable[[IterationRecord], None] | None = None,
    start=None,
    checkpoint: Callable | None = None,
) -> GameController:
    """Solve the approximate HJI equation by two-loop policy iteration.

    Parameters
    ----------
    system : ControlAffineSystem
    basis : PolynomialBasis
        The cost approximation ``J = W'σ(x)``; no constant term.
    cost : GameCost
    mesh : GridMesh or PointMesh
        Training points on Ω.
    initial_policy : callable, (p, n) -> (p, m)
        A stabilizing state feedback ``u⁽⁰⁾``.
    settings : SolverSettings
    problem : dict, optional
        Extra description recorded in the controller (e.g. the preset name).
    progress : callable, optional
        Called with each :class:`IterationRecord` as it completes.
    start : TrainingState, optional
        Continue from these finished outer iterations (a checkpoint of the same
        inputs, :mod:`weakgrid.game.checkpoint`): the result is the same, bit for
        bit, as that of a run that was never interrupted.
    checkpoint : callable, optional
        Called with the :class:`~weakgrid.game.checkpoint.TrainingState` after each
        finished outer iteration (before ``progress``); e.g. keep it to save on an
        interruption.

    Returns
    -------
    GameController
        With ``history`` (one :class:`IterationRecord` per outer iteration).

    Raises
    ------
    GammaTooSmallError, ControlHessianError, ConvergenceError, InitialPolicyError,
    NonFiniteError, ShapeError, ParameterError
    """
    settings = settings or SolverSettings()
    if basis.n_states != system.n_states:
        raise ShapeError("basis", (basis.size, basis.n_states), f"(L, {system.n_states})")
    if mesh.n_states != system.n_states:
        raise ShapeError("mesh", (mesh.n_states,), f"({system.n_states},) states")
    if not isinstance(cost, GameCost):
        raise ParameterError("cost", type(cost).__name__, "pass a GameCost")
    X = np.asarray(mesh.points, float)
    p = X.shape[0]
    check_mesh_for_basis(mesh, basis)
    if p < basis.size:
        raise ParameterError("mesh", f"{p} points", f"need at least {basis.size} points "
                             f"(one per basis term): use a finer mesh")
    t0 = time.perf_counter()
    pr = _Problem(system, basis, cost, X)

    u = np.asarray(initial_policy(X), float)
    if u.shape != (p, system.n_controls):
        raise ShapeError("initial_policy(x)", u.shape, f"({p}, {system.n_controls})")
    if not np.all(np.isfinite(u)):
        raise NonFiniteError("the initial policy gives NaN or inf on the mesh")
    bound = cost.bound
    if bound is not None:
        u = bound.squash(u)  # admissible: inside the bound, unchanged to first order
    if settings.check_initial_policy:
        rho = closed_loop_spectral_radius(system, initial_policy)
        if rho >= 1.0:
            raise InitialPolicyError(
                f"the initial policy does not stabilize the system: the closed loop "
                f"linearized at the origin has spectral radius {rho:.6f} ≥ 1. Policy "
                "iteration needs a stabilizing (admissible) u⁽⁰⁾: use an LQR of the "
                "linearization or a stabilizing nonlinear law."
            )

    q = system.n_disturbances
    history: list[IterationRecord] = []
    u = np.ascontiguousarray(u.T)  # (m, p): per-point quantities are kept as planes
    g2 = cost.gamma**2
    cs = pr.set_column_scale(u)  # from the initial policy, also when resuming
    first, seconds_before, done = 1, 0.0, False
    if start is not None:
        u, history, first, seconds_before, done = _resume(start, p, system.n_controls,
                                                          basis.size, settings)
    for i in range(first, settings.max_outer + 1):
        if done:  # the checkpoint already holds the converged iteration
            break
        w = np.zeros((q, p))
        base_Y = pr.Qx + (_quad_planes(cost.R, u) if bound is None
                          else bound.penalty(u.T, cost.R))
        vu = pr.input_effect(u, None)
        dws = []
        for j in range(1, settings.max_inner + 1):
            vw = (pr.H * w).sum(1)
            Xt = pr.rows(pr.C, vu + vw)  # scaled columns: the fit gives Ws = W/cs
            if j == 1:
                Y = base_Y
            elif q == 1:
                Y = base_Y - (g2 * cost.P[0, 0]) * (w[0] * w[0])
            else:
                Y = base_Y - g2 * _quad_planes(cost.P, w)
            # rank checked on the first fit of each outer iteration (the columns change
            # little with w); an exactly singular R is caught at every fit
            Ws, rank, res = _lstsq(Xt, -Y, check_rank=(j == 1))
            if Ws is None:
                raise ParameterError(
                    "mesh", f"rank {rank} < {basis.size}",
                    "the regression matrix (27) is rank deficient: the mesh cannot determine "
                    "every weight; use a finer or wider mesh or a smaller basis")
            a, HJ = pr.derivatives(Ws)
            # (23): Yw·w = −h'[∇J + ∇²J(f + g·u − x)]
            Yw, rhs = pr.best_disturbance_system(a, HJ, vu)
            eYw = _extreme_eig(Yw, "max")
            if not eYw.max() < 0:
                k = int(np.argmax(np.nan_to_num(eYw, nan=np.inf)))
                where = f" (outer iteration {i}, inner {j})"
                if i == 1:
                    where += (": the initial policy may attenuate disturbances less than "
                              "gamma; a better initial policy may help")
                raise GammaTooSmallError.from_mesh(
                    cost.gamma, int((eYw >= 0).sum()), p, X[k], float(eYw[k]), where=where)
            w_new = -_solve_planes(Yw, rhs)
            dw = float(np.abs(w_new - w).max())
            if not np.isfinite(dw):  # NaN anywhere in W or w propagates here
                raise NonFiniteError(f"the weights or the disturbance became NaN/inf at outer "
                                     f"iteration {i}, inner {j}")
            dws.append(dw)
            w = w_new
            if dw <= settings.tol_w:
                break
            if j >= 40 and min(dws[-10:]) >= min(dws[:-10]):
                floor = _ROUNDOFF * max(float(np.abs(w).max()), 1e-300)
                if min(dws) <= floor:
                    raise ConvergenceError(
                        f"settings.tol_w = {settings.tol_w:g} is below what double-precision "
                        f"arithmetic can reach: max|Δw| stalls at {min(dws):.2e} (round-off of "
                        f"|w| ≈ {float(np.abs(w).max()):.2e}) at outer iteration {i}. Fix: use "
                        f"tol_w ≥ {10 * min(dws):.0e} (e.g. 1e-7)", history)
                # for a fixed control the inner loop is a policy iteration of the
                # maximizing player: it contracts when gamma exceeds the attenuation
                # level of that control; no progress in 10 iterations means it does not
                raise GammaTooSmallError(
                    cost.gamma,
                    f"the inner (disturbance) loop does not contract at outer iteration {i} "
                    f"(max|Δw| of the last iterations: {[f'{v:.2e}' for v in dws[-5:]]}, "
                    f"best {min(dws):.2e} after {j} iterations): gamma is below the "
                    "attenuation level of the current control policy"
                    + (" (the initial policy)" if i == 1 else ""))
        else:
            raise ConvergenceError(
                f"the inner (disturbance) loop did not converge in {settings.max_inner} "
                f"iterations at outer iteration {i}: last max|Δw| = {dws[-1]:.3e} > δw = "
                f"{settings.tol_w:g} (changes of the last iterations: "
                f"{[f'{v:.2e}' for v in dws[-5:]]}). Raise max_inner, loosen tol_w, or "
                "increase gamma.", history)
        # (24) with the last J and w: Yu·u = −g'[∇J + ∇²J(f + h·w − x)]
        W = Ws * cs
        Yu, rhs = pr.best_control_system(a, HJ, (pr.H * w).sum(1))
        eYu = _extreme_eig(Yu, "min")
        if not eYu.min() > 0:
            k = int(np.argmin(np.nan_to_num(eYu, nan=-np.inf)))
            raise ControlHessianError(
                f"Yu = g'∇²J g + 2R is not positive definite at {int((eYu <= 0).sum())} of "
                f"{p} mesh points (worst at x = {X[k].tolist()}, eigenvalue {eYu[k]:.3g}) in "
                f"outer iteration {i}: the fitted cost is not convex enough; increase R or "
                "use a richer basis.")
        u_new = -_solve_planes(Yu, rhs)
        active = None
        if bound is not None:
            # the bounded update: argmin ½u'(Yu − 2R)u + u'rhs + W(u) at every point
            active = float(np.mean(bound.ratio(u_new.T) > 1.0))
            u_new, info = bound.minimize(np.moveaxis(Yu - pr.R2, -1, 0), rhs.T, cost.R,
                                         return_info=True)
            u_new = np.ascontiguousarray(u_new.T)
            if info["n_unconverged"]:
                warnings.warn(f"the bounded control update did not converge at "
                              f"{info['n_unconverged']} mesh points in outer iteration {i} "
                              f"(largest relative residual {info['max_residual']:.2e})",
                              RuntimeWarning, stacklevel=2)
        du = float(np.abs(u_new - u).max())
        if not np.isfinite(du):
            raise NonFiniteError(f"the control became NaN/inf at outer iteration {i}")
        rec = IterationRecord(
            outer=i, inner=len(dws), max_du=du, max_dw=dws,
            residual=res / max(float(np.sqrt(np.dot(Y, Y))), 1e-300),
            weights=W, min_J=float((pr.phi_s @ Ws).min()),
            max_eig_Yw=float(eYw.max()), min_eig_Yu=float(eYu.min()), bound_active=active)
        history.append(rec)
        u = u_new
        if checkpoint is not None:  # before progress: an iteration reported is one kept
            from .checkpoint import TrainingState

            checkpoint(TrainingState(i, u.T, list(history),
                                     seconds_before + time.perf_counter() - t0))
        if progress is not None:
            progress(rec)
        if du <= settings.tol_u:
            break
        if (i >= 20 and du <= _ROUNDOFF * max(float(np.abs(u).max()), 1e-300)
                and min(r.max_du for r in history[-10:]) >= min(r.max_du for r in history[:-10])):
            raise ConvergenceError(
                f"settings.tol_u = {settings.tol_u:g} is below what double-precision arithmetic "
                f"can reach: max|Δu| stalls at {du:.2e} (round-off of |u| ≈ "
                f"{float(np.abs(u).max()):.2e}). Fix: use tol_u ≥ {10 * du:.0e} (e.g. 1e-7)",
                history)
    else:
        if not done:
            raise ConvergenceError(
                f"the outer (control) loop did not converge in {settings.max_outer} "
                f"iterations: last max|Δu| = {history[-1].max_du:.3e} > δu = "
                f"{settings.tol_u:g} (changes of the last iterations: "
                f"{[f'{r.max_du:.2e}' for r in history[-5:]]}). Raise max_outer or loosen "
                "tol_u.", history)
    if done:  # resumed after the last iteration: its weights are the result
        W = history[-1].weights
        Ws = W / cs

    J = pr.phi_s @ Ws
    if J.min() < -1e-9 * max(1.0, float(np.abs(J).max())):
        k = int(np.argmin(J))
        warnings.warn(
            f"the trained cost J is negative at {int((J < 0).sum())} of {p} mesh points "
            f"(minimum {J[k]:.3g} at x = {X[k].tolist()}): the basis cannot represent a "
            "nonnegative value on this region; use a richer basis or a smaller region",
            RuntimeWarning, stacklevel=2)
    elapsed = seconds_before + time.perf_counter() - t0
    record = {
        "model": _system_record(system),
        "cost": cost.to_dict(),
        "mesh": mesh.to_dict(),
        "basis": basis.to_dict(),
        "initial_policy": describe_policy(initial_policy)
        if bound is None else {**describe_policy(initial_policy),
                               "mapped_into_bound": "u_bar*tanh(u/u_bar)"},
        "settings": settings.to_dict(),
    }
    if problem:
        record.update(problem)
    return GameController(system=system, basis=basis, weights=W, cost=cost, problem=record,
                          history=history, train_seconds=elapsed)


def _resume(start, p, m, L, settings):
    """The loop state from a :class:`~weakgrid.game.checkpoint.TrainingState`, checked
    against this problem: ``(u (m, p), history, first outer index, seconds, converged)``."""
    policy = np.asarray(start.policy, float)
    if policy.shape != (p, m):
        raise ShapeError("checkpoint policy", policy.shape, f"({p}, {m}) for this mesh "
                         "and model: the checkpoint is of another problem")
    if len(start.history) != start.outer or start.outer < 1:
        raise ParameterError("checkpoint outer", start.outer,
                             f"holds {len(start.history)} iteration records")
    if any(np.shape(r.weights) != (L,) for r in start.history):
        raise ShapeError("checkpoint weights", np.shape(start.history[-1].weights),
                         f"({L},) for this basis")
    history = list(start.history)
    done = history[-1].max_du <= settings.tol_u
    return (np.ascontiguousarray(policy.T), history, start.outer + 1, float(start.seconds),
            done)


def _system_record(system):
    try:
        return system.to_dict()
    except NotImplementedError:
        return {"kind": system.kind, "serializable": False}
