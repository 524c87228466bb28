"""Metrics against analytic responses."""

import numpy as np
import pytest

from weakgrid.study.metrics import (
    control_cost, itae, running_cost, settling_time, stability_verdict,
)


def damped(sigma=1.5, omega=2 * np.pi * 1.2, t_end=12.0, n=120001):
    t = np.linspace(0, t_end, n)
    return t, np.exp(-sigma * t) * np.cos(omega * t)


def test_settling_time_of_an_exponential():
    t = np.linspace(0, 10, 100001)
    y = np.exp(-2.0 * t)
    # |y| falls below 2 % of its peak (1) at ln(50)/2
    assert settling_time(t, y, y_final=0.0) == pytest.approx(np.log(50) / 2, rel=1e-4)


def test_settling_time_of_a_damped_oscillation_is_near_its_envelope():
    sigma = 1.5
    t, y = damped(sigma)
    ts = settling_time(t, y, y_final=0.0)
    env = np.log(50) / sigma
    assert env - 1.0 / 1.2 <= ts <= env + 1e-3  # within one period before the envelope time


def test_itae_of_an_exponential():
    t = np.linspace(0, 20, 200001)
    assert itae(t, 3 * np.exp(-2 * t), y_final=0.0) == pytest.approx(3 / 4, rel=1e-6)


def test_itae_from_a_start_time():
    t = np.linspace(0, 20, 200001)
    y = np.where(t < 1, 0.0, np.exp(-2 * (t - 1)))
    assert itae(t, y, t_start=1.0, y_final=0.0) == pytest.approx(1 / 4, rel=1e-4)


def test_costs():
    u = np.array([[1.0, 2.0], [0.5, 0.0]])
    assert control_cost(u, np.eye(2), 1e-3) == pytest.approx((5 + 0.25) * 1e-3)
    x = np.array([[1.0, 0.0], [0.0, 2.0]])
    np.testing.assert_allclose(running_cost(x, u, 0.01 * np.eye(2), np.eye(2)),
                               [0.01 + 5, 0.01 + 5 + 0.04 + 0.25])


def test_verdicts():
    t, y = damped(1.0, t_end=10)
    assert stability_verdict(t, y) == "stable"
    t, y = damped(-0.3, t_end=10)
    assert stability_verdict(t, y) == "unstable"
    t, y = damped(0.0, t_end=10)
    assert stability_verdict(t, y) == "undamped"


def test_not_settled_is_nan():
    t, y = damped(0.0, t_end=10)
    assert np.isnan(settling_time(t, y, y_final=0.0))


def test_backswing_of_a_damped_cosine():
    from weakgrid.study.metrics import backswing

    sigma, omega = 1.5, 2 * np.pi * 1.2
    t, y = damped(sigma, omega)
    # first negative extreme near half a period: e^{-σ·π/ω}
    assert backswing(t, y, y_final=0.0) == pytest.approx(np.exp(-sigma * np.pi / omega), rel=2e-2)
