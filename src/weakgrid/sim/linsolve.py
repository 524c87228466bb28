"""Linear solvers of the integrator: the chord iteration matrix and the algebraic block.

The integrator needs two kinds of factorized matrices built from the Jacobian
``J = dF/dz`` (device part by coloured differences, network part ``Yr``):

* the iteration matrix of the trapezoidal step (``h`` the step)::

      M = [I - h/2 J_xz ; J_yz]     (rows of states held at a limit: identity rows)

* the algebraic block ``J_yy`` (network re-solve with the states fixed).

Two backends implement :class:`LinearSolver`:

:class:`DenseSolver`
    LAPACK ``getrf``/``getrs`` on dense arrays. Fastest for small systems
    (a few hundred variables), where sparse bookkeeping costs more than it saves.
:class:`SparseSolver`
    The full pattern (device pattern ∪ network pattern with every branch ∪ the
    diagonal) is fixed once, so matrices are assembled in O(nnz) with one
    ``bincount`` into CSC arrays. The LU is SciPy's **SuperLU** (``lu="superlu"``),
    with the COLAMD column ordering of the first factorization reused (SciPy's
    SuperLU has no separate symbolic step), or **KLU** (``lu="klu"``: SuiteSparse
    through ``kvxopt``, which ANDES also uses; the extra ``weakgrid[klu]``,
    GPL-3.0-or-later): the symbolic analysis (BTF + AMD ordering) is done once per
    matrix kind and reused by every numeric refactorization. ``lu="auto"`` (the
    default) takes KLU when ``kvxopt`` is installed and SuperLU otherwise
    (``benchmarks/bench_lu.py`` measures the difference).

:func:`make_solver` chooses: ``"auto"`` takes dense up to
:data:`DENSE_MAX_VARS` variables and sparse above (the crossover measured by
``benchmarks/bench_scale.py``); ``"dense"`` and ``"sparse"`` force a backend.
"""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla
from scipy.linalg.lapack import dgetrs

from .errors import DataError

#: largest DAE size (states + 2 × buses) solved densely by ``linear_solver="auto"``
DENSE_MAX_VARS = 100


class DenseFactor:
    """A dense LU factorization (LAPACK)."""

    def __init__(self, M):
        self.lu = sla.lu_factor(M, check_finite=False)

    def solve(self, b):
        """Solve ``M x = b`` (LAPACK ``getrs`` without SciPy's per-call checks)."""
        x, _ = dgetrs(self.lu[0], self.lu[1], b)
        return x


class SingularFactor:
    """Stands for a factorization that failed (singular matrix): every solve gives NaN, which
    the integrator treats as a failed Newton iteration (fresh Jacobian, then a shorter step)."""

    def __init__(self, n):
        self.n = n

    def solve(self, b):
        return np.full(np.shape(b), np.nan)


class LinearSolver:
    """Interface: holds the current device Jacobian and factorizes the matrices built from it.

    Parameters
    ----------
    system : System
        A set-up system (its pattern, sizes and current network matrix ``Yr_coo`` are read).
    """

    name = "base"

    def __init__(self, system):
        self.sys = system
        self.nx, self.N = system.nx, system.N
        self.dev = None

    def set_device_jacobian(self, vals):
        """Store the device Jacobian values (on ``system._pr, system._pc``)."""
        self.dev = vals

    def factor_iteration(self, h, frozen_rows):
        """Factorize ``M`` for step ``h``; ``frozen_rows`` are replaced by identity rows."""
        raise NotImplementedError

    def factor_algebraic(self):
        """Factorize the algebraic block ``J_yy``."""
        raise NotImplementedError


class DenseSolver(LinearSolver):
    """Dense matrices and LAPACK LU (small systems)."""

    name = "dense"

    def _full(self):
        s = self.sys
        J = np.zeros((self.N, self.N))
        J[s._pr, s._pc] = self.dev
        nx = self.nx
        if s.Yr_dense is not None:
            J[nx:, nx:] += s.Yr_dense
        else:
            r, c, v = s.Yr_coo
            np.add.at(J, (r + nx, c + nx), v)
        return J

    def factor_iteration(self, h, frozen_rows):
        nx = self.nx
        M = self._full()
        M[:nx] *= -0.5 * h
        M[:nx, :nx] += np.eye(nx)
        if frozen_rows is not None and len(frozen_rows):
            M[frozen_rows] = 0.0
            M[frozen_rows, frozen_rows] = 1.0
        return DenseFactor(M)

    def factor_algebraic(self):
        nx = self.nx
        return DenseFactor(self._full()[nx:, nx:])


class _Pattern:
    """A fixed COO → CSC map: ``data = bincount(inv, coo_values)`` in O(nnz)."""

    def __init__(self, rows, cols, n):
        key = cols.astype(np.int64) * n + rows
        uniq, self.inv = np.unique(key, return_inverse=True)
        self.nnz = len(uniq)
        self.n = n
        self.indices = (uniq % n).astype(np.int32)
        colidx = uniq // n
        self.colidx = colidx.astype(np.int32)
        self.indptr = np.zeros(n + 1, dtype=np.int32)
        np.cumsum(np.bincount(colidx, minlength=n), out=self.indptr[1:])

    def data(self, vals):
        return np.bincount(self.inv, weights=vals, minlength=self.nnz)

    def csc(self, vals):
        import scipy.sparse as sp

        return sp.csc_matrix((self.data(vals), self.indices, self.indptr), shape=(self.n, self.n))


class _KLU:
    """KLU through kvxopt: symbolic analysis once, numeric refactorization after."""

    def __init__(self, pat):
        from kvxopt import matrix, spmatrix

        self._matrix, self._spmatrix = matrix, spmatrix
        self.pat = pat
        self._I = matrix(pat.indices.astype(np.int64))
        self._J = matrix(pat.colidx.astype(np.int64))
        self.symbolic = None

    def factor(self, data):
        from kvxopt import klu

        A = self._spmatrix(self._matrix(data), self._I, self._J, (self.pat.n, self.pat.n))
        if self.symbolic is None:
            self.symbolic = klu.symbolic(A)
        try:
            return _KLUFactor(A, self.symbolic, klu.numeric(A, self.symbolic), self._matrix)
        except ArithmeticError:   # singular
            return SingularFactor(self.pat.n)


class _KLUFactor:
    def __init__(self, A, F, Nf, matrix):
        self.A, self.F, self.Nf, self._matrix = A, F, Nf, matrix

    def solve(self, b):
        from kvxopt import klu

        x = self._matrix(np.asarray(b, dtype=float))
        klu.solve(self.A, self.F, self.Nf, x)
        return np.frombuffer(x, dtype=float).copy()


class _SuperLU:
    """SciPy SuperLU with the COLAMD column ordering of the first factorization reused."""

    def __init__(self, pat):
        self.pat = pat
        self.perm = None

    def factor(self, data):
        import scipy.sparse as sp
        from scipy.sparse.linalg import splu

        p = self.pat
        A = sp.csc_matrix((data, p.indices, p.indptr), shape=(p.n, p.n))
        try:
            return self._factor(A, splu)
        except RuntimeError:      # "Factor is exactly singular"
            return SingularFactor(p.n)

    def _factor(self, A, splu):
        if self.perm is None:
            lu = splu(A, permc_spec="COLAMD")
            self.perm = lu.perm_c
            self.inv = np.argsort(self.perm)
            # the first factorization solves A x = b directly
            return _SuperLUFactor(lu, None)
        # A Pc = A[:, inv]; solving (A Pc) y = b gives x = Pc y = y[perm]
        return _SuperLUFactor(splu(A[:, self.inv], permc_spec="NATURAL"), self.perm)


class _SuperLUFactor:
    def __init__(self, lu, perm):
        self.lu, self.perm = lu, perm

    def solve(self, b):
        y = self.lu.solve(b)
        return y if self.perm is None else y[self.perm]


class SparseSolver(LinearSolver):
    """Sparse matrices on a pattern fixed at construction, KLU or SuperLU (:func:`sparse_lu`)."""

    name = "sparse"

    def __init__(self, system, lu="auto"):
        super().__init__(system)
        lu = sparse_lu(lu)
        #: the sparse LU library in use, ``"klu"`` or ``"superlu"``
        self.lu = lu
        N, nx = self.N, self.nx
        s = system
        yr, yc, _ = s.Yr_coo
        self._nnet = len(yr)
        d = np.arange(N)
        rows = np.concatenate([s._pr, yr + nx, d])
        cols = np.concatenate([s._pc, yc + nx, d])
        self._rows = rows
        self._ndev = len(s._pr)
        self.it_pat = _Pattern(rows, cols, N)
        # the algebraic block: entries in rows and columns >= nx, shifted
        alg = (rows >= nx) & (cols >= nx)
        self._alg_sel = np.nonzero(alg)[0]
        self.alg_pat = _Pattern(rows[alg] - nx, cols[alg] - nx, N - nx)
        self._state_row = rows < nx
        self._diag_state = np.concatenate([np.zeros(len(rows) - N), (d < nx).astype(float)])
        backend = _KLU if lu == "klu" else _SuperLU
        self._it_lu = backend(self.it_pat)
        self._alg_lu = backend(self.alg_pat)

    def _coo_values(self):
        s = self.sys
        r, _, v = s.Yr_coo
        if len(r) != self._nnet:
            raise RuntimeError("the network pattern changed; the sparse solver must be rebuilt")
        return np.concatenate([self.dev, v, np.zeros(self.N)])

    def factor_iteration(self, h, frozen_rows):
        vals = self._coo_values()
        vals[self._state_row] *= -0.5 * h
        vals += self._diag_state
        if frozen_rows is not None and len(frozen_rows):
            fr = np.zeros(self.N, dtype=bool)
            fr[frozen_rows] = True
            vals[fr[self._rows]] = 0.0
            vals[len(vals) - self.N + np.asarray(frozen_rows)] = 1.0
        return self._it_lu.factor(self.it_pat.data(vals))

    def factor_algebraic(self):
        vals = self._coo_values()[self._alg_sel]
        return self._alg_lu.factor(self.alg_pat.data(vals))


def sparse_lu(lu: str = "auto") -> str:
    """The sparse LU library for ``lu``: ``"klu"`` or ``"superlu"``.

    ``"auto"`` is KLU when ``kvxopt`` is installed (the extra ``weakgrid[klu]``, or with
    ANDES), else SciPy's SuperLU. An explicit ``"klu"`` without ``kvxopt`` is an error
    naming the extra, not a silent switch to SuperLU.

    Raises
    ------
    DataError
        ``lu`` is not one of ``"auto"``, ``"klu"``, ``"superlu"``, or ``"klu"`` without
        ``kvxopt``.
    """
    if lu not in ("auto", "klu", "superlu"):
        raise DataError("linear solver", "lu", lu, "use 'auto', 'klu' or 'superlu'")
    if lu == "superlu":
        return lu
    try:
        import kvxopt  # noqa: F401
    except ImportError:
        if lu == "klu":
            raise DataError("linear solver", "lu", lu,
                            "KLU needs kvxopt: pip install 'weakgrid[klu]' (GPL-3.0-or-later), "
                            "or use 'superlu' or 'auto'") from None
        return "superlu"
    return "klu"


def make_solver(system, kind: str = "auto", lu: str = "auto") -> LinearSolver:
    """The linear solver for ``system``.

    Parameters
    ----------
    kind : {"auto", "dense", "sparse"}
        ``"auto"``: dense up to :data:`DENSE_MAX_VARS` DAE variables, sparse above.
    lu : {"auto", "klu", "superlu"}
        Sparse LU library (sparse backend only; :func:`sparse_lu`).
    """
    if kind == "auto":
        kind = "dense" if system.N <= DENSE_MAX_VARS else "sparse"
    if kind == "dense":
        return DenseSolver(system)
    if kind == "sparse":
        return SparseSolver(system, lu=lu)
    raise DataError("simulation", "linear_solver", kind, "use 'auto', 'dense' or 'sparse'")
