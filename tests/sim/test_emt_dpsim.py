"""DPsim engines (weakgrid.sim.emt): one SMIB, three engines, the same data.

A GENCLS machine (bus 1) on a line ``0.01 + j0.3`` pu to an infinite bus (bus 2), a bolted
three-phase fault at the machine bus from 0.1 s to 0.2 s. Oracles: the initial point is the
power flow in every engine; while the fault is on the machine's electrical power is zero in
every engine, so the speed at clearing is ``1 + Pm 0.1 / M`` up to the switching instants; the
electromechanical response (speed excursion) of EMT and DP agree with each other closely and
with the phasor engine within a few per cent (the network transients DPsim keeps are the
difference, see weakgrid.sim.emt.machines); EMT's three-phase voltages are balanced.
"""

import math

import numpy as np
import pytest

from weakgrid.sim.errors import DataError
from weakgrid.sim.events import Fault, LineTrip
from weakgrid.sim.integrate import simulate
from weakgrid.sim.runfile import read_run, write_run

from sim_cases import classical_smib

pytest.importorskip("dpsimpy")
from weakgrid.sim.emt import simulate_dpsim  # noqa: E402

pytestmark = pytest.mark.emt

M, PM, T_ON, T_OFF = 6.0, 0.8, 0.1, 0.2
EVENTS = [Fault(bus=1, t_on=T_ON, t_off=T_OFF)]


def _smib(model="GENCLS", **params):
    return classical_smib(p=PM, model=model, **{"M": M, **params})


@pytest.fixture(scope="module")
def runs():
    return {"phasor": simulate(_smib(), 1.0, dt=1e-4, events=EVENTS),
            "dpsim-dp": simulate_dpsim(_smib(), 1.0, engine="dpsim-dp", dt=1e-4, events=EVENTS),
            "dpsim-emt": simulate_dpsim(_smib(), 1.0, engine="dpsim-emt", dt=1e-4, events=EVENTS)}


def _at(res, name, t):
    return res[name][np.searchsorted(res.t, t - 1e-9) - 1]


@pytest.mark.parametrize("engine", ["dpsim-dp", "dpsim-emt"])
def test_initial_point_is_the_power_flow(runs, engine):
    ref, r = runs["phasor"], runs[engine]
    for name in ("G1.delta", "bus1.v", "bus1.a", "bus2.v", "bus2.a"):
        assert r[name][0] == pytest.approx(ref[name][0], abs=1e-9), name
    pre = r.t < T_ON - 1e-9
    assert np.max(np.abs(r["G1.omega"][pre] - 1.0)) < 1e-6       # steady before the fault
    assert np.max(np.abs(r["bus1.v"][pre] - ref["bus1.v"][0])) < 1e-4
    assert r["G1.te"][0] == pytest.approx(PM, rel=1e-9)


def test_speed_at_clearing_is_the_free_acceleration(runs):
    """No electrical power while the bolted fault is on: dw = Pm * 0.1 s / M in every engine."""
    expect = PM * (T_OFF - T_ON) / M
    for eng, r in runs.items():
        dw = _at(r, "G1.omega", T_OFF) - 1.0
        assert dw == pytest.approx(expect, rel=0.01), eng


def test_three_engines_agree_on_the_speed_peak(runs):
    peak = {e: r["G1.omega"].max() - 1.0 for e, r in runs.items()}
    low = {e: 1.0 - r["G1.omega"].min() for e, r in runs.items()}
    assert peak["dpsim-emt"] == pytest.approx(peak["dpsim-dp"], rel=2e-3)
    assert low["dpsim-emt"] == pytest.approx(low["dpsim-dp"], rel=2e-3)
    for e in ("dpsim-dp", "dpsim-emt"):
        assert peak[e] == pytest.approx(peak["phasor"], rel=0.05), e
        assert low[e] == pytest.approx(low["phasor"], rel=0.05), e
    assert peak["phasor"] > 0.012        # a real swing (the fault was applied)


def test_emt_three_phase_voltages_are_balanced_and_sized(runs):
    r = runs["dpsim-emt"]
    va, vb, vc = r["bus1.va"], r["bus1.vb"], r["bus1.vc"]
    assert np.max(np.abs(va + vb + vc)) < 1e-6
    pre = r.t < T_ON - 1e-9
    assert np.max(np.abs(va[pre])) == pytest.approx(r["bus1.v"][0], rel=1e-3)
    w = 2 * math.pi * 60.0
    V0 = r["bus1.v"][0] * np.exp(1j * r["bus1.a"][0])
    assert va[0] == pytest.approx((V0 * np.exp(1j * w * r.t[0])).real, abs=1e-6)
    assert r.si_factor[r.names.index("bus1.va")] == pytest.approx(110 * math.sqrt(2 / 3))
    assert "bus1.va" not in runs["dpsim-dp"]


def test_run_file_round_trip(runs, tmp_path):
    p = tmp_path / "emt.parquet"
    write_run(p, runs["dpsim-emt"], meta={"engine": "dpsim-emt"})
    df = read_run(p, ["G1.omega", "bus1.va"])
    assert np.allclose(df["G1.omega"].to_numpy(), runs["dpsim-emt"]["G1.omega"])


@pytest.mark.parametrize("model, params, field", [
    ("GENROE", dict(Sn=100, M=6.0, D=0.0, ra=0.0, xd=1.8, xq=1.7, xd1=0.3, xq1=0.55, xd2=0.25,
                    xq2=0.25, xl=0.2, Td10=8.0, Tq10=0.4, Td20=0.03, Tq20=0.05, psse_shaft=0.0),
     "GENROE"),
    ("GENCLS", dict(D=2.0), "D = 2"),
])
def test_machines_without_a_dpsim_model_are_refused(model, params, field):
    with pytest.raises(DataError, match=field):
        simulate_dpsim(_smib(model, **params), 0.01, engine="dpsim-emt", dt=1e-4)


@pytest.mark.parametrize("engine", ["dpsim-dp", "dpsim-emt"])
def test_stator_resistance_is_represented(engine):
    """ra = 0.01 pu: during the bolted terminal fault the machine feeds ra |I|^2 (about a quarter
    of Pm here) into its own stator, so it gains less speed than the free acceleration; DPsim's
    series resistor gives the phasor engine's speed at clearing (without it: the free value)."""
    ref = simulate(_smib(ra=0.01), 0.3, dt=1e-4, events=EVENTS)
    r = simulate_dpsim(_smib(ra=0.01), 0.3, engine=engine, dt=1e-4, events=EVENTS)
    assert r["G1.delta"][0] == pytest.approx(ref["G1.delta"][0], abs=1e-9)
    assert np.max(np.abs(r["G1.omega"][r.t < T_ON - 1e-9] - 1.0)) < 1e-6
    free = PM * (T_OFF - T_ON) / M
    dw_ref, dw = _at(ref, "G1.omega", T_OFF) - 1.0, _at(r, "G1.omega", T_OFF) - 1.0
    assert dw_ref < 0.85 * free
    assert dw == pytest.approx(dw_ref, rel=0.02)


def test_unmapped_events_and_engines_are_refused():
    from weakgrid.sim.events import Event

    class Surge(Event):          # an event kind no engine maps
        t = 0.005

    s = _smib()
    with pytest.raises(DataError, match="Surge"):
        simulate_dpsim(s, 0.01, engine="dpsim-dp", events=[Surge()])
    with pytest.raises(DataError, match="LineTrip.*islands"):    # the SMIB's only line
        simulate_dpsim(s, 0.01, engine="dpsim-dp", events=[LineTrip(0, 0.005)])
    with pytest.raises(DataError, match="dpsim-emt"):
        simulate_dpsim(s, 0.01, engine="dpsim-sp")
    with pytest.raises(DataError, match="dt"):
        simulate_dpsim(s, 0.01, engine="dpsim-dp", dt=-1.0)
