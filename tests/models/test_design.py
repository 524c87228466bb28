"""The design model (10) from physical parameters; the control laws (29) and LQR."""

import numpy as np
import pytest

from weakgrid.game import ParameterError
from weakgrid.models import (
    NonlinearInitialPolicy, UPQCDesignModel, gti_design_model, lqr_policy, sg_design_model,
)

GTI = dict(C=0.05, tau=15.0, Vs=1.05, B=4.0, Vr_bar=0.98, T=1e-3, chi=0.02)


def test_gti_equilibrium_and_gain():
    m = gti_design_model(Pin=1.5, **GTI)
    tau_p = (1 + GTI["chi"]) * GTI["tau"]
    assert m.a == pytest.approx(tau_p * GTI["Vs"] * GTI["B"] / GTI["C"])
    # Pm = Pin/(1+χ) = Vs·V̄r·B·sin ϕs0
    assert 1.5 / 1.02 == pytest.approx(GTI["Vs"] * GTI["Vr_bar"] * GTI["B"] * np.sin(m.phi_s0))
    np.testing.assert_allclose(m.step(np.zeros(2)), np.zeros(2), atol=1e-15)


def test_discrete_model_is_euler_of_9():
    """(10) is the forward-Euler step of (9) written with the physical parameters."""
    p = GTI
    m = gti_design_model(Pin=1.2, **p)
    rng = np.random.default_rng(1)
    tau_p = (1 + p["chi"]) * p["tau"]
    Pm = 1.2 / (1 + p["chi"])
    for _ in range(10):
        x = rng.uniform([-1, -10], [1, 10])
        u = rng.normal(size=2) * 0.1
        w = rng.normal(size=1) * 0.1
        ph, up = x
        ang = ph + m.phi_s0
        dup = (tau_p / p["C"]) * (Pm - p["Vs"] * p["Vr_bar"] * p["B"] * np.sin(ang)) \
            + (tau_p / p["C"]) * p["Vs"] * p["B"] * (np.cos(ang) * u[0] - np.sin(ang) * u[1]) \
            - (tau_p / p["C"]) * p["Vs"] * p["B"] * np.sin(ang) * w[0]
        expected = x + p["T"] * np.array([up, dup])
        np.testing.assert_allclose(m.step(x, u, w), expected, rtol=1e-12, atol=1e-12)


def test_linearization_matches_finite_differences():
    m = UPQCDesignModel(8.1e-4, 896.9, 0.83, 0.31)
    x0 = np.array([0.3, -2.0])
    A = m.open_loop_jacobian(x0)
    eps = 1e-6
    for j in range(2):
        e = np.zeros(2)
        e[j] = eps
        fd = (m.open_loop_dynamics(x0 + e) - m.open_loop_dynamics(x0 - e)) / (2 * eps)
        np.testing.assert_allclose(A[:, j], fd, rtol=1e-7, atol=1e-9)
    A0, B0, E0 = m.linearize()
    assert B0.shape == (2, 2) and E0.shape == (2, 1)


def test_sg_mapping_remark5():
    m = sg_design_model(H=3.0, E_prime=1.1, B=2.5, Vr_bar=1.0, T=1e-3, Pm=0.8)
    ws = 2 * np.pi * 50
    assert m.a == pytest.approx(1.1 * 2.5 * ws / 6.0)
    assert np.sin(m.phi_s0) == pytest.approx(0.8 / (1.1 * 1.0 * 2.5))
    assert m.machine == "sg"


def test_29_general_form_equals_preset_form():
    m = gti_design_model(Pin=1.0, **(GTI | {"chi": 0.0}))
    a = NonlinearInitialPolicy.on_design_model(m, 125, 0.069)
    b = NonlinearInitialPolicy.from_physical(gain=125, C=GTI["C"], B=GTI["B"], Vs=GTI["Vs"],
                                             tau=GTI["tau"], phase=0.069)
    x = np.random.default_rng(0).uniform([-1, -10], [1, 10], (50, 2))
    np.testing.assert_allclose(a(x), b(x), rtol=1e-12)
    # u = k(−υ−ϕ̂)[cos(ϕ̂+θ), sin(ϕ̂+θ)]
    k = 125 / m.a
    s = k * (-x[:, 1] - x[:, 0])
    np.testing.assert_allclose(a(x)[:, 0], s * np.cos(x[:, 0] + 0.069))


def test_lqr_policy_is_dlqr_of_linearization():
    control = pytest.importorskip("control")
    m = UPQCDesignModel(1.022834e-3, 4813.277, 1.645041, 0.982382)
    pol = lqr_policy(m, 0.01 * np.eye(2), np.eye(2))
    A, B, _ = m.linearize()
    K, _, _ = control.dlqr(A, B, 0.01 * np.eye(2), np.eye(2))
    np.testing.assert_allclose(pol.K, K, rtol=1e-8)


@pytest.mark.parametrize("field,value", [("C", -1.0), ("tau", 0.0), ("B", float("nan")),
                                         ("chi", -0.1), ("T", -1e-3)])
def test_non_physical_parameters(field, value):
    with pytest.raises(ParameterError, match=f"gti.{field}"):
        gti_design_model(Pin=1.0, **(GTI | {field: value}))


def test_power_above_transfer_limit():
    with pytest.raises(ParameterError, match="transfer limit"):
        gti_design_model(Pin=10.0, **GTI)
    with pytest.raises(ParameterError, match="exactly one"):
        gti_design_model(**GTI)
    with pytest.raises(ParameterError, match="phi_s0"):
        UPQCDesignModel(1e-3, 10.0, 1.0, 2.0)
