"""Case 2 (islanded CIGRE LV microgrid, SG behind a UPQC): data, operating point, design model.

The key check: the design model (10) derived from the operating point must describe the built
grid — its electromechanical frequency sqrt(a·V̄r·cos ϕs0)/2π must agree with the SG's
oscillation in the detailed simulation.
"""

import math

import numpy as np
import pytest

from weakgrid.game.errors import ParameterError
from weakgrid.models import sg_design_model
from weakgrid.sim.controllers import DigitalController, UPQCTarget
from weakgrid.sim.events import Fault
from weakgrid.sim.integrate import simulate
from weakgrid.sim.network import BUS_TYPE
from paper_setups import build_case, study_data

CASE = "case2-lv-microgrid"


def built(load):
    """A fresh build (systems are re-usable only for one run: build anew each time)."""
    return build_case(CASE, load=load)


def design_freq_hz(d):
    return math.sqrt(d.a * d.Vr_bar * math.cos(d.phi_s0)) / (2 * math.pi)


def oscillation_freq_hz(t, y, t_start, n_periods=3):
    """Frequency from the first ``n_periods`` periods between successive maxima of ``y`` after ``t_start``."""
    sel = t > t_start
    t, y = t[sel], y[sel]
    # unique time points (breakpoints appear twice)
    t, idx = np.unique(t, return_index=True)
    y = y[idx]
    k = np.nonzero((y[1:-1] > y[:-2]) & (y[1:-1] >= y[2:]))[0] + 1
    assert len(k) >= n_periods + 1, "too few oscillation maxima to measure a frequency"
    return 1.0 / np.mean(np.diff(t[k[: n_periods + 1]]))


@pytest.mark.parametrize("load", ["high", "low"])
def test_builds_and_power_flow_converges(load):
    cb = built(load)
    net = cb.system.network
    assert net.pf is not None and net.pf.mismatch < 1e-6
    # islanded: one slack, the SG's bus; no external grid
    sg_bus = cb.info["bus_ids"]["Bus SG"]
    slack = net.bus_ids[net.bus[:, BUS_TYPE] == 3]
    assert list(slack) == [sg_bus]
    assert cb.machine == "sg" and cb.sg == "SG" and cb.upqc_name == "U"
    assert cb.shunt_bus == cb.info["bus_ids"]["Bus R1"] == cb.fault_bus
    # voltages within LV limits, SG within its rating, SG feeds the microgrid through the UPQC
    v = np.abs(net.pf.V)
    assert v.min() > 0.95 and v.max() < 1.05
    sg_mva = study_data(CASE)["dynamics"]["generator"][0]["machine"]["Sn"]
    assert 0 < cb.info["sg_p_mw"] < sg_mva
    assert 0.9 * cb.info["sg_p_mw"] < cb.line_power_mw < cb.info["sg_p_mw"]
    # loads: constant impedance with pf 0.9 and 1 (paper)
    pf = cb.info["load_p_mw"] / math.hypot(cb.info["load_p_mw"], cb.info["load_q_mvar"])
    assert 0.9 < pf < 1.0
    for key in ("sg_speed", "vup", "vuq", "p_series"):
        assert key in cb.signals


def test_low_load_is_lower():
    hi, lo = built("high"), built("low")
    assert lo.info["load_p_mw"] < 0.7 * hi.info["load_p_mw"]
    assert lo.info["sg_p_mw"] < 0.7 * hi.info["sg_p_mw"]
    assert lo.design.phi_s0 < hi.design.phi_s0


def test_variant_pq_and_reduced_rejected():
    with pytest.raises(ParameterError, match="not a GTI"):
        build_case(CASE, variant="pq")
    with pytest.raises(ParameterError, match="conventional"):
        build_case(CASE, upqc="reduced")


def test_steady_state_with_idle_upqc_stays_put():
    cb = built("high")
    K = DigitalController(lambda m: np.zeros(2), 0.01, cb.measure, UPQCTarget(cb.upqc_name))
    res = simulate(cb.system, 6.0, dt=5e-3, controllers=[K])
    assert res.ok
    w = res[cb.signals["sg_speed"]]
    assert np.max(np.abs(w - 1.0)) < 1e-6
    vr = res[cb.signals["shunt_bus_v"]]
    assert np.max(np.abs(vr - vr[0])) < 1e-6
    assert np.max(np.abs(res[cb.signals["p_series"]])) < 1e-9
    m = np.array(K.log_u)
    assert np.all(m == 0)


def test_design_model_is_the_one_reported():
    cb = built("high")
    d, info = cb.design, cb.info
    assert d.machine == "sg" and d.upqc == "conventional"
    for k in ("T", "a", "Vr_bar", "phi_s0"):
        assert info["derived"][k] == pytest.approx(getattr(d, k), rel=1e-12)
    # a = E'·B/M, M = 2H/ωs — recomputed from the reported physical quantities
    ref = sg_design_model(H=info["H_system_base_s"], E_prime=info["E_prime"], B=info["B"],
                          Vr_bar=d.Vr_bar, T=d.T,
                          f_nominal=50.0, delta0=d.phi_s0)
    assert ref.a == pytest.approx(d.a, rel=1e-12)
    assert info["B"] == pytest.approx(1 / (info["x_d1_system"] + info["Xu_system"]))
    # V̄r is the shunt-bus voltage of the power flow
    net = cb.system.network
    assert d.Vr_bar == pytest.approx(abs(net.pf.V[net.index_of(cb.shunt_bus)]), rel=1e-12)
    # equilibrium of the lossless model vs the SG's electrical power (resistances neglected)
    assert info["Pm_design_pu"] == pytest.approx(info["Pe_sg_pu"], rel=0.05)
    # the preset is reported beside it
    assert info["preset_case2_paper"]["a"] == pytest.approx(4813.277)
    assert info["preset_case2_paper"]["Vr_bar"] == pytest.approx(1.645041)


def test_measure_returns_design_units():
    """ϕ̂ in rad w.r.t. the shunt bus, υ = speed error in rad/s (pu × ωs)."""
    cb = built("high")
    seen = []

    def K(m):
        seen.append(np.array(m))
        return np.zeros(2)

    ctl = DigitalController(K, 0.05, cb.measure, UPQCTarget("U"), t0=0.0)
    res = simulate(cb.system, 0.8, dt=5e-3, controllers=[ctl],
                   events=[Fault(bus=cb.info["bus_ids"]["Bus SG"], t_on=0.1, t_off=0.13, rf=5.0)])
    assert res.ok
    m = np.array(seen)
    assert np.allclose(m[0], 0.0, atol=1e-9)          # equilibrium: ϕ̂ = 0, υ = 0
    tk = np.array(ctl.log_t)
    tu, iu = np.unique(res.t, return_index=True)
    w = np.interp(tk, tu, res["SG.omega"][iu])
    ws = 2 * math.pi * 50.0
    assert np.max(np.abs(m[:, 1])) > 0.05           # a visible disturbance (rad/s)
    assert np.allclose(m[:, 1], (w - 1.0) * ws, rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("load", ["high", "low"])
def test_design_frequency_matches_simulated_sg_mode(load):
    """sqrt(a·V̄r·cos ϕs0)/2π within 15 % of the SG's electromechanical oscillation (u = 0)."""
    cb = built(load)
    f_design = design_freq_hz(cb.design)
    # small disturbance: a 20 ms resistive load pulse (~40 kW) at the SG terminal
    ev = Fault(bus=cb.info["bus_ids"]["Bus SG"], t_on=0.2, t_off=0.22, rf=2.0)
    res = simulate(cb.system, 2.0, dt=2e-3, events=[ev])
    assert res.ok
    w = res[cb.signals["sg_speed"]]
    assert np.max(np.abs(w - 1)) < 0.02                 # small: linear regime
    f_sim = oscillation_freq_hz(res.t, w, 0.23)
    assert f_sim == pytest.approx(f_design, rel=0.15), (f_sim, f_design)


def test_fault_at_upqc_bus_survived_at_high_load():
    cb = built("high")
    fd = cb.info["fault"]
    ev = Fault(bus=cb.fault_bus, t_on=3.0, t_off=3.1, rf=fd["rf"], xf=fd["xf"])
    res = simulate(cb.system, 7.0, dt=2e-3, events=[ev])
    assert res.ok
    t, w = res.t, res[cb.signals["sg_speed"]]
    assert np.max(np.abs(w - 1)) > 0.01                 # the fault is felt
    assert np.max(np.abs(w[t > 6.0] - 1)) < 2e-3        # and the SG settles back
    v = res[cb.signals["shunt_bus_v"]]
    assert np.min(v[(t > 3.0) & (t < 3.1)]) < 0.2       # a real fault at the UPQC bus


def test_series_voltage_input_gain_matches_design_model():
    """A quadrature step Vup accelerates the SG by ≈ a·cos ϕs0·Vup (the design model's g, u1 channel)."""
    cb = built("high")
    u = np.array([0.02, 0.0])
    K = DigitalController(lambda m: u, 0.5, cb.measure, UPQCTarget(cb.upqc_name), enable=[(0.5, 9.0)])
    res = simulate(cb.system, 0.52, dt=1e-3, controllers=[K])
    assert res.ok
    t, iu = np.unique(res.t, return_index=True)
    w = res[cb.signals["sg_speed"]][iu]
    k = np.searchsorted(t, 0.5)
    acc = (w[k + 10] - w[k]) / (t[k + 10] - t[k]) * 2 * math.pi * 50.0      # rad/s²
    d = cb.design
    assert acc == pytest.approx(d.a * math.cos(d.phi_s0) * u[0], rel=0.25)
    assert np.max(np.abs(res[cb.signals["vup"]][iu][k + 1:] - u[0])) < 1e-12
