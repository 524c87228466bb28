"""The UPQC as a physical device: the conventional structure's dc link (energy balance),
the shunt converter's current limit, the series converter's losses per (15), bad data."""

import numpy as np
import pytest
from scipy.integrate import trapezoid

from sim_cases import build_gti_upqc_sg
from weakgrid.sim.controllers import DigitalController, UPQCTarget, gti_design_states
from weakgrid.sim.errors import DataError
from weakgrid.sim.events import Fault
from weakgrid.sim.integrate import simulate

LOSSY = dict(chi=0.05, Rsh=0.02, Cdc=0.004, kp_dc=0.2, ki_dc=2.5)


def _run(structure="conventional", u=(0.08, -0.06), fault=(1.0, 1.08, 0.05), t_end=2.0, **p):
    s = build_gti_upqc_sg(structure, upqc=p)
    ctrl = DigitalController(lambda m: list(u), 1e-3, gti_design_states("PV"), UPQCTarget("U"),
                             enable=[(0.5, 10.0)], name="const")
    r = simulate(s, t_end, dt=1e-3, events=[Fault(2, fault[0], fault[1], xf=fault[2])],
                 controllers=[ctrl])
    assert r.ok
    return s, r


def test_dc_link_energy_balance():
    """Cdc·(Vdc(t)² − Vdc(0)²)/2 = ∫ (P_shunt − P_loss − P_dc) dt along a run with losses, a
    fault and series-voltage steps (the integral of the recorded powers, trapezoid rule)."""
    s, r = _run(**LOSSY)
    C = s.components["UPQC"].p["Cdc"][0]
    Vdc = r["U.Vdc"]
    E = C * Vdc ** 2 / 2
    net = r["U.P_shunt"] - r["U.P_loss"] - r["U.P_dc"]
    t = r.t
    cum = np.concatenate([[0.0], np.cumsum(0.5 * np.diff(t) * (net[:-1] + net[1:]))])
    dE = E - E[0]
    assert np.max(np.abs(dE)) > 1e-5                  # the dc link did move
    assert np.max(np.abs(cum - dE)) < 1e-3 * np.max(np.abs(dE)) + 1e-9
    assert np.max(r["U.P_loss"]) > 0                  # losses were drawn
    # the dc-voltage loop brings the link back to its set-point
    assert abs(Vdc[-1] - 1.0) < 0.05 * np.max(np.abs(Vdc - 1.0))


def test_lossless_unlimited_dc_link_stays_at_its_set_point():
    """chi = Rsh = 0, no limit: the shunt converter draws exactly the series power at every
    instant (the ideal constant-power model) and Vdc does not move."""
    _, r = _run()
    assert np.allclose(r["U.P_shunt"], r["U.P_series"], atol=1e-12)
    assert np.max(np.abs(r["U.Vdc"] - 1.0)) < 1e-12
    assert np.max(np.abs(r["U.P_series"])) > 1e-3


def test_current_limit_binds_in_a_deep_fault():
    """A deep fault at the shunt bus: |I_shunt| stays at Imax (the unlimited converter draws
    more), the link discharges while the limit binds and recovers after."""
    imax = 0.3
    _, free = _run(**LOSSY)
    s, lim = _run(**LOSSY, Imax=imax)
    assert np.max(np.abs(free["U.I_shunt"])) > 1.5 * imax
    assert np.max(np.abs(lim["U.I_shunt"])) <= imax * (1 + 1e-9)
    bound = lim["U.limited"] > 0.5
    assert bound.any()
    assert np.all(np.isclose(np.abs(lim["U.I_shunt"][bound]), imax))
    assert np.min(lim["U.Vdc"]) < np.min(free["U.Vdc"]) - 1e-3
    assert abs(lim["U.Vdc"][-1] - 1.0) < 0.1 * (1.0 - np.min(lim["U.Vdc"]))
    # the drained link lowers the series voltage it can carry: |Vu| <= Vmax·Vdc/Vdc0
    assert np.all(lim["U.Vu"] <= 0.2 * np.minimum(lim["U.Vdc"], 1.0) + 1e-12)
    # energy still balances (looser: the integrator steps over the limit's kinks)
    C = s.components["UPQC"].p["Cdc"][0]
    dE = C * (lim["U.Vdc"] ** 2 - 1.0) / 2
    net = lim["U.P_shunt"] - lim["U.P_loss"] - lim["U.P_dc"]
    cum = np.concatenate([[0.0], np.cumsum(0.5 * np.diff(lim.t) * (net[:-1] + net[1:]))])
    assert np.max(np.abs(cum - dE)) < 0.03 * np.max(np.abs(dE))


@pytest.mark.parametrize("structure", ["conventional", "reduced"])
def test_series_losses_per_15(structure):
    """The series converter's dc power is (1 + chi)·P_series while it delivers power (15) and
    never more than |P_series| is returned while it absorbs; in the reduced structure that is
    what the GTI's dc link gives."""
    chi = 0.05
    _, r = _run(structure, chi=chi)
    P, Pdc = r["U.P_series"], r["U.P_dc"]
    pos, neg = P > 1e-6, P < -1e-6
    assert pos.any()
    assert np.allclose(Pdc[pos], (1 + chi) * P[pos], rtol=1e-12)
    assert np.allclose(Pdc[neg], (1 - chi) * P[neg], rtol=1e-12)
    if structure == "reduced":
        assert np.allclose(r["PV.P_series"], Pdc, atol=1e-12)
    else:
        assert np.all(r["PV.P_series"] == 0)


def test_apparent_powers_recorded():
    s, r = _run(**LOSSY)
    assert np.allclose(r["U.S_series"], r["U.Vu"] * r["U.I"])
    assert np.allclose(r["U.S_shunt"], np.abs(r["U.P_shunt"]))
    assert r.unit("U.S_series", si=True) == "MVA"
    assert np.allclose(r.si("U.S_series"), r["U.S_series"] * s.Sb)


@pytest.mark.parametrize("field,value", [("Cdc", 0.0), ("chi", -0.1), ("Imax", -1.0),
                                         ("Rsh", -0.01), ("Vdc0", 0.0)])
def test_bad_device_data_named(field, value):
    with pytest.raises(DataError, match=field):
        build_gti_upqc_sg(upqc={field: value})
