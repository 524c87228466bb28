"""Load steps and generator trips in DPsim (weakgrid.sim.emt.events) against the phasor engine.

Grid: a classical machine G1 (bus 1) on a line to bus 2 (a 100 MW load and a second classical
machine G2) and a line to an infinite bus (bus 3). Oracles: each engine stays at the power flow
until the event; EMT and DP agree with each other and, on the electromechanical response (G1's
speed excursion), with the phasor engine within a few per cent; a step that adds and the same
step that removes the load from the post-step point end at the same operating point; a tripped
machine records frozen states and zero power (weakgrid's convention).
"""

import numpy as np
import pytest

from weakgrid.sim.errors import DataError
from weakgrid.sim.events import Fault, GeneratorTrip, LineTrip, LoadStep
from weakgrid.sim.integrate import simulate

pytest.importorskip("dpsimpy")
from weakgrid.sim.emt import simulate_dpsim  # noqa: E402

pytestmark = pytest.mark.emt

T_EV, T_END = 0.1, 1.0


def _system(load2=100.0):
    from weakgrid.sim.sources import InfiniteBus
    from weakgrid.sim.system import System

    bus = np.array([[1, 2, 0, 0, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5],
                    [2, 2, load2, 20, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5],
                    [3, 3, 0, 0, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5]], float)
    gen = np.array([[1, 60, 0, 999, -999, 1.02, 100, 1, 999, -999] + [0] * 11,
                    [2, 40, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11,
                    [3, 0, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11], float)
    branch = np.array([[1, 2, 0.01, 0.15, 0.0, 0, 0, 0, 0, 0, 1, -360, 360],
                       [2, 3, 0.01, 0.15, 0.0, 0, 0, 0, 0, 0, 1, -360, 360]], float)
    s = System({"baseMVA": 100.0, "bus": bus, "gen": gen, "branch": branch})
    for nm, row in (("G1", 0), ("G2", 1)):
        s.add_machine("GENCLS", nm, row, Sn=100, M=6.0, D=0.0, ra=0.0, xd1=0.25)
    src = InfiniteBus()
    src.add_source("S3", 2)
    s.add_component(src)
    s.setup()
    return s


def _three(events, t_end=T_END, **kw):
    out = {"phasor": simulate(_system(**kw), t_end, dt=1e-4, events=events)}
    for e in ("dpsim-dp", "dpsim-emt"):
        out[e] = simulate_dpsim(_system(**kw), t_end, engine=e, dt=1e-4, events=events)
    return out


def _check_alike(runs, rel=0.01):
    exc = {e: np.max(np.abs(r["G1.omega"] - 1.0)) for e, r in runs.items()}
    assert exc["phasor"] > 1e-4, exc
    assert exc["dpsim-emt"] == pytest.approx(exc["dpsim-dp"], rel=0.01), exc
    for e in ("dpsim-dp", "dpsim-emt"):
        pre = runs[e].t < T_EV - 1e-9
        assert np.max(np.abs(runs[e]["G1.omega"][pre] - 1.0)) < 1e-6
        assert exc[e] == pytest.approx(exc["phasor"], rel=rel), exc
    return exc


@pytest.mark.parametrize("dP", [30.0, -30.0])
def test_load_step_swings_alike(dP):
    runs = _three([LoadStep(bus=2, t=T_EV, dP=dP, dQ=dP / 3)])
    _check_alike(runs)
    for e in ("dpsim-dp", "dpsim-emt"):     # the new operating point
        assert runs[e]["bus2.v"][-1] == pytest.approx(runs["phasor"]["bus2.v"][-1], abs=1e-3)


def test_generator_trip_swings_alike():
    runs = _three([GeneratorTrip(1, T_EV)])
    _check_alike(runs)
    for e, r in runs.items():
        after = r.t > T_EV + 2e-4
        assert np.all(r["G2.te"][after] == 0.0), e                      # no power after the trip
        assert np.ptp(r["G2.omega"][after]) == 0.0, e                    # frozen


def test_unsupported_events_are_refused():
    s = _system()
    with pytest.raises(DataError, match="LineTrip.*islands bus 1"):    # G1's only branch
        simulate_dpsim(s, 0.01, engine="dpsim-dp", events=[LineTrip(0, 0.005)])
    with pytest.raises(DataError, match="removes more load"):
        simulate_dpsim(s, 0.01, engine="dpsim-dp", events=[LoadStep(bus=1, t=0.005, dP=-10.0)])
    with pytest.raises(DataError, match="gen"):
        simulate_dpsim(s, 0.01, engine="dpsim-dp", events=[GeneratorTrip(2, 0.005)])


# ---------------------------------------------------------------- faults through an impedance
def _load_bus_on_infinite_bus():
    from weakgrid.sim.sources import InfiniteBus
    from weakgrid.sim.system import System

    bus = np.array([[1, 1, 40, 10, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5],
                    [2, 3, 0, 0, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5]], float)
    gen = np.array([[2, 0, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11], float)
    branch = np.array([[1, 2, 0.01, 0.3, 0.0, 0, 0, 0, 0, 0, 1, -360, 360]], float)
    s = System({"baseMVA": 100.0, "bus": bus, "gen": gen, "branch": branch})
    src = InfiniteBus()
    src.add_source("S2", 0)
    s.add_component(src)
    s.setup()
    return s


@pytest.mark.parametrize("rf, xf", [(0.0, 0.05), (0.02, 0.1), (0.05, 0.0)])
def test_fault_impedance_gives_the_phasor_fault_voltage(rf, xf):
    """A permanent fault through rf + j xf at a load bus fed from an infinite bus: once the dc
    offset has decayed (0.55 s after it, τ = 0.08 s) the faulted bus voltage is the algebraic
    one of the phasor engine (measured: |V| to 1.1e-4, its angle to 9.5e-4 rad, the damping
    resistor's 0.1 %)."""
    ev = [Fault(bus=1, t_on=0.05, rf=rf, xf=xf)]
    ref = simulate(_load_bus_on_infinite_bus(), 0.6, dt=1e-3, events=ev)
    for e in ("dpsim-dp", "dpsim-emt"):
        r = simulate_dpsim(_load_bus_on_infinite_bus(), 0.6, engine=e, dt=1e-4, events=ev)
        assert r["bus1.v"][-1] == pytest.approx(ref["bus1.v"][-1], abs=2e-4), e
        assert r["bus1.a"][-1] == pytest.approx(ref["bus1.a"][-1], abs=2e-3), e
        assert r["bus1.v"][-1] < 0.3                                  # the fault is on


def test_cleared_impedance_fault_swings_alike():
    """A fault through j0.05 pu at the machine bus for 0.1 s: speed excursion phasor 1.072e-2,
    DP 1.020e-2, EMT 1.021e-2 (the fault current's dc offset, which DPsim keeps, brakes)."""
    from sim_cases import classical_smib

    ev = [Fault(bus=1, t_on=0.1, t_off=0.2, xf=0.05)]
    runs = {"phasor": simulate(classical_smib(p=0.8, M=6.0), T_END, dt=1e-4, events=ev)}
    for e in ("dpsim-dp", "dpsim-emt"):
        runs[e] = simulate_dpsim(classical_smib(p=0.8, M=6.0), T_END, engine=e, dt=1e-4,
                                 events=ev)
    _check_alike(runs, rel=0.06)
    # after clearing no ringing at the faulted bus: the fault inductor's interrupted current
    # would alternate every step (period 2 dt); the network's own dc offset (a 60-Hz ripple of
    # |V| in DP) changes direction about every 80 steps
    d = np.diff(runs["dpsim-dp"]["bus1.v"][runs["dpsim-dp"].t > 0.2 + 1e-9])
    assert np.mean(np.sign(d[1:]) != np.sign(d[:-1])) < 0.05


def test_planning_check_refuses_what_the_build_refuses():
    """weakgrid.sim.emt.check_supported (a study's planning, no DPsim objects built) refuses
    what simulate_dpsim refuses, with the same field."""
    from weakgrid.sim.emt import check_supported

    s = _system()
    for ev, field in ((LineTrip(0, 0.005), "islands"), (LoadStep(bus=1, t=0.005, dP=-10.0), "dP"),
                      (GeneratorTrip(2, 0.005), "gen")):
        with pytest.raises(DataError, match=field):
            check_supported(s, [ev], "dpsim-dp")
        with pytest.raises(DataError, match=field):
            simulate_dpsim(s, 0.01, engine="dpsim-dp", events=[ev])
    check_supported(s, [LoadStep(bus=2, t=0.005, dP=-10.0), Fault(2, 0.001, 0.002, xf=0.1)],
                    "dpsim-emt")
    neg = _system(load2=-10.0)                       # generation as a load
    with pytest.raises(DataError, match="PD/GS"):
        check_supported(neg, [], "dpsim-dp")
