"""GTI + UPQC invariants on a GTI + UPQC + SG grid."""

import numpy as np
import pytest

from sim_cases import build_gti_upqc_sg
from weakgrid.sim.controllers import DigitalController, UPQCTarget, gti_design_states, sg_design_states
from weakgrid.sim.errors import SimulationError
from weakgrid.sim.events import Fault
from weakgrid.sim.integrate import simulate


def _gti_pac(s, r):
    """P_ac of the GTI recomputed from recorded network quantities (independent of the model code)."""
    g = s.components["GTI"]
    B = g.p["B"][0]
    V = r["bus1.Vr"] + 1j * r["bus1.Vi"]
    th_r = r["bus2.a"]
    Es = r["PV.Vs"] * np.exp(1j * (th_r + r["PV.phi_s"]))
    I = -1j * B * (Es - V)
    return (Es * np.conj(I)).real


@pytest.mark.parametrize("structure", ["conventional", "reduced"])
def test_steady_state_stays_put(structure):
    s = build_gti_upqc_sg(structure)
    r = simulate(s, 10.0, dt=0.01)
    x = r.data[:, : s.nx]
    assert np.max(np.abs(x - x[0])) < 1e-8


@pytest.mark.parametrize("structure", ["conventional", "reduced"])
def test_dc_link_balance_and_series_power(structure):
    s = build_gti_upqc_sg(structure)
    g = s.components["GTI"]
    C, chi, Pin = g.p["C"][0], g.p["chi"][0], g.Pin[0]
    ctrl = DigitalController(lambda m: [0.03, -0.02], 1e-3, gti_design_states("PV"), UPQCTarget("U"),
                             enable=[(0.5, 10.0)], name="const")
    r = simulate(s, 2.0, dt=1e-3, events=[Fault(3, 1.0, 1.05, xf=0.05)], controllers=[ctrl])
    assert r.ok
    Vc, dVc = r["PV.Vc"], r["PV.dVc"]
    # series power equals Re(Vu I*) recomputed from the recorded bus voltages
    y = 1.0 / complex(0.002, 0.05)
    Vr = r["bus2.Vr"] + 1j * r["bus2.Vi"]
    V1 = r["bus1.Vr"] + 1j * r["bus1.Vi"]
    Vu = (r["U.Vuq"] + 1j * r["U.Vup"]) * np.exp(1j * np.angle(Vr))
    I = y * (Vr + Vu - V1)
    Pser = (Vu * np.conj(I)).real
    assert np.max(np.abs(Pser - r["U.P_series"])) < 1e-9
    assert np.max(np.abs(Pser)) > 1e-3           # the source did work
    # dc-link balance C Vc dVc/dt = Pin - Pe (- P_series in the reduced structure), with Pe recomputed
    Pe = (1 + chi) * _gti_pac(s, r)
    drawn = Pser if structure == "reduced" else 0.0
    assert np.max(np.abs(C * Vc * dVc - (Pin - Pe - drawn))) < 1e-6
    # and the integrated trajectory is consistent with it (trapezoid rule between samples)
    dt = np.diff(r.t)
    k = dt > 0
    lhs = np.diff(Vc)[k]
    rhs = 0.5 * dt[k] * (dVc[:-1] + dVc[1:])[k]
    assert np.max(np.abs(lhs - rhs)) < 1e-6
    # where the power is drawn: the shunt (conventional) or the GTI dc link (reduced), never both
    if structure == "conventional":
        assert np.allclose(r["U.P_shunt"], r["U.P_series"]) and np.all(r["PV.P_series"] == 0)
    else:
        assert np.allclose(r["PV.P_series"], r["U.P_series"]) and np.all(r["U.P_shunt"] == 0)


def test_structures_identical_without_series_voltage():
    a = simulate(build_gti_upqc_sg("conventional"), 2.0, dt=5e-3, events=[Fault(3, 0.5, 0.6, xf=0.05)])
    b = simulate(build_gti_upqc_sg("reduced"), 2.0, dt=5e-3, events=[Fault(3, 0.5, 0.6, xf=0.05)])
    # round-off only: the conventional structure's dc-link loop enters the Newton Jacobian
    assert np.max(np.abs(a.data - b.data)) < 1e-9


def test_series_voltage_limit():
    s = build_gti_upqc_sg("conventional")
    ctrl = DigitalController(lambda m: [1.0, 1.0], 1e-2, gti_design_states("PV"), UPQCTarget("U"))
    r = simulate(s, 0.1, dt=1e-2, controllers=[ctrl])
    assert np.max(r["U.Vu"]) == pytest.approx(0.2, rel=1e-9)


def test_zoh_sampling_and_design_states():
    s = build_gti_upqc_sg("reduced")
    seen = []

    def K(m):
        seen.append(np.array(m))
        return [-2.0 * m[1], 0.0]

    ctrl = DigitalController(K, 2e-3, gti_design_states("PV"), UPQCTarget("U"), enable=[(0.25, 5.0)])
    r = simulate(s, 0.6, dt=1e-3, events=[Fault(3, 0.2, 0.25, xf=0.05)], controllers=[ctrl])
    assert r.ok
    t = np.array(ctrl.log_t)
    assert np.allclose(np.diff(t), 2e-3)
    u = np.array(ctrl.log_u)
    assert np.all(u[t < 0.25] == 0)                  # bypassed during the fault
    assert np.any(u[t >= 0.25, 0] != 0)
    # upsilon equals tau (Vc^2 - Vc0^2)/2 from the recorded dc-link voltage
    g = s.components["GTI"]
    i = int(np.argmin(np.abs(r.t - t[-1])))
    ups = g.p["tau"][0] * (r["PV.Vc"][i] ** 2 - 1.0) / 2
    assert seen[-1][1] == pytest.approx(ups, abs=1e-9)


def test_sg_design_states_start_at_zero():
    s = build_gti_upqc_sg("conventional")
    seen = []
    ctrl = DigitalController(lambda m: (seen.append(m), [0.0, 0.0])[1], 1e-2, sg_design_states("SG", 2),
                             UPQCTarget("U"))
    simulate(s, 0.05, dt=1e-2, controllers=[ctrl])
    assert np.max(np.abs(seen[0])) < 1e-9


def test_controller_nan_reports_name_and_time():
    s = build_gti_upqc_sg("conventional")
    ctrl = DigitalController(lambda m: [np.nan, 0.0], 1e-2, gti_design_states("PV"), UPQCTarget("U"),
                             enable=[(0.05, 1.0)], name="hji")
    with pytest.raises(SimulationError) as e:
        simulate(s, 0.2, dt=1e-2, controllers=[ctrl])
    assert e.value.cause == "controller" and "hji" in str(e.value) and e.value.t == pytest.approx(0.05)
