"""The conventional UPQC's shunt converter and dc link in DPsim (weakgrid.sim.emt.upqc) against
the phasor engine.

The SMIB of test_emt_upqc (a conventional UPQC "U" in the line, shunt bus = the machine's bus):
at 0.1 s a DigitalController (period 1 ms, zero-order hold) steps the series voltage's in-phase
command ``Vuq`` from 0 to 0.15 pu, so the series converter draws ``P_series`` ~ 0.11 pu from the
dc link. Oracles: the phasor engine's dc link (the same law,
:func:`weakgrid.sim.upqc.shunt_dc_law`), the dc link's energy balance, and the ideal shunt the law
reduces to without limit and losses.
"""

import numpy as np
import pytest

from weakgrid.sim.controllers import DigitalController, UPQCTarget
from weakgrid.sim.integrate import simulate

from sim_cases import classical_smib

pytest.importorskip("dpsimpy")
from weakgrid.sim.emt import simulate_dpsim  # noqa: E402

pytestmark = pytest.mark.emt

T_STEP, T_END, T, DT = 0.1, 0.6, 1e-3, 1e-4
U = (0.0, 0.15)                                    # (Vup, Vuq) [pu]
#: the current limit binds: P_series ~ 0.11 pu > Imax |Vr|; with converter and shunt losses
LIMITED = dict(Imax=0.1, chi=0.02, Rsh=0.05)


def _controller():
    return DigitalController(lambda m: list(U), T, lambda sim, t, z, ctx: np.zeros(1),
                             UPQCTarget("U"), enable=[(T_STEP, 10.0)])


def _run(engine, **upqc):
    s = classical_smib(upqc_vmax=0.2, upqc_params=upqc)
    if engine == "phasor":
        return simulate(s, T_END, dt=DT, controllers=[_controller()])
    return simulate_dpsim(s, T_END, engine=engine, dt=DT, controllers=[_controller()])


@pytest.fixture(scope="module")
def limited():
    return {e: _run(e, **LIMITED) for e in ("phasor", "dpsim-dp", "dpsim-emt")}


def test_without_limit_and_losses_the_shunt_is_the_ideal_one():
    """Imax = 0 (no limit) or large, chi = Rsh = 0: the shunt converter draws exactly the
    series power at every step and the dc link stays at Vdc0 — the ideal constant-power
    shunt the DPsim bridge had before the dc link was modelled; the two limits run alike."""
    runs = [_run("dpsim-dp"), _run("dpsim-dp", Imax=100.0)]
    for r in runs:
        assert np.max(r["U.P_series"]) > 0.05                     # the series converter works
        assert np.max(np.abs(r["U.Vdc"] - 1.0)) < 1e-9
        assert np.allclose(r["U.P_shunt"], r["U.P_series"], rtol=0, atol=1e-12)
        assert np.allclose(r["U.P_dc"], r["U.P_series"], rtol=0, atol=1e-12)
        assert np.all(r["U.limited"] == 0) and np.all(r["U.P_loss"] == 0)
        assert np.allclose(r["U.Vu"][r.t > T_STEP + 2e-4], 0.15)   # the full command applied
    assert np.allclose(runs[0]["G1.omega"], runs[1]["G1.omega"], rtol=0, atol=1e-12)


@pytest.mark.parametrize("engine", ["dpsim-dp", "dpsim-emt"])
def test_the_limited_dc_link_dips_as_in_the_phasor_engine(limited, engine):
    ph, r = limited["phasor"], limited[engine]
    dip = {e: 1.0 - np.min(x["U.Vdc"]) for e, x in (("phasor", ph), (engine, r))}
    assert dip["phasor"] > 0.2                                    # the limit drains the link
    assert dip[engine] == pytest.approx(dip["phasor"], rel=0.03)
    assert r["U.Vdc"][-1] == pytest.approx(ph["U.Vdc"][-1], rel=0.03)
    # the whole trajectory, after the step's network transient
    late = r.t > T_STEP + 0.02
    assert np.max(np.abs(r["U.Vdc"][late] - np.interp(r.t[late], ph.t, ph["U.Vdc"]))) < 0.03
    assert np.max(np.abs(r["U.I_shunt"])) <= LIMITED["Imax"] + 1e-12
    assert np.any(r["U.limited"] == 1.0)


@pytest.mark.parametrize("engine", ["dpsim-dp", "dpsim-emt"])
def test_dc_link_energy_balance(limited, engine):
    """∫(P_shunt − P_loss − P_dc) dt = Δ(Cdc Vdc²/2): the recorded powers at row k are those held
    over the step ending there (forward Euler), so the sum matches to the step's accuracy."""
    r = limited[engine]
    Cdc = 0.01                                                   # UPQC default [pu·s on Sb]
    net = (r["U.P_shunt"] - r["U.P_loss"] - r["U.P_dc"])[1:]
    assert np.all(np.diff(r.t) == pytest.approx(DT))             # every step recorded
    work = float(np.sum(net) * DT)
    dE = Cdc * (r["U.Vdc"][-1] ** 2 - r["U.Vdc"][0] ** 2) / 2
    assert abs(dE) > 2e-3                                         # a real energy swing
    assert work == pytest.approx(dE, rel=2e-3)
    assert np.max(r["U.P_loss"]) > 0 and np.max(r["U.P_dc"] - r["U.P_series"]) > 0


def test_the_current_limit_lowers_the_series_voltage(limited):
    """Regression: the former ideal shunt drew the series power whatever Imax, so DPsim
    applied the full command (0.15 pu) where the drained link carries less."""
    ph, r = limited["phasor"], limited["dpsim-dp"]
    assert ph["U.Vu"][-1] < 0.9 * 0.15
    assert r["U.Vu"][-1] == pytest.approx(ph["U.Vu"][-1], rel=0.02)
    assert r["bus1.v"][-1] == pytest.approx(ph["bus1.v"][-1], abs=1e-3)
