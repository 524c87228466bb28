"""The linearized grid as a python-control state-space model: its A is the modes' matrix, its
B the grid's response to the UPQC's series-voltage commands (checked against a simulation)."""

import numpy as np
import pytest

from weakgrid.design import modes, state_space
from weakgrid.sim.errors import DataError
from weakgrid.sim.integrate import simulate
from weakgrid.study.build import build_setup
from weakgrid.study.studyfile import load_study


@pytest.fixture(scope="module")
def setup():
    return build_setup(load_study("case2-lv-microgrid"))


def test_eigenvalues_equal_the_modes(setup):
    import control

    s = setup.system
    omega = f"{setup.source}.omega"
    ss = state_space(s, outputs=[omega])
    assert isinstance(ss, control.StateSpace)
    assert ss.B.shape == (s.nx, 2) and ss.C.shape == (1, s.nx)
    lam = np.sort_complex(np.linalg.eigvals(ss.A))
    ref = np.sort_complex(modes(s).eigenvalues)
    np.testing.assert_allclose(lam, ref, rtol=1e-9, atol=1e-9)
    assert ss.output_labels == [omega.replace(".", "_")]


def test_input_matrix_is_the_grid_response_to_a_held_command(setup):
    """A short simulation with the command held at a small du against the linear model's step
    response x(h) = (integral of e^(A s) ds over [0, h]) B du."""
    from scipy.linalg import expm

    s = setup.system
    ss = state_space(s)
    A, B = ss.A, ss.B
    comp = s.components["UPQC"]
    name = comp.names[0]
    du, h = 1e-4, 2e-4
    for k in range(2):
        comp.set_input(name, du if k == 0 else 0.0, du if k == 1 else 0.0)
        try:
            res = simulate(s, h, dt=h / 4)
        finally:
            comp.set_input(name, 0.0, 0.0)
        names = s.state_names()
        n = s.nx
        M = np.zeros((n + 1, n + 1))
        M[:n, :n], M[:n, n] = A, B[:, k] * du
        pred = expm(M * h)[:n, n] / h        # the mean derivative over [0, h]
        assert np.abs(pred).max() > 0
        big = np.nonzero(np.abs(pred) > 1e-2 * np.abs(pred).max())[0]
        dx = np.array([(res[names[j]][-1] - s.z0[j]) / h for j in big])
        np.testing.assert_allclose(dx, pred[big], rtol=0.05)


def test_unknown_output_names_the_close_ones(setup):
    with pytest.raises(DataError) as e:
        state_space(setup.system, outputs=[f"{setup.source}.omegaa"])
    assert f"{setup.source}.omega" in str(e.value)
