"""Polynomial bases: analytic derivatives against finite differences, orders, sizes."""

from math import comb

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from weakgrid.game import (
    ParameterError, PolynomialBasis, ShapeError, even_monomials, from_generator, paper_basis,
)


@st.composite
def basis_and_points(draw):
    n = draw(st.integers(1, 4))
    L = draw(st.integers(1, 6))
    rows = draw(st.lists(st.tuples(*[st.integers(0, 4)] * n).filter(lambda r: sum(r) > 0),
                         min_size=1, max_size=L, unique=True))
    x = draw(arrays(float, (5, n), elements=st.floats(-2, 2, allow_nan=False)))
    return PolynomialBasis(np.array(rows)), x


@given(basis_and_points())
def test_gradient_and_hessian_match_finite_differences(bp):
    basis, x = bp
    phi, grad, hess = basis.evaluate(x)
    n = basis.n_states
    h = 1e-5
    for j in range(n):
        e = np.zeros(n)
        e[j] = h
        fd_grad = (basis(x + e) - basis(x - e)) / (2 * h)
        np.testing.assert_allclose(grad[..., j], fd_grad, rtol=1e-6, atol=1e-6)
        fd_hess = (basis.gradient(x + e) - basis.gradient(x - e)) / (2 * h)
        np.testing.assert_allclose(hess[..., j, :], fd_hess, rtol=1e-6, atol=1e-6)
    np.testing.assert_allclose(hess, np.swapaxes(hess, -1, -2))


@given(basis_and_points())
def test_values_are_the_monomials(bp):
    basis, x = bp
    expected = np.prod(x[:, None, :] ** basis.exponents[None], axis=-1)
    np.testing.assert_allclose(basis(x), expected, rtol=1e-12, atol=1e-12)


def test_paper_basis_order():
    # docs/theory.md, (25): [ϕ̂⁴, ϕ̂³υ, ϕ̂²υ², ϕ̂², ϕ̂υ³, ϕ̂υ, υ⁴, υ²]
    assert paper_basis().exponents.tolist() == [
        [4, 0], [3, 1], [2, 2], [2, 0], [1, 3], [1, 1], [0, 4], [0, 2]]


@pytest.mark.parametrize("n,d", [(1, 2), (2, 4), (3, 4), (4, 6)])
def test_even_monomials_count(n, d):
    b = even_monomials(n, d)
    assert b.size == sum(comb(k + n - 1, n - 1) for k in range(2, d + 1, 2))
    assert np.all(b.exponents.sum(1) % 2 == 0)


def test_generator_drops_vanishing_terms():
    b = from_generator(2, powers=(2,), coefficients=[1.0, 0.0])
    assert b.exponents.tolist() == [[2, 0]]
    assert from_generator(3, powers=(2,)).size == 6


def test_batch_shapes():
    b = paper_basis()
    x = np.zeros((3, 4, 2))
    phi, g, h = b.evaluate(x)
    assert phi.shape == (3, 4, 8) and g.shape == (3, 4, 8, 2) and h.shape == (3, 4, 8, 2, 2)
    assert b(np.zeros(2)).shape == (8,)


def test_bad_bases_are_refused():
    with pytest.raises(ParameterError, match="constant"):
        PolynomialBasis(np.array([[0, 0], [2, 0]]))
    with pytest.raises(ParameterError, match="≥ 0"):
        PolynomialBasis(np.array([[-1, 2]]))
    with pytest.raises(ParameterError, match="distinct"):
        PolynomialBasis(np.array([[2, 0], [2, 0]]))
    with pytest.raises(ShapeError):
        paper_basis()(np.zeros(3))
    with pytest.raises(ParameterError):
        even_monomials(2, 3)


@given(basis_and_points())
def test_a_batch_row_is_its_point_alone_bit_for_bit(bp):
    # the batch simulator evaluates many members' policies in one call and promises each
    # member its run alone: every row of a batched evaluation must be the one-point evaluation
    basis, x = bp
    rows = basis.evaluate(x)
    for i, xi in enumerate(x):
        for batched, alone in zip(rows, basis.evaluate(xi)):
            assert np.array_equal(batched[i], alone)


@given(basis_and_points())
def test_derivatives_are_the_monomials_derivatives(bp):
    # each derivative of x^e is a falling-factorial constant times a monomial (analytic, to
    # round-off): ∂/∂x_j x^e = e_j x^(e - 1_j), ∂²/∂x_j∂x_k = e_j (e_k - δ_jk) x^(e - 1_j - 1_k)
    basis, x = bp
    _, grad, hess = basis.evaluate(x)
    E, n = basis.exponents, basis.n_states
    for j in range(n):
        d = E.copy()
        d[:, j] -= 1
        want = E[:, j] * np.prod(x[:, None, :] ** np.maximum(d, 0)[None], axis=-1)
        np.testing.assert_allclose(grad[..., j], want, rtol=1e-12, atol=1e-12)
        for k in range(n):
            dd = d.copy()
            dd[:, k] -= 1
            c = E[:, j] * (E[:, k] - (j == k))
            want2 = np.where(dd.min(axis=1) >= 0, c, 0) * np.prod(
                x[:, None, :] ** np.maximum(dd, 0)[None], axis=-1)
            np.testing.assert_allclose(hess[..., j, k], want2, rtol=1e-12, atol=1e-12)
