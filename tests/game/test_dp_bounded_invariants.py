"""Invariants of the grid DP with an input bound, and the richer "full" polynomial basis.

The bounded game charges ``W(u) ≥ u'Ru`` and restricts u to a subset, so its value can
only be higher: ``V_bounded ≥ V_unbounded`` at every state. The DP's self-consistency is
``|cost(u_dp, w_dp) − V(x₀)| / V(x₀)`` from the verify starts
(:func:`weakgrid.game.optimality.closed_loop_gap`, ``dp_consistency``).
"""

import numpy as np
import pytest

from weakgrid.game import PolynomialBasis, full_monomials
from weakgrid.game.dynamic_programming import DPSettings, solve_game_dp
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


@pytest.mark.xfail(strict=True, reason="known defect (issue 22): the cubic (non-monotone) "
                   "residual of the bounded DP oscillates at grid scale and has a slope at the "
                   "origin; V_bounded < V_unbounded by 2.1 % of max V on 21x21, 0.20 % on 41x41")
def test_bounded_value_is_not_below_the_unbounded_one_with_the_cubic_scheme():
    Vb, Vu = _values(21, "cubic")
    assert np.all(Vb >= Vu - 1e-9 * Vu.max())


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


@pytest.mark.slow
@pytest.mark.xfail(strict=True, reason="known defect (issue 22): the bounded DP is "
                   "self-consistent to 4.54 % (41x41), 2.99 % (61x61), 2.86 % (81x81): "
                   "refinement does not cure it (see the cubic-scheme test above)")
def test_bounded_dp_is_self_consistent_to_half_a_percent():
    assert _consistency(load_preset("case1-paper").with_input_bound(0.15), 41) < 0.005


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
