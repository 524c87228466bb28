"""The network re-solve after a digital controller's sample starts from the previous jump scaled
to the sample's output change (:func:`weakgrid.sim.integrate.jump_guess`)."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from sim_cases import build_gti_upqc_sg
from weakgrid.sim import integrate
from weakgrid.sim.batch import simulate_batch
from weakgrid.sim.controllers import DigitalController, UPQCTarget, gti_design_states
from weakgrid.sim.integrate import jump_guess, simulate

finite = st.floats(-1e3, 1e3, allow_nan=False)


@given(st.floats(-50, 50, allow_nan=False).filter(lambda c: abs(c) > 1e-6),
       st.integers(0, 2**32 - 1))
def test_the_guess_is_exact_for_a_linear_response_along_the_previous_change(c, seed):
    # the network's response to the held outputs over one sample: Δy = S·Δu
    rng = np.random.default_rng(seed)
    S, y, du_prev = rng.normal(size=(7, 2)), rng.normal(size=7), rng.normal(size=2)
    du = c * du_prev
    got = jump_guess(y, (S @ du_prev, du_prev), du)
    np.testing.assert_allclose(got - y, S @ du, rtol=1e-9, atol=1e-12)


def test_a_turning_output_is_guessed_on_its_side():
    # the output reverses: the plain previous jump would start twice as far from the solution
    y, dy, du_prev = np.array([1.0, 2.0]), np.array([0.1, -0.3]), np.array([0.02, 0.01])
    np.testing.assert_allclose(jump_guess(y, (dy, du_prev), -du_prev), y - dy)
    np.testing.assert_allclose(jump_guess(y, (dy, du_prev), 0.5 * du_prev), y + 0.5 * dy)


@pytest.mark.parametrize("du_prev,du", [(None, np.array([1.0, 0.0])),
                                        (np.array([1.0, 0.0]), None),
                                        (np.zeros(2), np.array([1.0, 0.0])),
                                        (np.ones(3), np.ones(2))])
def test_without_a_usable_change_the_previous_jump_is_taken(du_prev, du):
    y, dy = np.array([1.0, 2.0]), np.array([0.1, -0.3])
    np.testing.assert_array_equal(jump_guess(y, (dy, du_prev), du), y + dy)


def _sine_controller():
    """Holds a sinusoid of the sample count (5 Hz at T = 1 ms) on the UPQC's two channels: an
    output that turns every 100 ms."""
    k = [0]

    def K(m):
        k[0] += 1
        w = 2 * np.pi * 5.0 * 1e-3 * k[0]
        return np.array([0.02 * np.sin(w), 0.01 * np.cos(w)])

    return DigitalController(K, 1e-3, gti_design_states("PV"), UPQCTarget("U"), name="sine")


def test_a_turning_output_costs_fewer_evaluations_than_the_plain_previous_jump(monkeypatch):
    def run():
        r = simulate(build_gti_upqc_sg("conventional"), 0.3, dt=1e-3,
                     controllers=[_sine_controller()])
        return r.stats["evals"], r
    scaled, r1 = run()
    monkeypatch.setattr(integrate, "jump_guess", lambda y, jump, du: y + jump[0])
    plain, r2 = run()
    assert scaled < plain
    # both re-solves converge to the tolerance: the same trajectories to well within it
    np.testing.assert_allclose(r1.data, r2.data, rtol=0, atol=1e-6)


def test_a_batch_member_takes_its_run_alones_guesses():
    # the batch's re-solve starts each member where its run alone does: the same floats
    alone = simulate(build_gti_upqc_sg("conventional"), 0.2, dt=1e-3,
                     controllers=[_sine_controller()])
    sc = [{"controllers": [_sine_controller()]} for _ in range(3)]
    batch = simulate_batch(build_gti_upqc_sg("conventional"), sc, 0.2, dt=1e-3)
    for r in batch:
        assert r.stats["evals"] == alone.stats["evals"]
        np.testing.assert_array_equal(r.data, alone.data)
