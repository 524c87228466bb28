"""InputBound.minimize does no work twice (issue #21, throughput of the bounded law): F is never
evaluated again at a point it was evaluated at, the residual of the info only when asked for,
and the control is the same bit for bit with and without the info."""

import numpy as np
import pytest

import weakgrid.game.input_bound as ib
from weakgrid.game.input_bound import InputBound


def _problems(m, n, seed):
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, m, m)) * 5.0
    M = 0.5 * (A + np.swapaxes(A, -1, -2))
    R = np.eye(m) * 0.7
    ev = np.linalg.eigvalsh(M + 2 * R)
    M = M + np.eye(m) * np.maximum(0.0, 0.1 - ev.min(-1))[:, None, None]
    b = rng.normal(size=(n, m)) * 10.0 ** rng.uniform(-2, 1, size=(n, 1))
    return M, b, R


@pytest.mark.parametrize("shape", ["disk", "box"])
def test_point_form_evaluates_F_once_per_point(shape, monkeypatch):
    """A step's f0 is F at the point the last step accepted, not evaluated again: F is
    evaluated once at the start and once per trial of the backtracking, so fewer than twice
    per step when the steps are taken whole (re-evaluating f0: at least twice)."""
    calls = [0]
    orig = ib._pt_penalty_of_v

    def spy(bd, v, twoR):   # F's only call of the penalty: one per evaluation of F
        calls[0] += 1
        return orig(bd, v, twoR)

    monkeypatch.setattr(ib, "_pt_penalty_of_v", spy)
    M, b, R = _problems(2, 6, 1)
    bd = InputBound.for_inputs(2, 5.0, shape)    # far from the bound: whole Newton steps
    evals = its = 0
    for k in range(len(b)):
        calls[0] = 0
        _, info = bd.minimize(M[k], b[k], R, return_info=True)
        assert info["n_unconverged"] == 0
        evals, its = evals + calls[0], its + info["iterations"]
    steps = its - len(b)    # ``iterations`` counts the pass that finds every point converged
    assert steps >= 2 * len(b)           # every point took steps
    assert evals < 2 * steps, f"{evals} evaluations of F in {steps} steps"


@pytest.mark.parametrize("n", [1, 4, 20])   # the point form (≤ POINTWISE_MAX) and the arrays
@pytest.mark.parametrize("shape", ["disk", "box"])
def test_info_changes_nothing(n, shape):
    M, b, R = _problems(2, n, 2)
    bd = InputBound.for_inputs(2, 0.2, shape)
    u = bd.minimize(M, b, R)
    u_info, info = bd.minimize(M, b, R, return_info=True)
    assert np.array_equal(u, u_info)
    assert info["n_unconverged"] == 0 and info["max_residual"] < 1e-12
