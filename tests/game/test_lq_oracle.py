"""The LQ game is the exact special case of the HJI solver (docs/theory.md, "The LQ game")."""

import numpy as np
import pytest

from weakgrid.game import (
    GameCost, GammaTooSmallError, GridMesh, LinearPolicy, LinearSystem, SolverSettings,
    attenuation_limit, dlqr, quadratic_basis, solve_game_riccati, solve_hji,
)
from weakgrid.game.lq import policy_attenuation_limit


def weights_to_matrix(basis, W):
    n = basis.n_states
    S = np.zeros((n, n))
    for w, e in zip(W, basis.exponents):
        idx = np.flatnonzero(e)
        if len(idx) == 1:
            S[idx[0], idx[0]] += w
        else:
            S[idx[0], idx[1]] += w / 2
            S[idx[1], idx[0]] += w / 2
    return S


def random_case(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 5))
    m = int(rng.integers(1, 3))
    q = int(rng.integers(1, 3))
    A = rng.normal(size=(n, n))
    # half of the cases open-loop unstable, half stable
    target = rng.uniform(1.05, 1.4) if seed % 2 else rng.uniform(0.5, 0.95)
    A *= target / np.max(np.abs(np.linalg.eigvals(A)))
    B = rng.normal(size=(n, m))
    E = 0.5 * rng.normal(size=(n, q))
    Q = np.diag(rng.uniform(0.5, 2, n))
    R = np.diag(rng.uniform(0.5, 2, m))
    P = np.diag(rng.uniform(0.5, 2, q))
    return A, B, E, Q, R, P


SEEDS = list(range(12))


@pytest.mark.parametrize("seed", SEEDS)
def test_trained_weights_equal_game_riccati(seed):
    A, B, E, Q, R, P = random_case(seed)
    n = A.shape[0]
    K0, _, _ = dlqr(A, B, Q, R)
    # the policy iteration starts from K0: gamma must be admissible for K0 too
    gamma = 1.3 * max(attenuation_limit(A, B, E, Q, R, P),
                      policy_attenuation_limit(A, B, E, K0, Q, R, P))
    sol = solve_game_riccati(A, B, E, Q, R, P, gamma)
    system = LinearSystem(A, B, E)
    basis = quadratic_basis(n)
    ctl = solve_hji(system, basis, GameCost.for_system(system, Q, R, P, gamma),
                    GridMesh([-1] * n, [1] * n, [0.5] * n), LinearPolicy(K0),
                    SolverSettings(tol_u=1e-12, tol_w=1e-12, max_outer=2000, max_inner=2000))
    S = weights_to_matrix(basis, ctl.weights)
    assert np.max(np.abs(S - sol.S)) <= 1e-8 * np.max(np.abs(sol.S))
    x = np.random.default_rng(seed).normal(size=(20, n))
    u, w = ctl.saddle_point(x)
    np.testing.assert_allclose(u, -x @ sol.K.T, atol=1e-8 * np.abs(sol.K).max())
    np.testing.assert_allclose(w, -x @ sol.L.T, atol=1e-8 * np.abs(sol.L).max())


@pytest.mark.parametrize("seed", SEEDS[:6])
def test_below_attenuation_limit_refuses(seed):
    A, B, E, Q, R, P = random_case(seed)
    n = A.shape[0]
    gstar = attenuation_limit(A, B, E, Q, R, P)
    K0, _, _ = dlqr(A, B, Q, R)
    system = LinearSystem(A, B, E)
    with pytest.raises(GammaTooSmallError) as exc:
        solve_hji(system, quadratic_basis(n),
                  GameCost.for_system(system, Q, R, P, 0.9 * gstar),
                  GridMesh([-1] * n, [1] * n, [0.5] * n), LinearPolicy(K0))
    msg = str(exc.value)
    assert "mesh points" in msg and "worst at x" in msg and "Increase gamma" in msg
    assert exc.value.n_bad >= 1 and exc.value.n_points == 5**n
    # and the LQ game itself refuses too
    with pytest.raises(GammaTooSmallError):
        solve_game_riccati(A, B, E, Q, R, P, 0.9 * gstar)


@pytest.mark.parametrize("seed", SEEDS)
def test_game_riccati_solution_satisfies_its_equation_and_conditions(seed):
    A, B, E, Q, R, P = random_case(seed)
    gamma = 1.2 * attenuation_limit(A, B, E, Q, R, P)
    s = solve_game_riccati(A, B, E, Q, R, P, gamma)
    Bt = np.hstack([B, E])
    Rt = np.block([[R, np.zeros((R.shape[0], P.shape[0]))],
                   [np.zeros((P.shape[0], R.shape[0])), -gamma**2 * P]])
    rhs = Q + A.T @ s.S @ A - A.T @ s.S @ Bt @ np.linalg.solve(Rt + Bt.T @ s.S @ Bt,
                                                                Bt.T @ s.S @ A)
    assert np.max(np.abs(rhs - s.S)) < 1e-8 * np.max(np.abs(s.S))
    assert np.linalg.eigvalsh(R + B.T @ s.S @ B).min() > 0
    assert np.linalg.eigvalsh(gamma**2 * P - E.T @ s.S @ E).min() > 0
    assert np.max(np.abs(np.linalg.eigvals(A - B @ s.K - E @ s.L))) < 1


@pytest.mark.parametrize("seed", SEEDS[:6])
def test_lq_saddle_inequalities(seed):
    """x'Sx = min_u max_w of the one-step game: the gains are a saddle point."""
    A, B, E, Q, R, P = random_case(seed)
    gamma = 1.2 * attenuation_limit(A, B, E, Q, R, P)
    s = solve_game_riccati(A, B, E, Q, R, P, gamma)
    rng = np.random.default_rng(seed)

    def stage(x, u, w):
        xn = A @ x + B @ u + E @ w
        return x @ Q @ x + u @ R @ u - gamma**2 * w @ P @ w + xn @ s.S @ xn

    for _ in range(20):
        x = rng.normal(size=A.shape[0])
        us, ws = -s.K @ x, -s.L @ x
        u = us + rng.normal(size=us.shape)
        w = ws + rng.normal(size=ws.shape)
        assert stage(x, us, w) <= stage(x, us, ws) + 1e-9
        assert stage(x, us, ws) <= stage(x, u, ws) + 1e-9
        assert abs(stage(x, us, ws) - x @ s.S @ x) < 1e-8 * max(1, x @ s.S @ x)


def test_dlqr_matches_python_control():
    control = pytest.importorskip("control")
    A, B, E, Q, R, P = random_case(3)
    K, S, ev = dlqr(A, B, Q, R)
    K2, S2, ev2 = control.dlqr(A, B, Q, R)
    np.testing.assert_allclose(K, K2, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(S, S2, rtol=1e-9, atol=1e-12)
    assert np.max(np.abs(ev)) < 1


def test_attenuation_limit_is_the_boundary():
    A, B, E, Q, R, P = random_case(5)
    g = attenuation_limit(A, B, E, Q, R, P, rtol=1e-8)
    solve_game_riccati(A, B, E, Q, R, P, g * (1 + 1e-6))
    with pytest.raises(GammaTooSmallError):
        solve_game_riccati(A, B, E, Q, R, P, g * (1 - 1e-6))
