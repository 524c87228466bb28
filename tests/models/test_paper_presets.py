"""The paper's presets: weights of (30)/(31), saddle inequalities, closed loops."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from weakgrid.game.hji import closed_loop_spectral_radius
from weakgrid.game.rollout import rollout

TOLERANCE = {"case1-paper": 0.20, "case2-paper": 0.06}  # README: within 15 % (case 1) and 6 % (case 2), with margin


@pytest.mark.parametrize("name", ["case1-paper", "case2-paper"])
def test_weights_reproduce_the_paper(trained_presets, name):
    problem, ctl = trained_presets[name]
    W = ctl.weights
    Wp = np.array(problem.published["weights"])
    big = np.abs(Wp) >= 0.01
    rel = np.abs(W[big] - Wp[big]) / np.abs(Wp[big])
    assert rel.max() <= TOLERANCE[name], (W, Wp, rel)
    assert np.abs(W[~big] - Wp[~big]).max() <= 0.002
    # every weight has the paper's sign where the paper's is not zero
    assert np.all(np.sign(W[big]) == np.sign(Wp[big]))


@pytest.mark.parametrize("name", ["case1-paper", "case2-paper"])
def test_history_shrinks_to_tolerance(trained_presets, name):
    problem, ctl = trained_presets[name]
    h = ctl.history
    s = problem.settings
    assert h[-1].max_du <= s.tol_u
    assert all(r.max_dw[-1] <= s.tol_w for r in h)
    assert all(r.max_du > s.tol_u for r in h[:-1])
    # the final phase converges: the last five changes decrease monotonically
    last = [r.max_du for r in h[-5:]]
    assert all(b < a for a, b in zip(last, last[1:]))
    # conditions checked along the way
    assert all(r.max_eig_Yw < 0 and r.min_eig_Yu > 0 and r.min_J >= 0 for r in h)
    assert ctl.iterations["outer"] == len(h)


def test_case1_outer_loop_is_not_monotone_yet_converges(trained_presets):
    """docs/findings.md: max|Δu| rises for a while before the final fast convergence."""
    _, ctl = trained_presets["case1-paper"]
    du = np.array([r.max_du for r in ctl.history])
    rises = np.flatnonzero(np.diff(du) > 0)
    assert rises.size >= 5  # a sustained rise, not one blip
    assert du[-1] <= 1e-7 and du[rises[-1] + 1] > 1e3 * du[-1]


@pytest.mark.parametrize("name", ["case1-paper", "case2-paper"])
@given(data=st.data())
def test_saddle_inequalities(trained_presets, name, data):
    problem, ctl = trained_presets[name]
    lo, hi = np.array(problem.mesh.lower), np.array(problem.mesh.upper)
    x = np.array([data.draw(st.floats(lo[i], hi[i])) for i in range(2)])
    u = np.array([data.draw(st.floats(-5, 5)) for _ in range(2)])
    w = np.array([data.draw(st.floats(-5, 5))])
    us, ws = ctl.saddle_point(x)
    H = ctl.hamiltonian
    tol = 1e-9 * max(1.0, abs(H(x, us, ws)))
    assert H(x, us, w) <= H(x, us, ws) + tol
    assert H(x, us, ws) <= H(x, u, ws) + tol


def test_saddle_point_is_stationary(trained_presets):
    """At (u*, w*) the gradient of the Hamiltonian (22) vanishes (finite differences)."""
    problem, ctl = trained_presets["case1-paper"]
    x = problem.mesh.sample(10, seed=4)
    u, w = ctl.saddle_point(x)
    eps = 1e-6
    for k in range(2):
        du = np.zeros(2)
        du[k] = eps
        g = (ctl.hamiltonian(x, u + du, w) - ctl.hamiltonian(x, u - du, w)) / (2 * eps)
        assert np.abs(g).max() < 1e-5
    dw = np.array([eps])
    g = (ctl.hamiltonian(x, u, w + dw) - ctl.hamiltonian(x, u, w - dw)) / (2 * eps)
    assert np.abs(g).max() < 1e-5


def _closed_loops(problem, ctl, horizon_s=20.0):
    x0 = problem.mesh.corners_and_midpoints()
    N = int(horizon_s / problem.system.T)
    kw = dict(Q=problem.cost.Q, R=problem.cost.R)
    return x0, rollout(problem.system, ctl.control, x0, N, **kw), \
        rollout(problem.system, problem.initial_policy, x0, N, **kw)


def test_case1_trained_controller_recovers_and_beats_29(trained_presets):
    problem, ctl = trained_presets["case1-paper"]
    x0, hji, init = _closed_loops(problem, ctl)
    assert not hji.diverged.any()
    assert np.all(hji.final_norm() < 1e-6)
    assert np.all(hji.cost < init.cost), (hji.cost, init.cost)
    # (29) does not recover from every corner (docs/findings.md)
    recovered = (~init.diverged) & (np.nan_to_num(init.final_norm(), nan=np.inf) < 1e-6)
    assert not recovered.all()


def test_case2_trained_controller_recovers(trained_presets, capsys):
    problem, ctl = trained_presets["case2-paper"]
    x0, hji, lqr = _closed_loops(problem, ctl)
    assert not hji.diverged.any()
    assert np.all(hji.final_norm() < 1e-6)
    # reported, not asserted: a game controller buys robustness, not nominal cost
    with capsys.disabled():
        print("\ncase2-paper accumulated cost, HJI vs LQR initial policy:")
        for x, a, b in zip(x0, hji.cost, lqr.cost):
            print(f"  x0 = {x}:  HJI {a:9.3f}   LQR {b:9.3f}   ratio {a / b:6.3f}")


@pytest.mark.parametrize("name", ["case1-paper", "case2-paper"])
def test_trained_closed_loop_is_locally_stable(trained_presets, name):
    problem, ctl = trained_presets[name]
    assert closed_loop_spectral_radius(problem.system, ctl.control) < 1
    d = ctl.diagnostics(problem.mesh.points)
    assert d["n_bad_Yu"] == 0 and d["n_bad_Yw"] == 0 and d["n_negative_J"] == 0
