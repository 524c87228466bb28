"""Polynomial bases ("neural networks" of the paper) with analytic derivatives.

A basis is a list of monomials ``σ_l(x) = Π_i x_i^{E[l, i]}`` given by an integer
exponent table ``E`` of shape ``(L, n)``. Values, gradients and Hessians are
evaluated in one vectorized pass over a batch of states: each derivative of a
monomial is a monomial times a constant, so every order is a gather-and-product
over a table of powers.

The cost approximation is ``J(x) = W'σ(x)`` (paper, Section IV-B).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field
from math import factorial

import numpy as np

from .errors import ParameterError, ShapeError
from .rowwise import sum_in_order

__all__ = [
    "PolynomialBasis",
    "paper_basis",
    "even_monomials",
    "full_monomials",
    "from_generator",
    "quadratic_basis",
]


def _falling(e: np.ndarray, k: int) -> np.ndarray:
    """Falling factorial e·(e−1)···(e−k+1) (zero where e < k)."""
    out = np.ones_like(e)
    for j in range(k):
        out = out * (e - j)
    return np.where(e >= k, out, 0)


@dataclass(frozen=True, eq=False)
class PolynomialBasis:
    """A set of monomials in ``n`` states.

    Parameters
    ----------
    exponents : array_like of int, shape (L, n)
        Row ``l`` holds the exponents of monomial ``l``.
    name : str
        A short description recorded in controller files.
    """

    exponents: np.ndarray
    name: str = "custom"
    _tables: tuple = field(init=False, repr=False, compare=False)

    def __post_init__(self):
        E = np.asarray(self.exponents)
        if E.ndim != 2 or E.shape[0] == 0 or E.shape[1] == 0:
            raise ShapeError("exponents", E.shape, "(L, n) with L ≥ 1 and n ≥ 1")
        if not np.issubdtype(E.dtype, np.integer):
            if not np.all(np.equal(np.mod(E, 1), 0)):
                raise ParameterError("exponents", E.tolist(), "exponents must be integers")
            E = E.astype(int)
        if np.any(E < 0):
            raise ParameterError("exponents", E.tolist(), "exponents must be ≥ 0")
        if np.any(E.sum(axis=1) == 0):
            raise ParameterError(
                "exponents", E.tolist(),
                "drop the constant monomial: it gives a zero column in the least-squares fit "
                "(J(x+) − J(x) does not see a constant)",
            )
        if len({tuple(r) for r in E.tolist()}) != E.shape[0]:
            raise ParameterError("exponents", E.tolist(), "monomials must be distinct")
        E = np.array(E, dtype=np.int64)
        E.setflags(write=False)
        object.__setattr__(self, "exponents", E)
        object.__setattr__(self, "_tables", self._build_tables(E))
        object.__setattr__(self, "_states", np.arange(E.shape[1]))
        n = E.shape[1]
        planes = np.empty((n, n), dtype=np.int64)
        for m, (j, k) in enumerate(self._tables[2]):
            planes[j, k] = planes[k, j] = 1 + n + m
        object.__setattr__(self, "_hessian_planes", planes)

    # ------------------------------------------------------------------ sizes
    @property
    def n_states(self) -> int:
        return self.exponents.shape[1]

    @property
    def size(self) -> int:
        return self.exponents.shape[0]

    def __len__(self) -> int:
        return self.size

    @property
    def degree(self) -> int:
        return self._tables[3]

    # ------------------------------------------------------------ evaluation
    @staticmethod
    def _build_tables(E):
        L, n = E.shape
        # multi-indices of derivatives: value, first (n), second (j ≤ k)
        alphas = [np.zeros(n, int)]
        for j in range(n):
            a = np.zeros(n, int)
            a[j] = 1
            alphas.append(a)
        pairs = [(j, k) for j in range(n) for k in range(j, n)]
        for j, k in pairs:
            a = np.zeros(n, int)
            a[j] += 1
            a[k] += 1
            alphas.append(a)
        exps = np.empty((len(alphas), L, n), dtype=np.int64)
        coef = np.empty((len(alphas), L))
        for m, a in enumerate(alphas):
            c = np.ones(L)
            for i in range(n):
                c = c * _falling(E[:, i], int(a[i]))
            coef[m] = c
            exps[m] = np.maximum(E - a, 0)
        return exps, coef, pairs, int(E.sum(axis=1).max())

    def _check_x(self, x) -> tuple[np.ndarray, tuple]:
        x = np.asarray(x, dtype=float)
        if x.ndim == 0 or x.shape[-1] != self.n_states:
            raise ShapeError("x", x.shape, f"(..., {self.n_states})")
        return x.reshape(-1, self.n_states), x.shape[:-1]

    def planes(self, xT: np.ndarray, order: int = 2) -> np.ndarray:
        """Derivatives of every monomial at the points of ``xT`` (n, p), as planes.

        Returns an array (K, L, p): plane 0 holds the values, planes ``1 … n`` the
        first derivatives, then the second derivatives ∂²/∂x_j∂x_k for ``j ≤ k`` in
        row-major order (K = 1, 1 + n or 1 + n + n(n+1)/2 for order 0, 1, 2).
        """
        exps, coef, _, dmax = self._tables
        n = self.n_states
        k = {0: 1, 1: 1 + n, 2: len(coef)}[order]
        # the powers x_i^d, d = 0 … degree, of every state at once: a cumulative product,
        # pw[d] = pw[d − 1]·x (the same products as one multiplication per power)
        base = np.empty((dmax + 1, n, xT.shape[1]))
        base[0] = 1.0
        base[1:] = xT
        pw = np.multiply.accumulate(base, axis=0)
        g = pw[exps[:k], self._states]  # (k, L, n, p): each monomial's factors
        out = g[:, :, 0]
        for i in range(1, n):
            out = out * g[:, :, i]
        return out * coef[:k, :, None]

    def evaluate(self, x, order: int = 2):
        """Values, gradients and Hessians of every monomial at a batch of states.

        Parameters
        ----------
        x : array_like, shape (..., n)
        order : {0, 1, 2}

        Returns
        -------
        phi : ndarray, shape (..., L)
        grad : ndarray, shape (..., L, n)   (if order ≥ 1)
        hess : ndarray, shape (..., L, n, n)   (if order = 2)
        """
        x2, batch = self._check_x(x)
        n, L = self.n_states, self.size
        mono = self.planes(x2.T, order)  # (k, L, p)
        phi = mono[0].T.reshape(*batch, L)
        if order == 0:
            return phi
        grad = mono[1 : 1 + n].transpose(2, 1, 0).reshape(*batch, L, n)
        if order == 1:
            return phi, grad
        hess = mono[self._hessian_planes]  # (n, n, L, p): plane of ∂²/∂x_j∂x_k at [j, k]
        return phi, grad, hess.transpose(3, 2, 0, 1).reshape(*batch, L, n, n)

    def weighted_derivatives(self, x, weights):
        """``∇J`` (..., n) and ``∇²J`` (..., n, n) of ``J = weights'σ`` at states ``x``
        (..., n), the sum over the monomials term by term (:mod:`weakgrid.game.rowwise`):
        a state's floats do not depend on the states evaluated with it. ``weights``: (L,), or
        (..., L) with a row of weights per state (the same floats as each row's own call)."""
        x2, batch = self._check_x(x)
        n = self.n_states
        w = np.asarray(weights, float)
        mono = self.planes(x2.T, 2)[1:]     # (K − 1, L, p): first, then second derivatives
        if w.ndim > 1:                      # a row of weights per state: (L, p)
            if w.shape[:-1] != tuple(batch) or w.shape[-1] != mono.shape[1]:
                raise ShapeError("weights", w.shape, f"({mono.shape[1]},) or "
                                 f"{tuple(batch) + (mono.shape[1],)}")
            acc = sum_in_order(mono * w.reshape(-1, w.shape[-1]).T, 1)
        else:
            acc = sum_in_order(mono * w[:, None], 1)
        grad = acc[:n].T.reshape(*batch, n)
        hess = acc[self._hessian_planes - 1].transpose(2, 0, 1).reshape(*batch, n, n)
        return grad, hess

    def second_derivative_pairs(self):
        """The (j, k), j ≤ k, of the second-derivative planes of :meth:`planes`."""
        return list(self._tables[2])

    def __call__(self, x) -> np.ndarray:
        return self.evaluate(x, order=0)

    def gradient(self, x) -> np.ndarray:
        return self.evaluate(x, order=1)[1]

    def hessian(self, x) -> np.ndarray:
        return self.evaluate(x, order=2)[2]

    # ------------------------------------------------------------- display/io
    def labels(self, state_names=None) -> list[str]:
        names = state_names or [f"x{i + 1}" for i in range(self.n_states)]
        out = []
        for row in self.exponents:
            parts = [f"{nm}^{e}" if e > 1 else nm for nm, e in zip(names, row) if e > 0]
            out.append("·".join(parts))
        return out

    def to_dict(self) -> dict:
        return {"name": self.name, "exponents": self.exponents.tolist()}

    @classmethod
    def from_dict(cls, d: dict) -> "PolynomialBasis":
        return cls(np.asarray(d["exponents"], dtype=np.int64), name=d.get("name", "custom"))

    def __eq__(self, other):
        return isinstance(other, PolynomialBasis) and np.array_equal(
            self.exponents, other.exponents
        )

    def __hash__(self):
        return hash(self.exponents.tobytes())


def _sort_key(e):
    """Order of the paper: descending exponent of x1, then of x2, …"""
    return tuple(-v for v in e)


def from_generator(n_states: int, powers=(2, 4), coefficients=None, name=None):
    """The monomials of a generator polynomial ``Σ_k (c·x)^k``, k in ``powers``.

    The paper's basis is the expansion of ``(ϕ̂ + υ)² + (ϕ̂ + υ)⁴`` (Section V): 8
    monomials listed by descending exponent of the first state, then the second.

    Parameters
    ----------
    n_states : int
    powers : sequence of int
        The powers ``k`` of the linear form.
    coefficients : array_like, shape (n,), optional
        The linear form ``c`` (default all ones). Monomials whose expansion
        coefficient vanishes are dropped.
    """
    if n_states < 1:
        raise ParameterError("n_states", n_states, "need at least one state")
    c = np.ones(n_states) if coefficients is None else np.asarray(coefficients, float)
    if c.shape != (n_states,):
        raise ShapeError("coefficients", c.shape, f"({n_states},)")
    powers = [int(k) for k in powers]
    if not powers or any(k < 1 for k in powers):
        raise ParameterError("powers", powers, "give powers ≥ 1")
    rows = set()
    for k in powers:
        for e in _compositions(k, n_states):
            mult = factorial(k) / np.prod([factorial(v) for v in e])
            if mult * np.prod(c ** np.array(e)) != 0.0:
                rows.add(e)
    E = np.array(sorted(rows, key=_sort_key), dtype=np.int64)
    label = name or "generator " + " + ".join(f"(c·x)^{k}" for k in powers)
    return PolynomialBasis(E, name=label)


def _compositions(k: int, n: int):
    """All exponent tuples of n non-negative integers summing to k."""
    for cut in itertools.combinations(range(k + n - 1), n - 1):
        prev, out = -1, []
        for c in cut:
            out.append(c - prev - 1)
            prev = c
        out.append(k + n - 1 - prev - 1)
        yield tuple(out)


def paper_basis() -> PolynomialBasis:
    """The paper's 8-term basis, ``[ϕ̂⁴, ϕ̂³υ, ϕ̂²υ², ϕ̂², ϕ̂υ³, ϕ̂υ, υ⁴, υ²]`` (docs/theory.md, (25))."""
    return from_generator(2, powers=(2, 4), name="paper: (x1+x2)^2 + (x1+x2)^4")


def even_monomials(n_states: int, degree: int) -> PolynomialBasis:
    """All monomials of even total degree 2, 4, …, ``degree`` in ``n_states`` states."""
    if degree < 2 or degree % 2:
        raise ParameterError("degree", degree, "use an even degree ≥ 2")
    if n_states < 1:
        raise ParameterError("n_states", n_states, "need at least one state")
    rows = [e for d in range(2, degree + 1, 2) for e in _compositions(d, n_states)]
    E = np.array(sorted(rows, key=lambda e: (sum(e), _sort_key(e))), dtype=np.int64)
    return PolynomialBasis(E, name=f"even monomials up to degree {degree}")


def full_monomials(n_states: int, degree: int) -> PolynomialBasis:
    """All monomials of total degree 2, 3, …, ``degree`` in ``n_states`` states.

    Unlike :func:`even_monomials` (the paper's basis for ``degree = 4``) it has the odd
    degrees too: the design model (10) is not symmetric about its equilibrium
    (``sin(ϕ̂ + ϕs0)``), so neither is the value. With an input bound the paper's basis puts a
    ridge into J at the edge of Ω, which the degree-3 terms remove (docs/beyond.md, input
    bound: measured there). No degree-1 term: J has its minimum 0 at the origin.
    """
    if int(degree) != degree or degree < 2:
        raise ParameterError("degree", degree, "use a whole degree ≥ 2")
    if n_states < 1:
        raise ParameterError("n_states", n_states, "need at least one state")
    rows = [e for d in range(2, int(degree) + 1) for e in _compositions(d, n_states)]
    E = np.array(sorted(rows, key=lambda e: (sum(e), _sort_key(e))), dtype=np.int64)
    return PolynomialBasis(E, name=f"all monomials of degree 2..{int(degree)}")


def quadratic_basis(n_states: int) -> PolynomialBasis:
    """The ``n(n+1)/2`` quadratic monomials: ``J = x'Sx`` exactly (LQ game)."""
    return even_monomials(n_states, 2)
