"""Grid dynamic programming: oracles from the LQ game and invariants."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from weakgrid.game import GameCost, LinearSystem, ParameterError, solve_game_riccati
from weakgrid.game.dynamic_programming import (
    DPSettings, _interp_weights, lifted_game_riccati, solve_game_dp,
)

A = np.array([[1.0, 0.1], [-0.3, 0.97]])
B = np.array([[0.0], [0.1]])
E = np.array([[0.02], [0.08]])
Q, R, P, GAMMA = np.eye(2), np.eye(1), np.eye(1), 2.0


def linear():
    s = LinearSystem(A, B, E)
    return s, GameCost.for_system(s, Q, R, P, GAMMA)


def inside_error(dp, S):
    X = dp.points
    X = X[np.all(np.abs(X) <= 1 + 1e-12, axis=1)]
    Vr = np.einsum("pi,ij,pj->p", X, S, X)
    return np.abs(dp.value(X) - Vr).max() / Vr.max()


def test_dp_equals_game_riccati_with_a_wrong_prior():
    """The residual has to be learnt: the prior is half the true value matrix."""
    s, c = linear()
    S = solve_game_riccati(A, B, E, Q, R, P, GAMMA).S
    dp = solve_game_dp(s, c, [-1, -1], [1, 1],
                       DPSettings(n_points=(41, 41), prior=0.5 * S, margin=1.0))
    assert dp.converged
    assert inside_error(dp, S) <= 0.01
    assert np.abs(dp.residual).max() > 0.1 * np.abs(S).max()  # it did learn something
    # the grid policies are the game-Riccati saddle gains
    sol = solve_game_riccati(A, B, E, Q, R, P, GAMMA)
    X = np.array([[0.3, -0.2], [-0.5, 0.4]])
    u, w = dp.saddle_point(X)
    np.testing.assert_allclose(u, -X @ sol.K.T, atol=0.02 * np.abs(X @ sol.K.T).max())
    np.testing.assert_allclose(w, -X @ sol.L.T, atol=0.02 * np.abs(X @ sol.L.T).max())


def test_dp_with_riccati_prior_is_a_fixed_point():
    s, c = linear()
    S = solve_game_riccati(A, B, E, Q, R, P, GAMMA).S
    dp = solve_game_dp(s, c, [-1, -1], [1, 1], DPSettings(n_points=(21, 21)))
    assert inside_error(dp, S) <= 1e-8 and dp.lifting_bias == 0.0


def test_linear_interpolation_is_the_worse_choice():
    s, c = linear()
    S = solve_game_riccati(A, B, E, Q, R, P, GAMMA).S
    errs = [inside_error(solve_game_dp(s, c, [-1, -1], [1, 1], DPSettings(
        n_points=(41, 41), prior=0.8 * S, margin=0.5, interpolation=k)), S)
        for k in ("cubic", "linear")]
    assert errs[0] < 1e-3 < errs[1]


def test_lifted_riccati_is_the_value_of_the_held_saddle_policies():
    """x'S_k x equals the simulated cost of the lifted saddle policies (inputs held k steps)."""
    k = 4
    S, KL = lifted_game_riccati(A, B, E, Q, R, P, GAMMA, k)
    np.testing.assert_allclose(lifted_game_riccati(A, B, E, Q, R, P, GAMMA, 1)[0],
                               solve_game_riccati(A, B, E, Q, R, P, GAMMA).S, rtol=1e-9)
    x0 = np.array([0.7, -0.4])
    x, J = x0.copy(), 0.0
    for _ in range(3000):
        z = -KL @ x
        u, w = z[:1], z[1:]
        for _ in range(k):
            J += x @ Q @ x + u @ R @ u - GAMMA**2 * w @ P @ w
            x = A @ x + B @ u + E @ w
    assert J == pytest.approx(x0 @ S @ x0, rel=1e-9)
    s, c = linear()
    dp = solve_game_dp(s, c, [-1, -1], [1, 1], DPSettings(n_points=(21, 21), hold_steps=k))
    assert inside_error(dp, S) <= 1e-8
    S1 = solve_game_riccati(A, B, E, Q, R, P, GAMMA).S
    X = dp.points
    expect = (np.abs(np.einsum("pi,ij,pj->p", X, S - S1, X)).max()
              / np.einsum("pi,ij,pj->p", X, S1, X).max())
    assert dp.lifting_bias == pytest.approx(expect, rel=1e-12) and dp.lifting_bias > 0


def test_value_pinned_at_origin_and_nonnegative():
    s, c = linear()
    S = solve_game_riccati(A, B, E, Q, R, P, GAMMA).S
    dp = solve_game_dp(s, c, [-1, -1], [1, 1],
                       DPSettings(n_points=(21, 21), prior=0.5 * S, margin=0.5))
    assert dp.value(np.zeros(2)) == 0.0
    assert dp.value(dp.points).min() >= -1e-12


@given(st.floats(-3, 3), st.floats(-3, 3), st.floats(-3, 3), st.floats(-1, 1))
def test_cubic_interpolation_is_exact_for_quadratics(a, b, cc, d):
    axes = [np.linspace(-1, 1, 7), np.linspace(-2, 3, 6)]
    g = np.meshgrid(*axes, indexing="ij")
    X = np.stack([v.ravel() for v in g], -1)

    def f(Y):
        return a * Y[:, 0] ** 2 + b * Y[:, 0] * Y[:, 1] + cc * Y[:, 1] ** 2 + d * Y[:, 0]
    Y = np.random.default_rng(1).uniform([-1, -2], [1, 3], (200, 2))
    W, idx = _interp_weights(axes, Y, cubic=True)
    np.testing.assert_allclose((W * f(X)[idx]).sum(1), f(Y), atol=1e-11)
    np.testing.assert_allclose(W.sum(1), 1.0, atol=1e-14)


def test_bad_settings_name_the_field():
    s, c = linear()
    with pytest.raises(ParameterError, match="n_points.*origin"):
        solve_game_dp(s, c, [-1, -1], [1, 1], DPSettings(n_points=(20, 21)))
    with pytest.raises(ParameterError, match="hold_steps"):
        DPSettings(hold_steps=0)
    with pytest.raises(ParameterError, match="prior"):
        DPSettings(prior="magic")
    with pytest.raises(ParameterError, match="margin"):
        DPSettings(margin=-1)
