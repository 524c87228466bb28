"""Contractions whose floats at a row do not depend on how many rows are computed together.

A policy evaluated for a whole batch of states in one call (a batched simulation's members
that share a trained law) must give each row the floats of the same call on that row alone,
or a closed loop amplifies the last-bit differences (one ulp at 0.3 s grows to 1e-8 rad in a
machine's angle over 6 s). NumPy's matrix products and ``einsum`` do not promise that: they
take other BLAS and SIMD paths (fused multiply-adds, other summation orders) by shape, and
round an ``(n, 2)`` call otherwise than a ``(2,)`` one in a third to a half of the outputs.

These functions contract with elementwise multiplications and additions only, term by term in
a fixed order (index 0 first, ``np.add.accumulate``): IEEE arithmetic rounds each of them the
same way whatever the array's shape, so row ``i`` of a call equals the call on row ``i``. They
suit the small dimensions of a controller (a few states and inputs, tens of basis terms: the
partial sums they keep on the way are that small). ``np.linalg.solve`` already solves each
matrix of a stack on its own (one LAPACK call each) and needs no counterpart here; a value
function's derivatives sum their basis terms the same way
(:meth:`weakgrid.game.bases.PolynomialBasis.weighted_derivatives`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["matvec", "matmul", "vecmat", "sum_in_order"]


def sum_in_order(terms, axis: int):
    """The sum of ``terms`` over ``axis``, term by term from index 0: ``np.add.accumulate``
    adds in sequence (each partial sum from the previous one), unlike ``np.sum``'s pairwise
    and SIMD orders."""
    return np.take(np.add.accumulate(terms, axis=axis), -1, axis=axis)


def matvec(A, x):
    """``A x`` for ``A`` (..., i, j) and ``x`` (..., j): (..., i), summed from ``j = 0``."""
    A = np.asarray(A, float)
    x = np.asarray(x, float)
    return sum_in_order(A * x[..., None, :], -1)


def vecmat(x, A):
    """``x' A`` for ``x`` (..., i) and ``A`` (..., i, j): (..., j), summed from ``i = 0``."""
    A = np.asarray(A, float)
    x = np.asarray(x, float)
    return sum_in_order(x[..., :, None] * A, -2)


def matmul(A, B):
    """``A B`` for ``A`` (..., i, k) and ``B`` (..., k, j): (..., i, j), summed from ``k = 0``."""
    A = np.asarray(A, float)
    B = np.asarray(B, float)
    return sum_in_order(A[..., :, :, None] * B[..., None, :, :], -2)
