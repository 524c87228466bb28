"""A controller in the DPsim loop: the same DigitalController and design-state map in every engine.

Three buses: a GENCLS at bus 1, a conventional UPQC in branch 3→1 (shunt bus 3, with a 10 MW
load), a line 3→2 to an infinite bus. A bolted fault at bus 3 (0.1-0.15 s), then a sampled
speed-feedback law on the SG design state ``u = [-k υ, 0]`` (υ = ω − 1 measured through
weakgrid's SGStateMap; period 1 ms, enabled after clearing). Without control the machine
swings undamped (D = 0); with it the swing must decay alike in the phasor engine, DP and EMT —
the controller's benefit surviving the network transients on the same data.
"""

import numpy as np
import pytest

from weakgrid.sim.controllers import (DigitalController, UPQCTarget, mapped, sg_signals,
                                      sg_state_map)
from weakgrid.sim.errors import DataError
from weakgrid.sim.events import Fault
from weakgrid.sim.integrate import simulate
from weakgrid.sim.sources import InfiniteBus
from weakgrid.sim.system import System
from weakgrid.sim.upqc import UPQC

pytest.importorskip("dpsimpy")
from weakgrid.sim.emt import simulate_dpsim  # noqa: E402
from weakgrid.sim.emt.controllers import sg_signals as sg_signals_dpsim  # noqa: E402

pytestmark = [pytest.mark.emt, pytest.mark.slow]

T_END, LATE, GAIN = 2.0, 1.5, 10.0
EVENTS = [Fault(bus=3, t_on=0.1, t_off=0.15)]


def _case(load_mw=10.0):
    bus = np.array([[1, 2, 0, 0, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5],
                    [2, 3, 0, 0, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5],
                    [3, 1, load_mw, 0, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5]], float)
    gen = np.array([[1, 80, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11,
                    [2, 0, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11], float)
    branch = np.array([[3, 1, 0.002, 0.05, 0, 0, 0, 0, 0, 0, 1, -360, 360],
                       [3, 2, 0.01, 0.25, 0, 0, 0, 0, 0, 0, 1, -360, 360]], float)
    return {"baseMVA": 100.0, "bus": bus, "gen": gen, "branch": branch}


def _system(load_mw=10.0):
    s = System(_case(load_mw))
    s.add_machine("GENCLS", "G1", 0, Sn=100, M=6.0, D=0.0, ra=0.0, xd1=0.25)
    src = InfiniteBus()
    src.add_source("S2", 1)
    s.add_component(src)
    s.add_component(UPQC()).add_upqc("U", branch=0, structure="conventional", Vmax=0.2)
    s.setup()
    return s


def _dc(signals, gain):
    return DigitalController(lambda m: [-gain * m[1], 0.0], 1e-3,
                             mapped(signals("G1", 3), lambda s: sg_state_map(s, "G1", 3)),
                             UPQCTarget("U"), enable=[(0.15, 10.0)])


def _run(engine, gain):
    if engine == "phasor":
        dc = _dc(sg_signals, gain)
        return simulate(_system(), T_END, dt=1e-3, events=EVENTS, controllers=[dc]), dc
    dc = _dc(sg_signals_dpsim, gain)
    return simulate_dpsim(_system(), T_END, engine=engine, dt=1e-4, events=EVENTS,
                          controllers=[dc]), dc


@pytest.fixture(scope="module")
def runs():
    return {(e, g): _run(e, g) for e in ("phasor", "dpsim-dp", "dpsim-emt") for g in (0.0, GAIN)}


def _late(res):
    return np.max(np.abs(res["G1.omega"][res.t > LATE] - 1.0))


def test_controller_damps_alike_in_every_engine(runs):
    ratio = {}
    for e in ("phasor", "dpsim-dp", "dpsim-emt"):
        free, ctl = runs[(e, 0.0)][0], runs[(e, GAIN)][0]
        assert _late(free) > 5e-3, e                       # undamped without control
        ratio[e] = _late(ctl) / _late(free)
        assert ratio[e] < 0.25, (e, ratio[e])              # the controller damps it
    assert ratio["dpsim-emt"] == pytest.approx(ratio["dpsim-dp"], rel=0.02), ratio
    assert ratio["dpsim-dp"] == pytest.approx(ratio["phasor"], rel=0.05), ratio   # measured 0.06 %


def test_the_law_sees_dpsims_speed(runs):
    """The held output is the law of DPsim's own measured speed at each sampling instant."""
    res, dc = runs[("dpsim-emt", GAIN)]
    t = np.asarray(dc.log_t)
    u = np.asarray(dc.log_u)
    on = t >= 0.15
    w = np.interp(t[on], res.t, res["G1.omega"])
    assert np.allclose(u[on, 0], -GAIN * (w - 1.0), atol=1e-12)
    assert np.all(u[~on] == 0.0)


def test_clearing_a_fault_at_a_purely_inductive_bus_is_refused():
    with pytest.raises(DataError, match="rings undamped"):
        simulate_dpsim(_system(load_mw=0.0), 0.2, engine="dpsim-dp", events=EVENTS)


def test_a_measurement_of_an_unknown_machine_is_refused():
    dc = DigitalController(lambda m: [0.0, 0.0], 1e-3,
                           mapped(sg_signals_dpsim("G9", 3), lambda s: sg_state_map(s, "G1", 3)),
                           UPQCTarget("U"))
    with pytest.raises(DataError, match="G9.delta"):
        simulate_dpsim(_system(), 0.01, engine="dpsim-dp", controllers=[dc])
