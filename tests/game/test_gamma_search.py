"""The γ bisection: on linear systems it must find the game-Riccati attenuation limit."""

import numpy as np
import pytest

from weakgrid.game import (
    GameCost, GridMesh, LinearPolicy, LinearSystem, ParameterError, SolverSettings,
    attenuation_limit, dlqr, quadratic_basis,
)
from weakgrid.game.gamma_search import SearchSettings, search_min_gamma
from weakgrid.game.lq import policy_attenuation_limit


def linear_case(seed):
    rng = np.random.default_rng(seed)
    n, m, q = 2, int(rng.integers(1, 3)), 1
    A = rng.normal(size=(n, n))
    A *= rng.uniform(0.6, 1.3) / np.max(np.abs(np.linalg.eigvals(A)))
    B = rng.normal(size=(n, m))
    E = 0.5 * rng.normal(size=(n, q))
    Q = np.diag(rng.uniform(0.5, 2, n))
    R = np.diag(rng.uniform(0.5, 2, m))
    P = np.diag(rng.uniform(0.5, 2, q))
    return A, B, E, Q, R, P


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
def test_linear_gamma_star_is_the_riccati_limit(seed):
    A, B, E, Q, R, P = linear_case(seed)
    system = LinearSystem(A, B, E)
    K0, _, _ = dlqr(A, B, Q, R)
    g_lin = attenuation_limit(A, B, E, Q, R, P, rtol=1e-9)
    g_pol = policy_attenuation_limit(A, B, E, K0, Q, R, P)
    cost = GameCost.for_system(system, Q, R, P, 3.0 * max(g_lin, g_pol))
    res = search_min_gamma(
        system, quadratic_basis(2), cost, GridMesh([-1, -1], [1, 1], [0.5, 0.5]),
        LinearPolicy(K0), SolverSettings(tol_u=1e-10, tol_w=1e-10, max_outer=3000,
                                         max_inner=3000),
        # near γ* the worst-case gain L of the LQ game grows without bound, so the
        # transients of the (Schur) closed loop do too: allow them to leave Ω far
        SearchSettings(rtol=1e-4, rollout_steps=1500, return_fraction=0.5, escape_factor=1e4))
    assert res.gamma_star == pytest.approx(g_lin, rel=1e-3)
    assert res.bracket[0] <= res.gamma_star and res.bracket[0] >= g_lin * (1 - 1e-6)
    # the history is consistent with the bracket: accepted above, rejected below
    acc = [t.gamma for t in res.history if t.accepted]
    rej = [t.gamma for t in res.history if not t.accepted]
    assert min(acc) == res.gamma_star and (not rej or max(rej) < res.gamma_star)
    assert res.controller.cost.gamma == res.gamma_star
    # the fixed LQR start alone could not go below its own limit: the search did
    assert g_pol > g_lin


def test_settings_errors_name_the_field():
    with pytest.raises(ParameterError, match="rtol"):
        SearchSettings(rtol=0.0)
    with pytest.raises(ParameterError, match="starts"):
        SearchSettings(starts=("magic",))
    with pytest.raises(ParameterError, match="escape_factor"):
        SearchSettings(escape_factor=0.5)


def test_fixed_initial_start_stops_at_its_own_limit():
    """Why the search restarts: from the LQR start alone γ* is the LQR policy's limit."""
    A, B, E, Q, R, P = linear_case(0)
    system = LinearSystem(A, B, E)
    K0, _, _ = dlqr(A, B, Q, R)
    g_lin = attenuation_limit(A, B, E, Q, R, P)
    g_pol = policy_attenuation_limit(A, B, E, K0, Q, R, P)
    cost = GameCost.for_system(system, Q, R, P, 3.0 * g_pol)
    res = search_min_gamma(
        system, quadratic_basis(2), cost, GridMesh([-1, -1], [1, 1], [0.5, 0.5]),
        LinearPolicy(K0), SolverSettings(tol_u=1e-10, tol_w=1e-10, max_outer=3000,
                                         max_inner=3000),
        SearchSettings(rtol=1e-3, rollout_steps=500, return_fraction=0.5, escape_factor=1e4,
                       starts=("initial",)))
    assert res.gamma_star >= g_pol * (1 - 1e-3) > g_lin
