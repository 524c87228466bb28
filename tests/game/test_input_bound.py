"""The input bound in the cost: penalty, bounded saddle point, policy iteration, DP ground truth."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from weakgrid.game import (
    GameCost,
    GridMesh,
    LinearPolicy,
    LinearSystem,
    ParameterError,
    even_monomials,
    solve_game_riccati,
    solve_hji,
)
from weakgrid.game.controller import controller_from_dict
from weakgrid.game.dynamic_programming import DPSettings, solve_game_dp
from weakgrid.game.input_bound import POINTWISE_MAX, InputBound
from weakgrid.game.optimality import closed_loop_gap, default_starts, value_error

# an open-loop stable oscillator (|λ| = 0.964): with a bounded control and an unbounded
# disturbance the game keeps a saddle point on the whole grid only if the plant is stable
A = np.array([[1.0, 0.1], [-0.3, 0.9]])
B = np.array([[0.0], [0.1]])
E = np.array([[0.02], [0.08]])
GAMMA = 5.0
LO, HI = [-1.0, -1.0], [1.0, 1.0]


def linear_cost(bound):
    s = LinearSystem(A, B, E)
    return s, GameCost.for_system(s, np.eye(2), 1.0, 1.0, GAMMA, bound=bound)


def riccati_policy():
    return LinearPolicy(solve_game_riccati(A, B, E, np.eye(2), np.eye(1), np.eye(1), GAMMA).K)


def train_linear(bound, degree=4, step=0.1):
    s, c = linear_cost(bound)
    return solve_hji(s, even_monomials(2, degree), c, GridMesh(LO, HI, [step, step]),
                     riccati_policy())


# ------------------------------------------------------------------ the penalty
@pytest.mark.parametrize("shape", ["box", "disk"])
def test_penalty_is_the_integral_and_tends_to_the_quadratic(shape):
    b = InputBound.for_inputs(2, 0.3, shape)
    R = 1.7 * np.eye(2)
    rng = np.random.default_rng(1)
    u = b.squash(rng.normal(size=(20, 2)) * 0.4)
    # W = 2∫ r ū atanh(v/ū) dv, per component (box) or along ‖u‖ (disk)
    for ui in u[:5]:
        parts = np.abs(ui) if shape == "box" else [np.linalg.norm(ui)]
        ref = sum(2 * 1.7 * quad(lambda v: 0.3 * np.arctanh(v / 0.3), 0, s)[0] for s in parts)
        assert b.penalty(ui, R) == pytest.approx(ref, rel=1e-10)
    # the gradient and the Hessian are the derivatives of W
    e = 1e-7
    for k in range(2):
        d = e * np.eye(2)[k]
        np.testing.assert_allclose((b.penalty(u + d, R) - b.penalty(u - d, R)) / (2 * e),
                                   b.penalty_gradient(u, R)[:, k], rtol=1e-6, atol=1e-8)
        np.testing.assert_allclose(
            (b.penalty_gradient(u + d, R) - b.penalty_gradient(u - d, R)) / (2 * e),
            b.penalty_hessian(u, R)[:, :, k], rtol=1e-5, atol=1e-6)
    # finite on the boundary (2rū² ln 2 per saturated direction), quadratic for ū → ∞
    edge = np.array([[0.3, 0.0]])
    assert b.penalty(edge, R)[0] == pytest.approx(2 * 1.7 * 0.09 * np.log(2), rel=1e-14)
    big = InputBound.for_inputs(2, 1e6, shape)
    np.testing.assert_allclose(big.penalty(u, R), 1.7 * (u * u).sum(1), rtol=1e-11)


@settings(max_examples=60, deadline=None)
@given(st.sampled_from(["box", "disk"]), st.integers(0, 10_000),
       st.floats(-5, 3), st.floats(0.01, 10))
def test_bounded_minimizer_is_inside_and_optimal(shape, seed, log_b, ubar):
    """argmin ½u'Mu + b'u + W(u): inside the bound, stationary, and no admissible point
    does better (M + 2R ≻ 0, M possibly indefinite)."""
    rng = np.random.default_rng(seed)
    bd = InputBound.for_inputs(2, ubar, shape)
    R = np.eye(2) * rng.uniform(0.2, 3)
    G = rng.normal(size=(2, 2))
    M = G @ G.T * rng.uniform(0, 5) - rng.uniform(0, 1.9) * R
    b = rng.normal(size=2) * 10.0**log_b
    u, info = bd.minimize(M, b, R, return_info=True)
    assert bd.ratio(u) <= 1.0
    assert info["n_unconverged"] == 0 and info["max_residual"] < 1e-12

    def F(v):
        return 0.5 * v @ M @ v + b @ v + bd.penalty(v, R)

    trial = bd.clip(u + rng.normal(size=(300, 2)) * 10.0 ** rng.uniform(-8, 0, (300, 1))
                    * ubar)
    vals = np.array([F(v) for v in trial])
    assert vals.min() >= F(u) - 1e-12 * (1 + abs(F(u)))


@pytest.mark.parametrize("shape", ["box", "disk"])
@pytest.mark.parametrize("m", [1, 2])
def test_one_point_path_equals_the_vectorized_iteration(shape, m):
    """A single point (a controller sample) takes the Python-float path; a batch the
    vectorized one: the same iteration, so the same u (to rounding) and the same count."""
    rng = np.random.default_rng(7 + m)
    bd = InputBound.for_inputs(m, 0.15, shape) if m == 2 or shape == "box" else \
        InputBound.for_inputs(1, 0.15, "disk")
    R = np.eye(m) * 0.8
    n = 200
    G = rng.normal(size=(n, m, m))
    M = G @ np.swapaxes(G, -1, -2) * rng.uniform(0, 5, (n, 1, 1)) - 1.5 * R
    b = rng.normal(size=(n, m)) * 10.0 ** rng.uniform(-4, 2, (n, 1))
    U, info = bd.minimize(M, b, R, return_info=True)      # vectorized (a batch)
    for k in range(n):
        u, inf1 = bd.minimize(M[k], b[k], R, return_info=True)   # one point
        assert u.shape == (m,)
        np.testing.assert_allclose(u, U[k], rtol=1e-12, atol=1e-15 * 0.15)
        assert inf1["n_unconverged"] == 0 and inf1["max_residual"] < 1e-12
    assert info["n_unconverged"] == 0


@pytest.mark.parametrize("shape", ["box", "disk"])
def test_a_few_points_take_each_points_own_arithmetic(shape):
    """Up to POINTWISE_MAX points (the rows of a small batch of controller samples) are solved
    point by point: each row bit for bit what the point alone gives (a batched run's policy
    outputs equal its run's alone), and the info sums the points' own."""
    rng = np.random.default_rng(11)
    bd = InputBound.for_inputs(2, 0.15, shape)
    R = np.eye(2) * 0.8
    n = 60
    G = rng.normal(size=(n, 2, 2))
    M = G @ np.swapaxes(G, -1, -2) * rng.uniform(0, 5, (n, 1, 1)) - 1.5 * R
    b = rng.normal(size=(n, 2)) * 10.0 ** rng.uniform(-4, 2, (n, 1))
    k = POINTWISE_MAX
    for s in range(0, n, k):
        U, info = bd.minimize(M[s:s + k], b[s:s + k], R, return_info=True)
        alone = [bd.minimize(M[j], b[j], R, return_info=True) for j in range(s, min(s + k, n))]
        assert np.array_equal(U, np.array([a[0] for a in alone]))
        assert info["iterations"] == max(a[1]["iterations"] for a in alone)
        assert info["n_unconverged"] == 0
        assert info["max_residual"] == max(a[1]["max_residual"] for a in alone)


def test_bound_settings_are_checked():
    s = LinearSystem(np.eye(2), np.eye(2), np.ones((2, 1)))
    for kw, field in (({"bound": -1.0}, "u_bound"),
                      ({"bound": 0.1, "bound_shape": "ring"}, "u_bound_shape"),
                      ({"bound": [0.1, 0.2, 0.3], "bound_shape": "box"}, "u_bound")):
        with pytest.raises(ParameterError, match=field):
            GameCost.for_system(s, 1.0, 1.0, 1.0, 2.0, **kw)
    with pytest.raises(ParameterError, match="R"):  # the disk needs R = r·I
        GameCost.for_system(s, 1.0, np.diag([1.0, 2.0]), 1.0, 2.0, bound=0.1)
    with pytest.raises(ParameterError, match="R"):  # any bound needs R diagonal
        GameCost.for_system(s, 1.0, [[2.0, 0.5], [0.5, 2.0]], 1.0, 2.0, bound=0.1,
                            bound_shape="box")


# ------------------------------------------------------ the policy iteration
@pytest.fixture(scope="module")
def case1_bounded():
    from weakgrid.models import load_preset

    p = load_preset("case1-paper")
    out = {}
    for shape, ub in (("disk", 0.15), ("box", 0.1)):
        c = p.cost.with_bound(InputBound.for_inputs(2, ub, shape))
        out[shape] = (solve_hji(p.system, p.basis, c, p.mesh, p.initial_policy), p)
    return out


@settings(max_examples=200, deadline=None)
@given(st.sampled_from(["disk", "box"]), st.floats(-1, 1), st.floats(-10, 10))
def test_no_policy_exceeds_the_bound_on_omega(case1_bounded, shape, phi, ups):
    ctl, _ = case1_bounded[shape]
    x = np.array([[phi, ups]])
    assert ctl.cost.bound.ratio(ctl.control(x))[0] <= 1.0


def test_bounded_training_on_case1_respects_the_bound_everywhere(case1_bounded):
    for shape in ("disk", "box"):
        ctl, p = case1_bounded[shape]
        X = p.mesh.points
        act = ctl.bound_activity(X)
        assert act["max_ratio"] <= 1.0
        assert act["fraction_binding"] > 0.5  # the rating matters on most of Ω
        assert all(r.bound_active is not None for r in ctl.history)
        d = ctl.diagnostics(X)
        assert d["min_eig_Yu"] > 0 and d["max_eig_Yw"] < 0 and d["min_J"] >= 0
        # the controller file carries the bound and loads back to the same policy
        back = controller_from_dict(ctl.to_dict())
        assert back.cost.bound.shape == shape
        np.testing.assert_array_equal(back.control(X[::37]), ctl.control(X[::37]))


@pytest.mark.parametrize("shape", ["disk", "box"])
def test_large_bound_gives_the_unbounded_weights(shape):
    from weakgrid.models import load_preset

    p = load_preset("case1-paper")
    free = p.train()
    c = p.cost.with_bound(InputBound.for_inputs(2, 1e4, shape))
    wide = solve_hji(p.system, p.basis, c, p.mesh, p.initial_policy)
    assert wide.iterations["outer"] == free.iterations["outer"]
    np.testing.assert_allclose(wide.weights, free.weights, rtol=1e-6, atol=0)


def test_linear_large_bound_gives_the_riccati_weights():
    free, wide = train_linear(None, degree=2), train_linear(1e5, degree=2)
    np.testing.assert_allclose(wide.weights, free.weights, rtol=1e-6, atol=0)


# -------------------------------------------------- saddle point inequalities
@pytest.fixture(scope="module")
def linear_bounded():
    return train_linear(0.2, degree=6)


@settings(max_examples=100, deadline=None)
@given(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1), st.floats(-3, 3))
def test_saddle_point_inequalities_for_admissible_u(linear_bounded, x1, x2, s, w):
    """H(x, u*, w) ≤ H(x, u*, w*) ≤ H(x, u, w*) for every u in the bound and every w."""
    ctl = linear_bounded
    x = np.array([x1, x2])
    us, ws = ctl.saddle_point(x)
    assert ctl.cost.bound.ratio(us) <= 1.0
    u = np.array([s * 0.2 * (1 - 1e-12)])  # any admissible control
    H0 = ctl.hamiltonian(x, us, ws)
    tol = 1e-12 * (1 + abs(H0))
    assert ctl.hamiltonian(x, us, np.array([w])) <= H0 + tol
    assert ctl.hamiltonian(x, u, ws) >= H0 - tol


# --------------------------------------------------------------- DP ground truth
def test_bounded_dp_is_the_riccati_value_when_the_bound_is_inactive():
    s, c = linear_cost(1e3)
    S = solve_game_riccati(A, B, E, np.eye(2), np.eye(1), np.eye(1), GAMMA).S
    dp = solve_game_dp(s, c, LO, HI, DPSettings(n_points=(41, 41), prior=0.5 * S, margin=1.0))
    assert dp.converged
    X = dp.points[np.all(np.abs(dp.points) <= 1 + 1e-12, axis=1)]
    Vr = np.einsum("pi,ij,pj->p", X, S, X)
    assert np.abs(dp.value(X) - Vr).max() / Vr.max() <= 0.01


def test_bounded_dp_differs_from_riccati_when_the_bound_acts():
    s, c = linear_cost(0.2)
    S = solve_game_riccati(A, B, E, np.eye(2), np.eye(1), np.eye(1), GAMMA).S
    dp = solve_game_dp(s, c, LO, HI, DPSettings(n_points=(41, 41), margin=0.5))
    assert dp.converged
    X = dp.points
    assert np.abs(dp.control(X)).max() <= 0.2
    Xi = X[np.all(np.abs(X) <= 1 + 1e-12, axis=1)]
    Vr = np.einsum("pi,ij,pj->p", Xi, S, Xi)
    assert (dp.value(Xi) - Vr).max() / Vr.max() > 0.05  # a weaker control costs more


def test_bounded_controller_is_within_5_percent_of_the_bounded_dp(linear_bounded):
    ctl = linear_bounded
    s, c = linear_cost(0.2)
    dp = solve_game_dp(s, c, LO, HI, DPSettings(n_points=(41, 41), margin=0.5))
    assert dp.converged
    assert ctl.bound_activity(GridMesh(LO, HI, [0.1, 0.1]).points)["fraction_binding"] > 0.3
    ve = value_error(ctl, dp, LO, HI)
    assert ve["sup_error_over_max_V"] <= 0.05
    gap = closed_loop_gap(ctl, dp, default_starts(LO, HI, 0.9), 400)
    for key in ("no_disturbance", "worst_case"):
        assert gap[key]["diverged_controller"] == 0
        assert abs(gap[key]["max_relative_gap"]) <= 0.05
        assert abs(gap[key]["min_relative_gap"]) <= 0.05


def test_unbounded_controller_is_not_the_bounded_optimum(linear_bounded):
    """The oracle can fail: the unbounded controller's J misses the bounded DP value."""
    free = train_linear(None, degree=6)
    s, c = linear_cost(0.2)
    dp = solve_game_dp(s, c, LO, HI, DPSettings(n_points=(41, 41), margin=0.5))
    assert value_error(free, dp, LO, HI)["sup_error_over_max_V"] > 0.05


def test_radial_diagnostic_flags_the_ridge_of_the_bounded_case1_cost(case1_bounded):
    """With the paper's basis the bounded J of case 1 has a ridge at |ϕ̂| ≈ 1.03 (just past Ω):
    the diagnostic sees it, and the closed loop from ϕ̂ = 1 crosses it and diverges."""
    from weakgrid.game.rollout import rollout
    from weakgrid.models import load_preset

    ctl, p = case1_bounded["disk"]
    assert ctl.diagnostics(1.25 * p.mesh.points)["n_radial_decrease"] > 0
    assert load_preset("case1-paper").train().diagnostics(
        1.25 * p.mesh.points)["n_radial_decrease"] == 0
    r = rollout(p.system, ctl.control, [[1.0, 0.0]], 3000, bound=1e3)
    assert r.diverged[0]
