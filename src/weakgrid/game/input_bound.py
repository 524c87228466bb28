"""A bound on the control as part of the cost: the constrained-input (non-quadratic) penalty.

Beyond the paper. The cost (18) charges ``u'Ru``; a device with a rating cannot apply
more than ``ū``. Following the constrained-input formulation of optimal control
(Abu-Khalaf, Lewis and Huang), the quadratic charge is replaced by

    W(u) = 2 ∫₀ᵘ (ū·tanh⁻¹(v/ū))ᵀ R dv

* **box** ``|u_i| ≤ ū_i``, R diagonal: per component,
  ``W(u) = 2 Σ r_i ū_i² ψ(|u_i|/ū_i)``;
* **disk** ``‖u‖ ≤ ū``, R = r·I: the same function of ``‖u‖`` along the direction of u,
  ``W(u) = 2 r ū² ψ(‖u‖/ū)``,

with ``ψ(ρ) = ½[(1+ρ)ln(1+ρ) + (1−ρ)ln(1−ρ)] = ρ²/2 + ρ⁴/12 + …``, so that
``W(u) = u'Ru·(1 + O(‖u‖²/ū²))``: as ``ū → ∞`` the cost tends to (18). W is finite
on the closed set (``2rū² ln 2`` per saturated component) while its gradient
``2R·ū·tanh⁻¹(u/ū)`` grows without bound at the boundary: every minimizer of
``(quadratic in u) + W(u)`` lies strictly inside.

The control update replacing (24) minimizes over u, at each point,

    F(u) = ½ u'M u + b'u + W(u),   M = g'∇²J g,  b = g'[∇J + ∇²J(f + h·w − x)]

whose stationarity condition ``b + Mu + ∇W(u) = 0`` is, in the Abu-Khalaf–Lewis form,
``u = −ū·tanh((2R)⁻¹(b + Mu)/ū)`` (per component for the box, radially for the disk):
implicit in u because of the second-order term M. ``Yu = M + 2R ≻ 0`` (the condition
of the unconstrained method) makes F strongly convex with Hessian ``⪰ Yu`` on the set,
so the minimizer is unique; it is found by damped Newton steps (fraction-to-boundary
rule and Armijo backtracking on F), vectorized over the points, started from the
exact solution for ``M = 0`` and finished by one evaluation of the tanh form — which
returns a control inside the bound by construction.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import ParameterError, ShapeError

__all__ = ["SHAPES", "InputBound", "minimize_points"]

SHAPES = ("box", "disk")
_SMALL = 0.1  # below this ρ the series are used (10 terms reach rounding)
_K = np.arange(1, 11, dtype=float)


#: up to this many points (with m ≤ 2 inputs), :meth:`InputBound.minimize` iterates point by
#: point on Python floats (the break-even with the vectorized iteration: 16–20 points, measured
#: 2026-12-02 on the case-2 sweep's samples, ≈ 16 µs a point against 250–300 µs a call)
POINTWISE_MAX = 16


def _psi(rho):
    """``ψ(ρ) = ½[(1+ρ)ln(1+ρ) + (1−ρ)ln(1−ρ)]`` for ρ ∈ [0, 1] (ψ(1) = ln 2)."""
    rho = np.asarray(rho, float)
    r = np.minimum(rho, 1.0)
    small = r < _SMALL
    rs = np.where(small, r, 0.0)
    r2 = rs * rs
    series = 0.5 * (r2[..., None] ** _K / (_K * (2 * _K - 1))).sum(-1)
    rb = np.where(small, 0.5, r)
    one_m = 1.0 - rb
    big = 0.5 * ((1.0 + rb) * np.log1p(rb)
                 + np.where(one_m > 0, one_m * np.log(np.where(one_m > 0, one_m, 1.0)), 0.0))
    return np.where(small, series, big)


def _kappa(rho):
    """``κ(ρ) = tanh⁻¹(ρ)/ρ`` (κ(0) = 1), ρ ∈ [0, 1)."""
    rho = np.asarray(rho, float)
    small = rho < _SMALL
    rs = np.where(small, rho, 0.0)
    series = (rs[..., None] ** (2 * _K - 2) / (2 * _K - 1)).sum(-1)
    rb = np.where(small, 0.5, rho)
    return np.where(small, series, np.arctanh(rb) / rb)


def _eta(rho):
    """``η(ρ) = (1/(1−ρ²) − κ(ρ))/ρ²`` (η(0) = 2/3), ρ ∈ [0, 1)."""
    rho = np.asarray(rho, float)
    small = rho < _SMALL
    rs = np.where(small, rho, 0.0)
    series = (rs[..., None] ** (2 * _K - 2) * (2 * _K / (2 * _K + 1))).sum(-1)
    rb = np.where(small, 0.5, rho)
    return np.where(small, series, (1.0 / (1.0 - rb * rb) - np.arctanh(rb) / rb) / (rb * rb))


def _solve(A, b):
    """Batched ``A x = b``: A (..., m, m), b (..., m)."""
    m = A.shape[-1]
    if m == 1:
        return b / A[..., 0]
    if m == 2:
        det = A[..., 0, 0] * A[..., 1, 1] - A[..., 0, 1] * A[..., 1, 0]
        return np.stack([(A[..., 1, 1] * b[..., 0] - A[..., 0, 1] * b[..., 1]) / det,
                         (A[..., 0, 0] * b[..., 1] - A[..., 1, 0] * b[..., 0]) / det], -1)
    return np.linalg.solve(A, b[..., None])[..., 0]


@dataclass(frozen=True, eq=False)
class InputBound:
    """The admissible control set and its penalty (see the module).

    Parameters
    ----------
    shape : {"box", "disk"}
    limit : ndarray
        ``ū``: one value per input (box) or one value (disk), in the units of u.
    """

    shape: str
    limit: np.ndarray

    @classmethod
    def for_inputs(cls, m: int, limit, shape: str = "disk") -> InputBound:
        """Check and build a bound for ``m`` inputs (a scalar box limit applies to each)."""
        if shape not in SHAPES:
            raise ParameterError("cost.u_bound_shape", shape, "use 'disk' (‖u‖ ≤ ū) or 'box' "
                                 "(|u_i| ≤ ū_i)")
        lim = np.atleast_1d(np.asarray(limit, float))
        if lim.ndim != 1 or not np.all(np.isfinite(lim)) or not np.all(lim > 0):
            raise ParameterError("cost.u_bound", np.asarray(limit).tolist(),
                                 "the input bound must be positive and finite (e.g. 0.15, the "
                                 "rating in the units of u); omit it for no bound")
        if shape == "disk":
            if lim.size != 1:
                raise ParameterError("cost.u_bound", lim.tolist(),
                                     "a disk bound ‖u‖ ≤ ū takes one value")
        else:
            if lim.size == 1:
                lim = np.full(m, lim[0])
            if lim.size != m:
                raise ParameterError("cost.u_bound", lim.tolist(),
                                     f"a box bound takes one value or one per input ({m})")
        return cls(shape, lim)

    def check_weight(self, R):
        """The penalty needs R diagonal (box) or a multiple of I (disk)."""
        R = np.asarray(R, float)
        if not np.allclose(R, np.diag(np.diag(R)), rtol=0, atol=1e-14 * np.abs(R).max()):
            raise ParameterError("cost.R", R.tolist(), "with an input bound R must be diagonal")
        d = np.diag(R)
        if self.shape == "disk" and not np.allclose(d, d[0], rtol=1e-14, atol=0):
            raise ParameterError("cost.R", R.tolist(), "with a disk bound R must be r·I (the "
                                 "radial penalty has one weight); use a box bound otherwise")

    # ------------------------------------------------------------ maps
    def ratio(self, u) -> np.ndarray:
        """How much of the bound u uses: ``max_i |u_i|/ū_i`` (box) or ``‖u‖/ū`` (disk)."""
        u = np.asarray(u, float)
        if self.shape == "box":
            return np.abs(u / self.limit).max(-1)
        return np.sqrt((u * u).sum(-1)) / self.limit[0]

    def clip(self, u) -> np.ndarray:
        """Projection onto the set (radial for the disk): what a device's limiter does."""
        u = np.asarray(u, float)
        if self.shape == "box":
            return np.clip(u, -self.limit, self.limit)
        s = np.sqrt((u * u).sum(-1, keepdims=True))
        return u * np.minimum(1.0, self.limit[0] / np.maximum(s, 1e-300))

    def squash(self, v) -> np.ndarray:
        """``ū·tanh(v/ū)`` per component (box) or along v (disk): ℝᵐ into the set."""
        v = np.asarray(v, float)
        if self.shape == "box":
            return self.limit * np.tanh(v / self.limit)
        ub = self.limit[0]
        s = np.sqrt((v * v).sum(-1, keepdims=True))
        t = s / ub
        small = t < 1e-8
        fac = np.where(small, 1.0 - t * t / 3.0, np.tanh(t) / np.where(small, 1.0, t))
        u = v * fac
        over = self.ratio(u)[..., None]  # ‖u‖ = ū·tanh(t) may round above ū
        return np.where(over > 1.0, u / np.where(over > 1.0, over, 1.0) * (1.0 - 2.0 ** -52),
                        u)

    # --------------------------------------------------------- penalty
    def penalty(self, u, R) -> np.ndarray:
        """``W(u)``, shape ``(...)``, for u inside the closed set."""
        u = np.asarray(u, float)
        r = np.diag(np.asarray(R, float))
        if self.shape == "box":
            L = self.limit
            return (2.0 * r * L * L * _psi(np.abs(u) / L)).sum(-1)
        L = self.limit[0]
        return 2.0 * r[0] * L * L * _psi(np.sqrt((u * u).sum(-1)) / L)

    def penalty_gradient(self, u, R) -> np.ndarray:
        """``∇W(u) = 2R·ū·tanh⁻¹(u/ū)`` (radially for the disk), inside the open set."""
        u = np.asarray(u, float)
        r = np.diag(np.asarray(R, float))
        if self.shape == "box":
            return 2.0 * r * self.limit * np.arctanh(u / self.limit)
        rho = np.sqrt((u * u).sum(-1, keepdims=True)) / self.limit[0]
        return 2.0 * r[0] * _kappa(rho) * u

    def penalty_hessian(self, u, R) -> np.ndarray:
        """``∇²W(u)`` (..., m, m), inside the open set; ``⪰ 2R``."""
        u = np.asarray(u, float)
        r = np.diag(np.asarray(R, float))
        m = u.shape[-1]
        if self.shape == "box":
            z = u / self.limit
            return np.eye(m) * (2.0 * r / (1.0 - z * z))[..., None, :]
        L = self.limit[0]
        rho = np.sqrt((u * u).sum(-1)) / L
        return 2.0 * r[0] * (_kappa(rho)[..., None, None] * np.eye(m)
                             + _eta(rho)[..., None, None] * u[..., :, None] * u[..., None, :]
                             / (L * L))

    def _interior(self, u):
        """Pull points that rounding put on the boundary just inside it."""
        keep = 1.0 - 4.0 * np.finfo(float).eps
        if self.shape == "box":
            return np.clip(u, -keep * self.limit, keep * self.limit)
        rho = self.ratio(u)[..., None]
        return np.where(rho > keep, u * (keep / np.maximum(rho, 1e-300)), u)

    def _max_step(self, u, d):
        """Largest α ≥ 0 with ``u + αd`` in the closed set (inf if none binds)."""
        if self.shape == "box":
            L = self.limit
            with np.errstate(divide="ignore", invalid="ignore"):
                a = np.where(d > 0, (L - u) / d, np.where(d < 0, (-L - u) / d, np.inf))
            return a.min(-1)
        L = self.limit[0]
        dd = (d * d).sum(-1)
        ud = (u * d).sum(-1)
        gap = np.maximum(L * L - (u * u).sum(-1), 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            a = (gap) / (ud + np.sqrt(ud * ud + dd * gap))
        return np.where(dd > 0, np.where(np.isfinite(a), a, np.inf), np.inf)

    def squash_jacobian(self, v) -> np.ndarray:
        """``∂squash/∂v`` (..., m, m): symmetric, eigenvalues in (0, 1]."""
        v = np.asarray(v, float)
        m = v.shape[-1]
        if self.shape == "box":
            t = v / self.limit
            return np.eye(m) * (1.0 / np.cosh(np.minimum(np.abs(t), 350.0)) ** 2)[..., None, :]
        L = self.limit[0]
        t = np.sqrt((v * v).sum(-1)) / L
        small = t < 1e-3
        ts = np.where(small, 1.0, t)
        t2 = t * t
        fac = np.where(small, 1.0 - t2 / 3.0 + 2.0 * t2 * t2 / 15.0, np.tanh(ts) / ts)
        sech2 = 1.0 / np.cosh(np.minimum(t, 350.0)) ** 2
        c = np.where(small, -2.0 / 3.0 + 8.0 * t2 / 15.0 - 34.0 * t2 * t2 / 105.0,
                     (sech2 - fac) / (ts * ts))
        return (fac[..., None, None] * np.eye(m)
                + c[..., None, None] * v[..., :, None] * v[..., None, :] / (L * L))

    def penalty_of_v(self, v, R) -> np.ndarray:
        """``W(squash(v))`` computed from v (exact in deep saturation).

        With ``t = |v|/ū`` (per component, or ``‖v‖/ū``): ``ū²ψ(tanh t) = ū²(t·tanh t −
        ln cosh t)``, ``ln cosh t = log1p(2 sinh²(t/2))``.
        """
        v = np.asarray(v, float)
        r = np.diag(np.asarray(R, float))
        if self.shape == "box":
            t = np.abs(v) / self.limit
            L2 = self.limit ** 2
        else:
            t = np.sqrt((v * v).sum(-1)) / self.limit[0]
            L2 = self.limit[0] ** 2
        big = t > 20.0
        tb = np.where(big, 0.0, t)
        lc = np.where(big, t - np.log(2.0), np.log1p(2.0 * np.sinh(0.5 * tb) ** 2))
        val = 2.0 * L2 * (t * np.tanh(t) - lc)
        if self.shape == "box":
            return (r * val).sum(-1)
        return r[0] * val

    def minimize(self, M, b, R, max_iter: int = 100, return_info: bool = False,
                 pointwise: bool | None = None):
        """``argmin_u ½u'Mu + b'u + W(u)`` at every point (see the module).

        Solved in the unbounded variable v of ``u = squash(v)`` (``ū·tanh(v/ū)``), in
        which stationarity reads ``G(v) = 2Rv + b + M·squash(v) = 0``. The Newton
        direction of G is the Newton direction of F mapped by ``∂squash/∂v`` (its
        Jacobian ``2R + M·∂squash/∂v`` is similar to a positive definite matrix when
        ``M + 2R ≻ 0``); steps are damped by Armijo backtracking on F; a point where
        the direction is not one of descent takes the fixed-point step instead. No
        step can leave the bound. The result is the tanh form
        ``u = squash(−(2R)⁻¹(b + Mu))`` evaluated at the solution.

        Parameters
        ----------
        M : (..., m, m)
            Symmetric, with ``M + 2R ≻ 0`` (checked by the callers: Yu ≻ 0).
        b : (..., m)
        R : (m, m)
        pointwise : bool, optional
            With at most 2 inputs, iterate point by point on Python floats (each point's
            floats then do not depend on the others: what the rows of a batched simulation
            need) or on the arrays of all points at once (the same iteration, equal to
            rounding, cheaper beyond about 16 points); default: point by point up to
            :data:`POINTWISE_MAX` points. Ignored for more inputs (always the arrays).

        Returns
        -------
        u : (..., m)
            Inside the bound (``ratio(u) ≤ 1``) by construction.
        info : dict, if ``return_info``
            ``iterations``, ``n_unconverged`` (points still moving after ``max_iter``)
            and ``max_residual`` (largest ``|G|``, relative to ``|b| + ‖M‖ū + 2rū``).
        """
        M = np.asarray(M, float)
        b = np.asarray(b, float)
        R = np.asarray(R, float)
        m = b.shape[-1]
        shape = b.shape[:-1]
        n_pts = b.size // m
        if m <= 2 and (n_pts <= POINTWISE_MAX if pointwise is None else pointwise):
            # a few points (a controller sample, a small batch's rows): the same iteration on
            # Python floats, point by point — the vectorized form below costs ~0.3 ms of numpy
            # call overhead whatever the count, a point ~16 µs (measured, m = 2)
            out = _minimize_points([self] * n_pts, M, b, R, max_iter, return_info)
            u = np.asarray([o[0] for o in out], float).reshape(shape + (m,))
            if not return_info:
                return u
            infos = [o[1] for o in out]
            return u, {"iterations": max((i["iterations"] for i in infos), default=0),
                       "n_unconverged": sum(i["n_unconverged"] for i in infos),
                       "max_residual": max((i["max_residual"] for i in infos), default=0.0)}
        M = np.broadcast_to(M, shape + (m, m)).reshape(-1, m, m)
        b = b.reshape(-1, m)
        twoR = 2.0 * np.diag(R)
        L = self.limit.max()
        scale = (np.abs(b).max(-1) + np.abs(M).max((-2, -1)) * L + twoR.max() * L)

        def F(v, M, b):
            u = self.squash(v)
            return (0.5 * np.einsum("pi,pij,pj->p", u, M, u) + (b * u).sum(-1)
                    + self.penalty_of_v(v, R))

        def G(v, M, b):
            return twoR * v + b + np.einsum("pij,pj->pi", M, self.squash(v))

        v = _solve(M + 2.0 * R, -b)  # exact for M = 0
        active = np.ones(v.shape[0], bool)
        it = 0
        for it in range(1, max_iter + 1):
            idx = np.flatnonzero(active)
            if idx.size == 0:
                break
            va, Ma, ba = v[idx], M[idx], b[idx]
            g = G(va, Ma, ba)
            Sj = self.squash_jacobian(va)
            d = -_solve(np.eye(m) * twoR + Ma @ Sj, g)
            slope = np.einsum("pi,pij,pj->p", g, Sj, d)  # dF/dα along v + αd
            bad = ~np.all(np.isfinite(d), -1) | (slope >= 0)
            if bad.any():  # fixed-point step v ← −(2R)⁻¹(b + M·squash(v))
                d[bad] = -g[bad] / twoR
                slope = np.einsum("pi,pij,pj->p", g, Sj, d)
            alpha = np.ones(idx.size)
            f0 = F(va, Ma, ba)
            tol_f = 1e-15 * (np.abs(f0) + 1.0)
            for _ in range(60):  # Armijo backtracking on F
                vn = va + alpha[:, None] * d
                fail = F(vn, Ma, ba) > f0 + 1e-4 * alpha * np.minimum(slope, 0.0) + tol_f
                if not fail.any():
                    break
                alpha = np.where(fail, 0.5 * alpha, alpha)
            vn = va + alpha[:, None] * d
            v[idx] = vn
            dv = np.abs(vn - va).max(-1)
            done = ((np.abs(g).max(-1) <= 1e-14 * scale[idx])
                    | (dv <= 1e-15 * (np.abs(vn).max(-1) + L)))
            active[idx[done]] = False
        n_left = int(active.sum())
        # the Abu-Khalaf–Lewis form at the solution: u = −ū·tanh((2R)⁻¹(b + Mu)/ū)
        u = self.squash(-(b + np.einsum("pij,pj->pi", M, self.squash(v))) / twoR)
        u = u.reshape(shape + (m,))
        if not return_info:
            return u
        res = np.abs(G(v, M, b)).max(-1) / scale    # only for the info (u does not read it)
        return u, {"iterations": it, "n_unconverged": n_left,
                   "max_residual": float(res.max()) if res.size else 0.0}

    # ------------------------------------------------------------ files
    def to_dict(self) -> dict:
        return {"shape": self.shape, "limit": self.limit.tolist()}

    @classmethod
    def from_dict(cls, d: dict, m: int | None = None) -> InputBound:
        lim = np.asarray(d["limit"], float)
        return cls.for_inputs(m if m is not None else lim.size, lim, d["shape"])

    def describe(self) -> str:
        if self.shape == "disk":
            return f"‖u‖ ≤ {self.limit[0]:g}"
        return "|u_i| ≤ " + ", ".join(f"{v:g}" for v in self.limit)


# ---------------------------------------------------------------------------------------------
# One point, m ≤ 2, on Python floats: the iteration of InputBound.minimize step by step (same
# start, directions, Armijo rule and stopping tests; tests/game/test_input_bound.py compares
# the two). Vectors are lists of m floats, matrices lists of rows; every sum is written out
# for m = 1 and m = 2 in the order of Python's ``sum`` (from 0, left to right), so a point
# gives the same floats as the generator form it replaced (about 2× less interpreter time).

def _pt_dot(a, c):
    if len(a) == 2:
        return 0.0 + a[0] * c[0] + a[1] * c[1]
    return 0.0 + a[0] * c[0]


def _pt_mv(M, x):
    if len(x) == 2:
        x0, x1 = x
        return [0.0 + M[0][0] * x0 + M[0][1] * x1, 0.0 + M[1][0] * x0 + M[1][1] * x1]
    return [0.0 + M[0][0] * x[0]]


def _pt_squash(bd, v):
    lim = bd._lim
    if bd.shape == "box":
        return [L * math.tanh(x / L) for x, L in zip(v, lim)]
    ub = lim[0]
    t = math.sqrt(_pt_dot(v, v)) / ub
    fac = 1.0 - t * t / 3.0 if t < 1e-8 else math.tanh(t) / t
    u = [x * fac for x in v]
    over = math.sqrt(_pt_dot(u, u)) / ub
    if over > 1.0:
        u = [x / over * (1.0 - 2.0 ** -52) for x in u]
    return u


def _pt_squash_jacobian(bd, v):
    m = len(v)
    if bd.shape == "box":
        d = [1.0 / math.cosh(min(abs(x / L), 350.0)) ** 2 for x, L in zip(v, bd._lim)]
        return [[d[0], 0.0], [0.0, d[1]]] if m == 2 else [[d[0]]]
    L = bd._lim[0]
    fac, c = _pt_disk_jacobian_coeffs(math.sqrt(_pt_dot(v, v)) / L)
    LL = L * L
    if m == 2:
        v0, v1 = v
        off = 0.0 + c * v0 * v1 / LL
        return [[fac + c * v0 * v0 / LL, off], [0.0 + c * v1 * v0 / LL, fac + c * v1 * v1 / LL]]
    return [[fac + c * v[0] * v[0] / LL]]


def _pt_disk_jacobian_coeffs(t):
    """``(fac, c)`` of the disk's ``∂squash/∂v = fac·I + c·vv'/ū²`` at ``t = ‖v‖/ū``."""
    t2 = t * t
    if t < 1e-3:
        return (1.0 - t2 / 3.0 + 2.0 * t2 * t2 / 15.0,
                -2.0 / 3.0 + 8.0 * t2 / 15.0 - 34.0 * t2 * t2 / 105.0)
    fac = math.tanh(t) / t
    return fac, (1.0 / math.cosh(min(t, 350.0)) ** 2 - fac) / (t * t)


def _pt_penalty_val(t, L2):
    """``2ū²(t·tanh t − ln cosh t)`` (``L2 = ū²``): the penalty of one saturating component."""
    lc = t - math.log(2.0) if t > 20.0 else math.log1p(2.0 * math.sinh(0.5 * t) ** 2)
    return 2.0 * L2 * (t * math.tanh(t) - lc)


def _pt_penalty_of_v(bd, v, twoR):
    if bd.shape == "box":
        w = [0.5 * r2 * _pt_penalty_val(abs(x) / L, L * L) for x, L, r2 in zip(v, bd._lim, twoR)]
        return 0.0 + w[0] + w[1] if len(w) == 2 else 0.0 + w[0]
    L = bd._lim[0]
    return 0.5 * twoR[0] * _pt_penalty_val(math.sqrt(_pt_dot(v, v)) / L, L * L)


def _pt_solve(A, b):
    if len(b) == 1:
        return [b[0] / A[0][0]]
    det = A[0][0] * A[1][1] - A[0][1] * A[1][0]
    return [(A[1][1] * b[0] - A[0][1] * b[1]) / det, (A[0][0] * b[1] - A[1][0] * b[0]) / det]


def _pt_add_diag(A, d):
    """``A + diag(d)``, the off-diagonal entries ``+ 0.0`` as the generator form had them."""
    if len(d) == 2:
        return [[A[0][0] + d[0], A[0][1] + 0.0], [A[1][0] + 0.0, A[1][1] + d[1]]]
    return [[A[0][0] + d[0]]]


def _pt_mm(A, S):
    """``A S`` for m ≤ 2."""
    if len(A) == 2:
        (a00, a01), (a10, a11) = A
        (s00, s01), (s10, s11) = S
        return [[0.0 + a00 * s00 + a01 * s10, 0.0 + a00 * s01 + a01 * s11],
                [0.0 + a10 * s00 + a11 * s10, 0.0 + a10 * s01 + a11 * s11]]
    return [[0.0 + A[0][0] * S[0][0]]]


def _pt_absmax(v):
    return max(abs(v[0]), abs(v[1])) if len(v) == 2 else abs(v[0])


def minimize_points(bounds, M, b, R, max_iter: int = 100) -> np.ndarray:
    """:meth:`InputBound.minimize` point by point with a bound of its own at each point:
    ``u[i] = argmin ½u'M[i]u + b[i]'u + W_i(u)`` over ``bounds[i]`` (at most 2 inputs), each
    point's floats those of ``bounds[i].minimize(M[i], b[i], R, pointwise=True)`` (what the
    rows of controllers that differ only in their bound need:
    :meth:`weakgrid.game.controller.GameController.rows_of`).

    Parameters
    ----------
    bounds : sequence of InputBound
        One per point.
    M : (p, m, m)
    b : (p, m)
    R : (m, m)

    Returns
    -------
    u : (p, m)
    """
    M = np.asarray(M, float)
    b = np.asarray(b, float)
    if b.ndim != 2 or b.shape[-1] > 2 or M.shape != b.shape + (b.shape[-1],) \
            or len(bounds) != b.shape[0]:
        raise ShapeError("M, b, bounds", (M.shape, b.shape, len(bounds)),
                         "(p, m, m), (p, m) and p bounds, m <= 2")
    out = _minimize_points(bounds, M, b, np.asarray(R, float), max_iter, False)
    return np.asarray([o[0] for o in out], float).reshape(b.shape)


def _minimize_points(bounds, M, b, R, max_iter, return_info):
    """:func:`_minimize_point` at each point ``i`` with ``bounds[i]`` (``M`` broadcast to the
    points of ``b``); a list of ``(u, info)``."""
    m = b.shape[-1]
    shape = b.shape[:-1]
    Ms = np.broadcast_to(M, shape + (m, m)).reshape(-1, m, m).tolist()
    twoR = [2.0 * r for r in np.diag(R).tolist()]
    return [_minimize_point(bd, Mk, bk, twoR, max_iter, return_info)
            for bd, Mk, bk in zip(bounds, Ms, b.reshape(-1, m).tolist())]


def _minimize_point(bd, M, b, twoR, max_iter, return_info=True):
    """:meth:`InputBound.minimize` at one point: ``(u, info)`` (lists and floats; ``info``
    None unless ``return_info``: its residual costs one more evaluation of G).

    Nothing is evaluated twice at the same point: F at the point a step accepted is the next
    step's ``f0`` (the same floats in, the same float out)."""
    if not hasattr(bd, "_lim"):
        object.__setattr__(bd, "_lim", [float(x) for x in bd.limit])
    L = max(bd._lim)
    scale = _pt_absmax(b) + max(abs(x) for row in M for x in row) * L + max(twoR) * L
    isfinite = math.isfinite

    def F(v):
        u = _pt_squash(bd, v)
        return 0.5 * _pt_dot(u, _pt_mv(M, u)) + _pt_dot(b, u) + _pt_penalty_of_v(bd, v, twoR)

    def G(v):
        Ms = _pt_mv(M, _pt_squash(bd, v))
        return [r2 * vi + bi + mi for r2, vi, bi, mi in zip(twoR, v, b, Ms)]

    v = _pt_solve(_pt_add_diag(M, twoR), [-x for x in b])
    it, active = 0, True
    f_v = None      # F(v), when the last step's backtracking evaluated it at the accepted v
    for it in range(1, max_iter + 1):
        if not active:
            break
        g = G(v)
        Sj = _pt_squash_jacobian(bd, v)
        d = [-x for x in _pt_solve(_pt_add_diag(_pt_mm(M, Sj), twoR), g)]
        finite = all(isfinite(x) for x in d)
        slope = _pt_dot(g, _pt_mv(Sj, d)) if finite else math.nan
        if not finite or not slope < 0:
            d = [-gi / r2 for gi, r2 in zip(g, twoR)]
            slope = _pt_dot(g, _pt_mv(Sj, d))
        alpha = 1.0
        f0 = F(v) if f_v is None else f_v
        tol_f = 1e-15 * (abs(f0) + 1.0)
        f_v = None
        for _ in range(60):
            vn = [vi + alpha * di for vi, di in zip(v, d)]
            fn = F(vn)
            if not fn > f0 + 1e-4 * alpha * min(slope, 0.0) + tol_f:
                f_v = fn        # F at the accepted point (vn is recomputed below, equal)
                break
            alpha = 0.5 * alpha
        vn = [vi + alpha * di for vi, di in zip(v, d)]
        dv = _pt_absmax([a - c for a, c in zip(vn, v)])
        v = vn
        if _pt_absmax(g) <= 1e-14 * scale or dv <= 1e-15 * (_pt_absmax(vn) + L):
            active = False
    Ms = _pt_mv(M, _pt_squash(bd, v))
    u = _pt_squash(bd, [-(bi + mi) / r2 for bi, mi, r2 in zip(b, Ms, twoR)])
    if not return_info:
        return u, None
    res = _pt_absmax(G(v)) / scale
    return u, {"iterations": it, "n_unconverged": int(active), "max_residual": float(res)}
