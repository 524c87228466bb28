"""Ground truth for small problems: zero-sum dynamic programming on a grid.

Solves, on a rectangular grid over a box around Ω, the Isaacs equation of the
discrete game

    V(x) = min_u max_w [ ℓ_k(x, u, w) + V(Φ_k(x, u, w)) ]

where ``Φ_k`` is the *k-step lifting* of ``x+ = f + g·u + h·w`` with ``u`` and
``w`` held for ``k`` steps and ``ℓ_k`` the stage cost ``x'Qx + u'Ru − γ²w'Pw``
summed over those steps (``k = 1`` is the system itself).

Design choices (and why)
------------------------
* **Policy iteration with exact policy evaluation** (the default, ``k = 1``). The
  paper's models have T ≈ 1 ms while they evolve over tenths of a second, so
  one-step *value* iteration would need thousands of sweeps. Policy iteration
  does not: each iteration evaluates the current pair of grid policies exactly —
  the linear system ``r = c + M r`` (``M`` the sparse interpolation matrix of the
  successors, ``r(0) = 0`` imposed) is solved by a sparse LU factorization, whose
  cost does not depend on T — and then improves the policies. On the presets it
  converges in 10–15 iterations (seconds on a 61 × 61 grid).
* **Interpolation error vs small T.** The interpolation error of one step is paid
  every step, ~1/T times per second: the residual is therefore interpolated with
  Keys' cubic convolution (C¹, O(h⁴), exact for quadratics) rather than
  multilinearly (O(h²)); grid refinement (61 → 81 nodes per axis) changes the
  preset values by ~1e-4 relative.
* **Quadratic prior, pinned origin.** ``V(y) = y'S₀y + r(y)``: ``S₀`` is the game
  Riccati solution of the (lifted) linearization, so the interpolated residual
  ``r`` is only the non-quadratic part — near the origin it vanishes — and
  ``r(0) = 0`` is imposed (the origin must be a grid node): the value cannot drift
  at the origin. ``prior="none"`` (S₀ = 0) or a given matrix are possible.
* **Optional lifting** (``hold_steps = k > 1``): inputs held for ``k`` steps
  (``Φ_k``, ``ℓ_k`` as above) divide the number of decision stages by ``k``. It
  changes the game (the players may switch only every ``k`` steps);
  :func:`lifted_game_riccati` measures that change exactly on the linearization
  (``lifting_bias`` in the result, e.g. 0.9 % at k = 10 and 5 % at k = 25 on
  case 1). Not needed with policy iteration; kept for larger problems.
* **Leaving the grid.** Successor states outside the grid keep their exact
  quadratic part ``y'S₀y``; the residual is read at the nearest point of the grid
  box (``r(clip(y))``, continued as a constant) — except, for a cost with an input
  bound, the cubic residual is continued linearly with the interpolant's own end
  slope (one-sided, second order) up to four cells out (``DPSettings.extrapolate``
  sets it either way). With a bound the residual grows towards the boundary and a
  constant continuation puts a kink there: its negative curvature made the
  saddle-point search fail at the boundary nodes (25 of 41 × 41 on case 1 with
  ``ū = 0.15``), which kept their first policy, and the bounded DP was
  self-consistent to only 4.5 % (41²), 3.0 % (61²), 2.9 % (81²); with the linear
  continuation no node fails and it is 0.95 %, 0.17 %, 0.08 %. Without a bound the
  residual of case 2 falls outward past the power-angle limit: continued linearly
  it makes the game valueless past the box (policy iteration does not converge, V <
  0), so there the constant stays (the unbounded case 1 is the same either way).
  ``margin`` moves the box boundary away from Ω (beware of regions where no
  saddle point exists, e.g. past the power-angle limit).
* **Saddle point per node.** The saddle point of ``ψ(z) = ℓ_k + V(Φ_k)`` over
  ``z = (u, w)`` is found by a few Newton steps on a finite-difference quadratic
  model of ψ (stencil of half a grid cell; exact for quadratic ψ; steps limited to
  two cells). The inertia is checked — ``∂²ψ/∂w² ≺ 0`` (else the maximizer is
  unbounded: γ too small there) and the Schur complement in ``u`` ``≻ 0`` — and
  nodes that fail keep their policy (counted as ``n_bad_inertia``).

* **Input bound** (a cost with :class:`~weakgrid.game.input_bound.InputBound`): the
  stage cost charges ``W(u)`` and the controls stay in the bound. The finite-difference
  model is then of ``ψ − W`` (smooth, defined for any u); w is eliminated from it and
  the reduced ``½u'Mu + b'u + W(u)`` is minimized exactly over the bound by the
  same bounded minimizer as the controller (a Newton step in u against W's barrier
  would crawl away from the boundary). The initial policies are mapped
  into the bound by ``ū·tanh(·/ū)``; the interpolated grid policy of
  :meth:`DPSolution.saddle_point` is a convex combination of admissible nodes.

Everything is vectorized over the nodes (NumPy/SciPy; no Python loop per node).
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .dp_settings import DPSettings
from .errors import ConvergenceError, GammaTooSmallError, ParameterError, ShapeError

__all__ = ["DPSettings", "DPSolution", "solve_game_dp", "lifted_game_riccati"]

#: Cells beyond the box over which the cubic residual is continued linearly when the cost has
#: an input bound (``DPSettings.extrapolate = None``); without a bound it is continued as a
#: constant (see the module).
BOUNDED_EXTRAPOLATE_CELLS = 4.0


def lifted_game_riccati(A, B, E, Q, R, P, gamma, k):
    """Game Riccati solution of the ``k``-step lifting of ``x+ = Ax + Bu + Ew`` (inputs held).

    The lifted game has ``A_k = A^k``, ``[B_k E_k] = Σ_{j<k} A^j [B E]`` and a stage
    cost quadratic in ``(x, u, w)`` with cross terms (the states between samples
    are weighted by Q). Returns ``(S, KL)`` with ``z* = −KL·x``; ``k = 1`` gives
    :func:`~weakgrid.game.lq.solve_game_riccati`'s ``S``.

    Raises
    ------
    GammaTooSmallError
        No stabilizing solution with ``w``-block of ``R̃ + B̃'SB̃`` negative definite.
    """
    A, B, E = (np.atleast_2d(np.asarray(M, float)) for M in (A, B, E))
    n, m, q = A.shape[0], B.shape[1], E.shape[1]
    Bt = np.hstack([B, E])
    Ak = np.eye(n)
    Bk = np.zeros((n, m + q))
    Qk = np.zeros((n, n))
    Nk = np.zeros((n, m + q))
    Rk = np.zeros((m + q, m + q))
    for _ in range(int(k)):
        Qk += Ak.T @ Q @ Ak
        Nk += Ak.T @ Q @ Bk
        Rk += Bk.T @ Q @ Bk
        Bk = A @ Bk + Bt
        Ak = A @ Ak
    Rk[:m, :m] += k * np.asarray(R)
    Rk[m:, m:] -= k * gamma**2 * np.asarray(P)
    try:
        S = sla.solve_discrete_are(Ak, Bk, Qk, Rk, s=Nk)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise GammaTooSmallError(gamma, f"the lifted game Riccati equation (k = {k}) has no "
                                        f"stabilizing solution ({exc})") from None
    S = 0.5 * (S + S.T)
    G = Rk + Bk.T @ S @ Bk
    if np.linalg.eigvalsh(G[m:, m:]).max() >= 0 or np.linalg.eigvalsh(G[:m, :m]).min() <= 0:
        raise GammaTooSmallError(gamma, f"the lifted game (k = {k}) has no saddle point")
    KL = np.linalg.solve(G, Bk.T @ S @ Ak + Nk.T)
    return S, KL


@dataclass
class DPSolution:
    """The grid value ``V = x'S₀x + r(x)`` and the saddle policies on the grid.

    Attributes
    ----------
    axes : list of ndarray
    S0 : ndarray (n, n)
    residual : ndarray, grid shape
    policy : ndarray, grid shape + (m+q,)
        Held ``(u, w)`` at each node.
    settings : DPSettings
    history : list of dict
    lifting_bias : float
        ``max |x'S_k x − x'S_1 x| / max x'S_1 x`` over the grid, on the linearization.
    """

    system: object
    cost: object
    axes: list
    S0: np.ndarray
    residual: np.ndarray
    policy: np.ndarray
    settings: DPSettings
    history: list = field(default_factory=list)
    lifting_bias: float = float("nan")
    seconds: float = float("nan")
    converged: bool = True

    @property
    def points(self):
        g = np.meshgrid(*self.axes, indexing="ij")
        return np.stack([v.ravel() for v in g], -1)

    def value(self, x):
        """``V(x)`` (residual read at the nearest grid-box point outside the box)."""
        x = np.asarray(x, float)
        W, idx = _interp_weights(self.axes, x.reshape(-1, x.shape[-1]),
                                 self.settings.interpolation == "cubic",
                                 _extrapolate_cells(self.settings, self.cost))
        r = (W * self.residual.ravel()[idx]).sum(-1)
        return (np.einsum("pi,ij,pj->p", x.reshape(-1, x.shape[-1]), self.S0,
                          x.reshape(-1, x.shape[-1])) + r).reshape(x.shape[:-1])

    def saddle_point(self, x):
        """``(u, w)`` of the grid policies, multilinearly interpolated (clipped to the box)."""
        x = np.asarray(x, float)
        x2 = x.reshape(-1, x.shape[-1])
        W, idx = _interp_weights(self.axes, x2, cubic=False)
        Z = np.einsum("pc,pck->pk", W, self.policy.reshape(-1, self.policy.shape[-1])[idx])
        m = self.system.n_controls
        return (Z[:, :m].reshape(x.shape[:-1] + (m,)),
                Z[:, m:].reshape(x.shape[:-1] + (Z.shape[1] - m,)))

    def control(self, x):
        return self.saddle_point(x)[0]

    def disturbance(self, x):
        return self.saddle_point(x)[1]

    def to_dict(self):
        return {"settings": self.settings.to_dict(), "axes": [a.tolist() for a in self.axes],
                "S0": self.S0.tolist(), "lifting_bias": self.lifting_bias,
                "converged": self.converged, "seconds": self.seconds,
                "history": self.history}


def _axis_weights(a, x, cubic, cells=0.0):
    """Per-axis interpolation: window start (p,) and weights (p, w) on nodes start…start+w−1.

    ``cells``: how far beyond the ends (in cells) the cubic interpolant is continued linearly
    with its end slope; past that, and always for the multilinear one, as a constant.
    """
    N = len(a)
    h = a[1] - a[0]
    t = (np.clip(x, a[0], a[-1]) - a[0]) / h
    if cubic:  # cells beyond the box (≥ 0), capped: the continuation is linear that far
        below = np.clip((a[0] - x) / h, 0.0, cells)
        above = np.clip((x - a[-1]) / h, 0.0, cells)
    near = np.rint(t)
    t = np.where(np.abs(t - near) <= 1e-9, near, t)  # grid nodes read their own value exactly
    j = np.clip(np.floor(t).astype(np.int64), 0, N - 2)
    s = np.clip(t - j, 0.0, 1.0)
    if not cubic:
        return j, np.stack([1.0 - s, s], -1)
    # Keys' cubic convolution (a = −1/2, Catmull–Rom): exact for quadratics; ghost nodes
    # beyond the ends by quadratic extrapolation (v₋₁ = 3v₀ − 3v₁ + v₂), so the window
    # [b, b+3] with b = clip(j − 1, 0, N − 4) holds every node involved
    s2, s3 = s * s, s * s * s
    ws = np.stack([(-s3 + 2 * s2 - s) / 2, (3 * s3 - 5 * s2 + 2) / 2,
                   (-3 * s3 + 4 * s2 + s) / 2, (s3 - s2) / 2], -1)
    b = np.clip(j - 1, 0, N - 4)
    out = np.zeros((x.shape[0], 4))
    rows = np.arange(x.shape[0])
    for k in range(4):
        node = j - 1 + k
        wk = ws[:, k]
        low, high = node < 0, node > N - 1
        mid = ~(low | high)
        np.add.at(out, (rows[mid], (node - b)[mid]), wk[mid])
        for pos, c in ((0, 3.0), (1, -3.0), (2, 1.0)):
            np.add.at(out, (rows[low], (pos - b)[low]), c * wk[low])
            np.add.at(out, (rows[high], (N - 1 - pos - b)[high]), c * wk[high])
    # beyond the box: the end value plus the distance times the end slope (one-sided,
    # second order: the Keys interpolant's own slope there), a C¹ continuation — a
    # constant one puts a kink at the boundary whose negative curvature breaks the
    # saddle-point search of the nodes next to it
    lo_out, hi_out = below > 0, above > 0
    out[lo_out, :3] += below[lo_out, None] * np.array([1.5, -2.0, 0.5])
    out[hi_out, 1:] += above[hi_out, None] * np.array([0.5, -2.0, 1.5])
    return b, out


def _interp_weights(axes, X, cubic=True, cells=0.0):
    """Tensor-product interpolation on a regular grid: weights and flat indices (p, wⁿ).

    Cubic (Keys, exact for quadratics) or multilinear; points outside the box are read
    at the box, the cubic continued linearly over ``cells`` cells beyond it.
    """
    shape = [len(a) for a in axes]
    strides = np.cumprod([1] + shape[::-1][:-1])[::-1]
    W = np.ones((X.shape[0], 1))
    idx = np.zeros((X.shape[0], 1), dtype=np.int64)
    for i, a in enumerate(axes):
        b, w = _axis_weights(a, X[:, i], cubic, cells)
        off = (b[:, None] + np.arange(w.shape[1])[None]) * strides[i]
        W = (W[:, :, None] * w[:, None, :]).reshape(X.shape[0], -1)
        idx = (idx[:, :, None] + off[:, None, :]).reshape(X.shape[0], -1)
    return W, idx


def _extrapolate_cells(settings, cost):
    """Cells of linear continuation past the box: the setting, else 4 with a bound, else 0."""
    if settings.extrapolate is not None:
        return float(settings.extrapolate)
    return BOUNDED_EXTRAPOLATE_CELLS if cost.bound is not None else 0.0


def _lift(system, cost, X, Z, k, control_penalty=True):
    """``Φ_k`` and ``ℓ_k`` for states (p, n) and held inputs (p, m+q).

    ``control_penalty=False`` leaves ``u'Ru`` (or ``W(u)``) out of ``ℓ_k``.
    """
    m = system.n_controls
    U, Wd = Z[:, :m], Z[:, m:]
    inputs = -cost.gamma**2 * np.einsum("pi,ij,pj->p", Wd, cost.P, Wd)
    if control_penalty:
        inputs = inputs + cost.control_penalty(U)
    x = X
    ell = np.zeros(X.shape[0])
    for _ in range(k):
        ell += np.einsum("pi,ij,pj->p", x, cost.Q, x) + inputs
        x = system.step(x, U, Wd)
    return x, ell


class _Grid:
    def __init__(self, system, cost, axes, S0, k, cubic, cells=0.0):
        self.system, self.cost, self.axes, self.S0, self.k = system, cost, axes, S0, k
        self.cubic, self.cells = cubic, cells
        g = np.meshgrid(*axes, indexing="ij")
        self.X = np.stack([v.ravel() for v in g], -1)
        self.N = self.X.shape[0]
        self.origin = int(np.argmin(np.abs(self.X).sum(1)))
        self.steps = np.array([a[1] - a[0] for a in axes])

    def quad(self, Y):
        return np.einsum("pi,ij,pj->p", Y, self.S0, Y)

    def V(self, Y, r):
        W, idx = _interp_weights(self.axes, Y, self.cubic, self.cells)
        return self.quad(Y) + (W * r[idx]).sum(1)

    def psi(self, X, Z, r, control_penalty=True):
        Y, ell = _lift(self.system, self.cost, X, Z, self.k, control_penalty)
        if not np.all(np.isfinite(Y)):
            Y = np.where(np.isfinite(Y), Y, 1e300)
        return ell + self.V(Y, r)

    def evaluate(self, Z):
        """Exact value of the held policies: solve ``r = c + M r`` with ``r(0) = 0``."""
        Y, ell = _lift(self.system, self.cost, self.X, Z, self.k)
        c = ell + self.quad(Y) - self.quad(self.X)
        W, idx = _interp_weights(self.axes, Y, self.cubic, self.cells)
        rows = np.repeat(np.arange(self.N), W.shape[1])
        M = sp.csr_matrix((W.ravel(), (rows, idx.ravel())), shape=(self.N, self.N))
        A = (sp.identity(self.N, format="csr") - M).tolil()
        A[self.origin, :] = 0.0
        A[self.origin, self.origin] = 1.0
        c = c.copy()
        c[self.origin] = 0.0
        r = spla.spsolve(A.tocsc(), c)
        if not np.all(np.isfinite(r)):
            raise ConvergenceError("policy evaluation failed (singular system): the grid "
                                   "policies do not drive every node to the origin; use a "
                                   "larger gamma, a finer grid or a margin")
        return r

    def improve(self, Z, r, newton_steps):
        """Newton steps on a finite-difference quadratic model of ψ at every node."""
        X = self.X
        N, K = Z.shape
        m = self.system.n_controls
        Bd = np.concatenate([self.system.control_directions(X),
                             self.system.disturbance_directions(X)], axis=-1)  # (N, n, K)
        sens = np.abs(self.k * Bd / self.steps[None, :, None]).max(1)  # cells per unit input
        delta = np.where(sens > 0, 0.5 / np.maximum(sens, 1e-300), 1.0)  # half-cell moves
        offs = [np.zeros(K)]
        for a in range(K):
            for s in (1, -1):
                e = np.zeros(K)
                e[a] = s
                offs.append(e)
        pairs = [(a, b) for a in range(K) for b in range(a + 1, K)]
        for a, b in pairs:
            for sa, sb in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
                e = np.zeros(K)
                e[a], e[b] = sa, sb
                offs.append(e)
        offs = np.array(offs)  # (S, K)
        n_bad = 0
        bound = self.cost.bound
        for _ in range(newton_steps):
            Zs = Z[None] + offs[:, None, :] * delta[None]  # (S, N, K)
            vals = self.psi(np.tile(X, (len(offs), 1)), Zs.reshape(-1, K), r,
                            control_penalty=bound is None).reshape(len(offs), N)
            f0 = vals[0]
            g = np.empty((N, K))
            H = np.empty((N, K, K))
            for a in range(K):
                fp, fm = vals[1 + 2 * a], vals[2 + 2 * a]
                g[:, a] = (fp - fm) / (2 * delta[:, a])
                H[:, a, a] = (fp - 2 * f0 + fm) / delta[:, a] ** 2
            base = 1 + 2 * K
            for p_, (a, b) in enumerate(pairs):
                v = vals[base + 4 * p_: base + 4 * p_ + 4]
                H[:, a, b] = H[:, b, a] = (v[0] - v[1] - v[2] + v[3]) / (
                    4 * delta[:, a] * delta[:, b])
            if bound is not None:
                Z, n_bad = self._bounded_step(Z, g, H, delta, m)
                continue
            ok = np.all(np.isfinite(H), axis=(1, 2)) & np.all(np.isfinite(g), axis=1)
            Hww = H[:, m:, m:]
            ok &= np.linalg.eigvalsh(np.where(ok[:, None, None], Hww, -1.0))[:, -1] < 0
            Hs = np.where(ok[:, None, None], H, np.eye(K))
            schur = Hs[:, :m, :m] - Hs[:, :m, m:] @ np.linalg.solve(Hs[:, m:, m:],
                                                                    Hs[:, m:, :m])
            ok &= np.linalg.eigvalsh(schur)[:, 0] > 0
            n_bad = int((~ok).sum())
            step = -np.linalg.solve(np.where(ok[:, None, None], H, np.eye(K)),
                                    np.where(ok[:, None], g, 0.0)[..., None])[..., 0]
            step = np.clip(step, -4 * delta, 4 * delta)  # trust region: 2 cells
            Z = Z + np.where(ok[:, None], step, 0.0)
        Z[self.origin] = 0.0
        return Z, n_bad


    def _bounded_step(self, Z, g, H, delta, m):
        """Saddle point of (quadratic model of ψ − W) + W(u) over the bound, per node.

        ``g``, ``H`` model ``ψ − W`` about ``Z`` (finite differences). w is eliminated
        (``Hww ≺ 0``) and the reduced ``½u'Mu + b'u + W(u)`` is minimized exactly by
        :meth:`InputBound.minimize` (needs ``M + 2R ≻ 0``): the step may leave the
        boundary region in one go, unlike a Newton step in u against W's barrier.
        """
        bound, R = self.cost.bound, self.cost.R
        K = Z.shape[1]
        ok = np.all(np.isfinite(H), axis=(1, 2)) & np.all(np.isfinite(g), axis=1)
        Hs = np.where(ok[:, None, None], H, np.eye(K) * np.r_[np.ones(m), -np.ones(K - m)])
        gs = np.where(ok[:, None], g, 0.0)
        Hww, Hwu = Hs[:, m:, m:], Hs[:, m:, :m]
        ok &= np.linalg.eigvalsh(Hww)[:, -1] < 0
        Hww = np.where(ok[:, None, None], Hww, -np.eye(K - m))
        Xs = np.linalg.solve(Hww, np.concatenate([Hwu, gs[:, m:, None]], -1))
        Xu, Xg = Xs[..., :m], Xs[..., m]
        M = Hs[:, :m, :m] - np.swapaxes(Hwu, 1, 2) @ Xu
        M = 0.5 * (M + np.swapaxes(M, 1, 2))
        ok &= np.linalg.eigvalsh(M + 2.0 * R)[:, 0] > 0
        M = np.where(ok[:, None, None], M, 0.0)
        u0 = Z[:, :m]
        gh = gs[:, :m] - np.einsum("pwu,pw->pu", Hwu, Xg)
        b = gh - np.einsum("pij,pj->pi", M, u0)
        u_new = bound.minimize(M, b, R)
        du = u_new - u0
        # trust region (2 cells) by scaling the whole u step: stays on the segment, inside
        lim = np.min(4 * delta[:, :m] / np.maximum(np.abs(du), 1e-300), axis=1)
        du *= np.minimum(1.0, lim)[:, None]
        dw = -(Xg + np.einsum("pwu,pu->pw", Xu, du))
        dw = np.clip(dw, -4 * delta[:, m:], 4 * delta[:, m:])
        step = np.where(ok[:, None], np.concatenate([du, dw], 1), 0.0)
        return Z + step, int((~ok).sum())

def solve_game_dp(system, cost, lower, upper, settings: DPSettings | None = None, *,
                  progress=None, start=None, checkpoint=None) -> DPSolution:
    """Solve the zero-sum game on a grid over the box ``[lower, upper]`` (see the module).

    Parameters
    ----------
    system : ControlAffineSystem
    cost : GameCost
    lower, upper : sequence of float
        The region Ω (the grid box is Ω enlarged by ``settings.margin``).
    settings : DPSettings
    progress : callable, optional
        Called with each iteration's record (a dict).
    start : DPState, optional
        Continue from these finished iterations (a checkpoint of the same inputs,
        :mod:`weakgrid.game.checkpoint`): the result is the same, bit for bit, as that
        of a run that was never interrupted.
    checkpoint : callable, optional
        Called with the :class:`~weakgrid.game.checkpoint.DPState` after each
        finished iteration (before ``progress``).

    Returns
    -------
    DPSolution

    Raises
    ------
    GammaTooSmallError
        The lifted linearization has no saddle point at this γ.
    ParameterError
        The origin is not a grid node.
    """
    settings = settings or DPSettings()
    t0 = time.perf_counter()
    lo, hi = np.asarray(lower, float), np.asarray(upper, float)
    n = system.n_states
    if lo.shape != (n,) or hi.shape != (n,):
        raise ShapeError("lower/upper", lo.shape, f"({n},)")
    if len(settings.n_points) != n:
        raise ParameterError("n_points", list(settings.n_points),
                             f"give one count per state ({n})")
    width = hi - lo
    margin = np.broadcast_to(np.asarray(settings.margin, float), (n,)) if np.ndim(
        settings.margin) == 0 or len(settings.margin) == n else None
    if margin is None:
        raise ParameterError("margin", list(settings.margin), f"give one value or {n}")
    lo, hi = lo - margin * width, hi + margin * width
    axes = [np.linspace(a, b, k) for a, b, k in zip(lo, hi, settings.n_points)]
    for i, a in enumerate(axes):
        if not (a[0] < 0 < a[-1]) or np.min(np.abs(a)) > 1e-12 * (a[-1] - a[0]):
            raise ParameterError("n_points", list(settings.n_points),
                                 f"state {i}: the origin must be a grid node (pinned V(0) = 0):"
                                 " use a box symmetric about 0 and an odd number of nodes")
        a[np.argmin(np.abs(a))] = 0.0
    k = settings.hold_steps
    A, B, E = system.linearize()
    S_k, KL = lifted_game_riccati(A, B, E, cost.Q, cost.R, cost.P, cost.gamma, k)
    if isinstance(settings.prior, str):
        S0 = S_k if settings.prior == "riccati" else np.zeros((n, n))
    else:
        S0 = np.asarray(settings.prior, float)
        if S0.shape != (n, n):
            raise ShapeError("prior", S0.shape, f"({n}, {n})")
    grid = _Grid(system, cost, axes, S0, k, settings.interpolation == "cubic",
                 _extrapolate_cells(settings, cost))
    X = grid.X
    # lifting bias on the linearization
    try:
        S_1, _ = lifted_game_riccati(A, B, E, cost.Q, cost.R, cost.P, cost.gamma, 1)
        q1 = np.einsum("pi,ij,pj->p", X, S_1, X)
        qk = np.einsum("pi,ij,pj->p", X, S_k, X)
        bias = float(np.abs(qk - q1).max() / q1.max())
    except GammaTooSmallError:
        bias = float("nan")
    Z = -X @ KL.T  # the lifted linearization's saddle policies
    if cost.bound is not None:
        Z[:, :system.n_controls] = cost.bound._interior(cost.bound.squash(
            Z[:, :system.n_controls]))
    history = []
    converged, first, before = False, 1, 0.0
    if start is None:
        r = grid.evaluate(Z)
        Vold = grid.quad(X) + r
    else:
        Z, r, Vold = (np.array(a, float) for a in (start.policy, start.residual, start.value))
        if Z.shape != (grid.N, system.n_controls + system.n_disturbances) or \
                r.shape != (grid.N,) or Vold.shape != (grid.N,):
            raise ShapeError("checkpoint policy", Z.shape, f"({grid.N}, "
                             f"{system.n_controls + system.n_disturbances}) for this grid "
                             "and model: the checkpoint is of another problem")
        history = [dict(h) for h in start.history]
        first, before = int(start.iteration) + 1, float(start.seconds)
        converged = bool(history) and history[-1]["max_rel_dV"] <= settings.tol
    for it in range(first, settings.max_iterations + 1):
        if converged:  # the checkpoint holds the converged iteration
            break
        t1 = time.perf_counter()
        Znew, n_bad = grid.improve(Z.copy(), r, settings.newton_steps)
        r = grid.evaluate(Znew)
        V = grid.quad(X) + r
        dV = float(np.abs(V - Vold).max() / max(np.abs(V).max(), 1e-300))
        dZ = float(np.abs(Znew - Z).max())
        rec = {"iteration": it, "max_rel_dV": dV, "max_dz": dZ, "n_bad_inertia": n_bad,
               "min_V": float(V.min()), "seconds": time.perf_counter() - t1}
        history.append(rec)
        Z, Vold = Znew, V
        if checkpoint is not None:  # before progress: an iteration reported is one kept
            from .checkpoint import DPState

            checkpoint(DPState(it, Z, r, V, list(history),
                               before + time.perf_counter() - t0))
        if progress is not None:
            progress(rec)
        if dV <= settings.tol:
            converged = True
            break
    shape = tuple(settings.n_points)
    return DPSolution(system, cost, axes, S0, r.reshape(shape),
                      Z.reshape(shape + (Z.shape[1],)), settings, history, bias,
                      before + time.perf_counter() - t0, converged)
