"""Term-by-term contractions (weakgrid.game.rowwise): the products they stand for to rounding,
and a row's floats the same whatever rows are computed with it (NumPy's ``@`` and ``einsum``
are not: they round an (n, 2) call otherwise than a (2,) one)."""

import numpy as np
import pytest

from weakgrid.game.bases import paper_basis
from weakgrid.game.rowwise import matmul, matvec, vecmat


def _rows_alone(f, *arrays):
    return np.stack([f(*(a[i] for a in arrays)) for i in range(arrays[0].shape[0])])


@pytest.mark.parametrize("n", [2, 3, 17, 64])
def test_contractions_equal_the_products_and_each_row_alone(n):
    rng = np.random.default_rng(n)
    A = rng.normal(size=(n, 3, 4))
    B = rng.normal(size=(n, 4, 2))
    x = rng.normal(size=(n, 4))
    y = rng.normal(size=(n, 3))
    basis = paper_basis()
    states = rng.uniform(-1, 1, (n, 2))
    w = rng.normal(size=basis.size)
    cases = [
        (matvec, (A, x), np.einsum("pij,pj->pi", A, x)),
        (vecmat, (y, A), np.einsum("pi,pij->pj", y, A)),
        (matmul, (A, B), A @ B),
        (lambda s: basis.weighted_derivatives(s, w)[0], (states,),
         np.einsum("pln,l->pn", basis.gradient(states), w)),
        (lambda s: basis.weighted_derivatives(s, w)[1], (states,),
         np.einsum("plij,l->pij", basis.hessian(states), w)),
    ]
    for f, args, exact in cases:
        got = f(*args)
        np.testing.assert_allclose(got, exact, rtol=1e-13, atol=1e-13)
        assert np.array_equal(got, _rows_alone(f, *args))    # bit for bit
