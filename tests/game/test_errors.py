"""Bad input gets a clear error that names the cause and the fix."""

import numpy as np
import pytest

from weakgrid.game import (
    ConvergenceError, FunctionSystem, GameCost, GammaTooSmallError, GridMesh,
    InitialPolicyError, LinearPolicy, LinearSystem, NonFiniteError, ParameterError, ShapeError,
    SolverSettings, paper_basis, quadratic_basis, solve_hji,
)
from weakgrid.models import load_preset


def test_gamma_too_small_on_the_paper_model():
    p = load_preset("case1-paper").with_gamma(0.5)
    with pytest.raises(GammaTooSmallError) as exc:
        p.train()
    e = exc.value
    assert e.gamma == 0.5 and "weakgrid gamma" in str(e)
    # either Yw lost negativity (where, how many) or the inner loop stopped contracting
    if e.n_bad is not None:
        assert 1 <= e.n_bad <= e.n_points == 1156 and e.worst_state.shape == (2,)
        assert "of 1156 mesh points" in str(e)
    else:
        assert "does not contract" in str(e) and "max|Δw|" in str(e)


def test_no_convergence_reports_last_changes():
    p = load_preset("case1-paper")
    with pytest.raises(ConvergenceError) as exc:
        p.train(SolverSettings(max_outer=3))
    msg = str(exc.value)
    assert "3 iterations" in msg and "max|Δu|" in msg and "Raise max_outer" in msg
    assert len(exc.value.history) == 3


def test_inner_loop_cap():
    p = load_preset("case1-paper")
    with pytest.raises(ConvergenceError, match="inner"):
        p.train(SolverSettings(max_inner=1))


def test_destabilizing_initial_policy():
    A = np.array([[1.2, 0.1], [0.0, 0.9]])
    sysm = LinearSystem(A, np.eye(2)[:, :1], np.ones((2, 1)))
    with pytest.raises(InitialPolicyError, match="spectral radius"):
        solve_hji(sysm, quadratic_basis(2), GameCost.for_system(sysm, 1, 1, 1, 10),
                  GridMesh([-1, -1], [1, 1], [0.2, 0.2]), LinearPolicy(np.zeros((1, 2))))


def test_non_finite_dynamics():
    def f(x):
        out = x.copy()
        out[..., 0] = np.where(x[..., 0] > 0.5, np.nan, x[..., 0] * 0.5)
        return out

    sysm = FunctionSystem(f, lambda x: np.broadcast_to([[0.0], [1.0]], x.shape[:-1] + (2, 1)),
                          lambda x: np.broadcast_to([[0.0], [1.0]], x.shape[:-1] + (2, 1)),
                          2, 1, 1)
    with pytest.raises(NonFiniteError, match="open_loop_dynamics"):
        solve_hji(sysm, quadratic_basis(2), GameCost.for_system(sysm, 1, 1, 1, 10),
                  GridMesh([-1, -1], [1, 1], [0.2, 0.2]), LinearPolicy(np.zeros((1, 2))))


def test_wrong_shapes():
    sysm = LinearSystem(0.5 * np.eye(2), np.ones((2, 1)), np.ones((2, 1)))
    cost = GameCost.for_system(sysm, 1, 1, 1, 10)
    with pytest.raises(ShapeError, match="basis"):
        solve_hji(sysm, quadratic_basis(3), cost, GridMesh([-1, -1], [1, 1], [0.2, 0.2]),
                  LinearPolicy(np.zeros((1, 2))))
    with pytest.raises(ShapeError, match="initial_policy"):
        solve_hji(sysm, quadratic_basis(2), cost, GridMesh([-1, -1], [1, 1], [0.2, 0.2]),
                  lambda x: np.zeros((x.shape[0], 3)))
    with pytest.raises(ShapeError, match="cost.R"):
        GameCost.for_system(sysm, 1, np.eye(3), 1, 10)
    with pytest.raises(ShapeError, match="B"):
        LinearSystem(np.eye(2), np.ones((3, 1)), np.ones((2, 1)))


@pytest.mark.parametrize("kw,field", [
    (dict(Q=-1.0), "cost.Q"), (dict(R=0.0), "cost.R"), (dict(P=-1.0), "cost.P"),
    (dict(gamma=0.0), "cost.gamma"), (dict(gamma=float("nan")), "cost.gamma")])
def test_bad_cost(kw, field):
    sysm = LinearSystem(0.5 * np.eye(2), np.ones((2, 1)), np.ones((2, 1)))
    args = dict(Q=1.0, R=1.0, P=1.0, gamma=10.0) | kw
    with pytest.raises(ParameterError, match=field.replace(".", r"\.")):
        GameCost.for_system(sysm, **args)


def test_bad_mesh_and_settings():
    with pytest.raises(ParameterError, match="mesh.step"):
        GridMesh([-1, -1], [1, 1], [0.0, 0.1])
    with pytest.raises(ParameterError, match="mesh.upper"):
        GridMesh([-1, -1], [-2, 1], [0.1, 0.1])
    with pytest.raises(ParameterError, match="tol_u"):
        SolverSettings(tol_u=-1)
    with pytest.raises(ParameterError, match="max_outer"):
        SolverSettings(max_outer=0)


def test_mesh_too_coarse_for_basis():
    sysm = LinearSystem(0.5 * np.eye(2), np.ones((2, 1)), np.ones((2, 1)))
    with pytest.raises(ParameterError, match="mesh"):
        solve_hji(sysm, paper_basis(), GameCost.for_system(sysm, 1, 1, 1, 10),
                  GridMesh([0, -1], [0.0001, 1], [0.00005, 1.0]), LinearPolicy(np.zeros((1, 2))))


def test_negative_cost_is_warned():
    """A basis that cannot represent a nonnegative J: the solver says so (J ≥ 0 check)."""
    import warnings

    from weakgrid.game import PolynomialBasis

    A = np.array([[0.5, 0.4], [0.0, 0.5]])
    sysm = LinearSystem(A, np.eye(2), np.array([[1.0], [0.0]]))
    basis = PolynomialBasis(np.array([[1, 1], [2, 0]]))  # no x2² term
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        ctl = solve_hji(sysm, basis, GameCost.for_system(sysm, np.diag([0.01, 1.0]), np.eye(2), 1, 5),
                        GridMesh([-1, -1], [1, 1], [0.05, 0.05]), LinearPolicy(np.zeros((2, 2))))
    msgs = [str(x.message) for x in w if issubclass(x.category, RuntimeWarning)]
    assert any("negative" in m and "mesh points" in m for m in msgs)
    assert ctl.diagnostics(GridMesh([-1, -1], [1, 1], [0.05, 0.05]).points)["n_negative_J"] > 0
