"""Invariants of the grid DP with an input bound, and the richer "full" polynomial basis.

The bounded game charges ``W(u) ≥ u'Ru`` and restricts u to a subset, so its value can
only be higher: ``V_bounded ≥ V_unbounded`` at every state. The DP's self-consistency is
``|cost(u_dp, w_dp) − V(x₀)| / V(x₀)`` from the verify starts
(:func:`weakgrid.game.optimality.closed_loop_gap`, ``dp_consistency``). The monotone
(multilinear) scheme keeps the order exactly; the cubic one to its accuracy.
"""

import numpy as np
import pytest

from weakgrid.game import PolynomialBasis, full_monomials
from weakgrid.game.dynamic_programming import (BOUNDED_EXTRAPOLATE_CELLS, DPSettings,
                                               _interp_weights, solve_game_dp)
from weakgrid.game.errors import ParameterError
from weakgrid.game.optimality import default_starts
from weakgrid.game.rollout import rollout
from weakgrid.models import load_preset
from weakgrid.models.problem import _basis


def _values(points, interpolation):
    prob = load_preset("case1-paper")
    lo, hi = prob.mesh.lower, prob.mesh.upper
    st = DPSettings(n_points=(points, points), interpolation=interpolation)
    bounded = prob.with_input_bound(0.15)
    db = solve_game_dp(bounded.system, bounded.cost, lo, hi, st)
    du = solve_game_dp(prob.system, prob.cost, lo, hi, st)
    X = db.points
    return db.value(X), du.value(X)


def test_bounded_value_is_not_below_the_unbounded_one_with_the_monotone_scheme():
    # multilinear interpolation is monotone: the DP keeps the order of the two games
    Vb, Vu = _values(21, "linear")
    assert np.all(Vb >= Vu - 1e-9 * Vu.max())
    assert np.mean(Vb > Vu + 1e-6 * Vu.max()) > 0.5       # the bound acts on most of Ω


@pytest.mark.parametrize("points", [21, 41])
def test_bounded_value_is_not_below_the_unbounded_one_with_the_cubic_scheme(points):
    # the cubic scheme is not monotone: the order holds to the grid's accuracy only. With
    # the residual continued as a constant past the box it failed by 2.1 % (21²) and
    # 0.20 % (41²) of max V; continued linearly: 0.024 % and 0.048 % (0.0065 % at 61²),
    # at nodes next to the origin, where V is ~1e-3 of its maximum
    Vb, Vu = _values(points, "cubic")
    assert np.min(Vb - Vu) >= -1e-3 * Vu.max()
    assert np.mean(Vb > Vu + 1e-6 * Vu.max()) > 0.9


def test_the_cubic_residual_is_continued_linearly_past_the_box():
    # a constant continuation makes a kink at the boundary (the cause of the bounded DP's
    # 3-5 % inconsistency): up to 4 cells out a linear function is read exactly
    assert BOUNDED_EXTRAPOLATE_CELLS == 4.0
    axes = [np.linspace(-1.0, 1.0, 11), np.linspace(-2.0, 2.0, 9)]
    X = np.stack([v.ravel() for v in np.meshgrid(*axes, indexing="ij")], -1)

    def f(Y):
        return 0.3 + 2.0 * Y[:, 0] - 0.7 * Y[:, 1] + 0.5 * Y[:, 0] * Y[:, 1]
    Y = np.array([[1.3, 0.1], [-1.5, -0.4], [0.2, 2.9], [-0.6, -3.5], [1.4, 2.6]])
    W, idx = _interp_weights(axes, Y, cubic=True, cells=4.0)
    np.testing.assert_allclose((W * f(X)[idx]).sum(1), f(Y), atol=1e-12)
    # beyond 4 cells the continuation is constant (bounded weights for far successors)
    W2, idx2 = _interp_weights(axes, np.array([[1.8, 0.0], [50.0, 0.0]]), cubic=True, cells=4.0)
    np.testing.assert_allclose((W2 * f(X)[idx2]).sum(1), f(np.array([[1.8, 0.0]]))[0])


def test_the_continuation_is_linear_with_a_bound_and_constant_without():
    # case 2 without a bound: its residual falls outward past the power-angle limit; continued
    # linearly, policy iteration did not converge in 40 iterations and V < 0 (−331 at 61²)
    prob = load_preset("case2-paper")
    lo, hi = prob.mesh.lower, prob.mesh.upper
    dp = solve_game_dp(prob.system, prob.cost, lo, hi, DPSettings(n_points=(61, 61)))
    assert dp.converged and dp.value(dp.points).min() >= 0.0
    lin = solve_game_dp(prob.system, prob.cost, lo, hi, DPSettings(n_points=(61, 61),
                                                                    extrapolate=4, max_iterations=15))
    assert not lin.converged       # the linear continuation fails here (40 iterations: too)
    assert DPSettings().extrapolate is None and DPSettings(extrapolate=2).extrapolate == 2.0
    with pytest.raises(ParameterError, match="extrapolate"):
        DPSettings(extrapolate=-1)
    with pytest.raises(ParameterError, match="extrapolate"):
        DPSettings(extrapolate="far")


def test_no_node_of_the_bounded_dp_fails_the_saddle_point_test():
    # with the constant continuation 25 boundary nodes (41²) kept their first policy
    prob = load_preset("case1-paper").with_input_bound(0.15)
    dp = solve_game_dp(prob.system, prob.cost, prob.mesh.lower, prob.mesh.upper,
                       DPSettings(n_points=(41, 41)))
    assert dp.converged and dp.history[-1]["n_bad_inertia"] == 0


def _consistency(problem, points):
    lo, hi = problem.mesh.lower, problem.mesh.upper
    dp = solve_game_dp(problem.system, problem.cost, lo, hi, DPSettings(n_points=(points,) * 2))
    c = problem.cost
    starts = default_starts(lo, hi, 0.5)
    r = rollout(problem.system, dp.control, starts, 4000, Q=c.Q, R=c.R,
                disturbance=dp.disturbance, P=c.P, gamma=c.gamma,
                penalty=c.control_penalty if c.bound is not None else None)
    V0 = dp.value(starts)
    return float(np.max(np.abs(r.cost - V0) / V0))


@pytest.mark.slow
def test_unbounded_dp_is_self_consistent_to_half_a_percent():
    assert _consistency(load_preset("case1-paper"), 41) < 0.005     # measured 0.089 %


def test_bounded_dp_is_self_consistent_to_half_a_percent():
    # measured 0.95 % (41²), 0.17 % (61², the default), 0.078 % (81²); before the linear
    # continuation past the box 4.54 %, 2.99 %, 2.86 %
    assert _consistency(load_preset("case1-paper").with_input_bound(0.15), 61) < 0.005


def test_full_basis_has_every_monomial_of_degree_two_to_d():
    b = full_monomials(2, 4)
    E = {tuple(e) for e in b.exponents.tolist()}
    want = {(i, d - i) for d in (2, 3, 4) for i in range(d + 1)}
    assert E == want and len(b) == 12
    assert len(full_monomials(2, 6)) == 3 + 4 + 5 + 6 + 7
    assert len(full_monomials(3, 2)) == 6
    # a problem file chooses it as kind = "full"
    assert _basis({"kind": "full", "degree": 4}, 2) == b
    assert isinstance(b, PolynomialBasis)
    with pytest.raises(ParameterError, match="degree"):
        full_monomials(2, 1)
    with pytest.raises(ParameterError, match="full"):
        _basis({"kind": "fullest"}, 2)
