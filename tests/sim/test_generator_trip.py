"""GeneratorTrip: a unit (machine or converter, with its controls) disconnected at time t.

On PSID's MultiGen benchmark files (tests/data/psid/MultiGen, PSS/E's own case: eight units on
bus 102, machines with exciters, governors and a stabilizer, converters with their electrical
and plant controls):

* the unit is its machine or converter *and* every control linked to it, nothing else;
* from the trip on its states stay where they were and its recorded power is zero;
* Kirchhoff at bus 102 (no load, one transformer out): the power the transformer carries away
  is the sum of the powers of the units still connected, before and after the trip — so the
  tripped unit's current is gone from the network, and only it;
* bad trips are refused before the run, naming the row.
"""

from pathlib import Path

import numpy as np
import pytest
from sim_cases import two_machine_case

from weakgrid.sim.errors import DataError
from weakgrid.sim.events import GeneratorTrip
from weakgrid.sim.integrate import Simulator
from weakgrid.sim.io.psse import from_psse
from weakgrid.sim.sources import InfiniteBus
from weakgrid.sim.system import System

MG = Path(__file__).resolve().parents[1] / "data" / "psid" / "MultiGen"
T_TRIP, T_END, DT = 0.5, 1.0, 1 / 240


def _system():
    s, _ = from_psse(MG / "FourBusMulti.raw", MG / "FourBus_multigen.dyr")
    return s.setup()


def _unit_power(res, names):
    """Active power [pu, system base] each named machine or converter injects into bus 102. A
    converter's is ``Ipout*|V|``: its ``Pe`` read from PSS/E is PSS/E's, with the per-step voltage
    estimate (REGCA1 ``psse_interface = 1``), which the network does not see."""
    v = np.asarray(res["bus102.v"])
    return {n: np.asarray(res[f"{n}.Ipout"]) * v if n.startswith("REGCA1") else np.asarray(res[f"{n}.Pe"])
            for n in names}


def _transformer_flow(s, res):
    """Active power [pu] from bus 102 into the 102-103 transformer, from the bus voltages."""
    net = s.network
    k = s.psse_transformer_rows[(102, 103, 0, "1")][0]
    f, t, Yff, Yft, Ytf, Ytt = net.branch_admittances()
    bf, bt = net.bus_ids[f[k]], net.bus_ids[t[k]]
    Vf = res[f"bus{bf}.Vr"] + 1j * res[f"bus{bf}.Vi"]
    Vt = res[f"bus{bt}.Vr"] + 1j * res[f"bus{bt}.Vi"]
    S = Vf * np.conj(Yff[k] * Vf + Yft[k] * Vt) if bf == 102 else Vt * np.conj(Ytf[k] * Vf + Ytt[k] * Vt)
    return S.real


@pytest.mark.parametrize("unit,expected", [
    ("EG", {"GENROU_102_EG", "SEXS_102_EG", "GAST_102_EG"}),
    ("WG", {"GENROU_102_WG", "SEXS_102_WG", "GAST_102_WG", "IEEEST_102_WG"}),
    ("SW", {"REGCA1_102_SW", "REECB1_102_SW", "REPCA1_102_SW"}),
])
def test_trip_disconnects_the_unit_and_only_it(unit, expected):
    s = _system()
    row = s.psse_gen_row[(102, unit)]
    res = Simulator(s, dt=DT).run(T_END, events=[GeneratorTrip(row, T_TRIP)])
    assert res.ok and res.t[-1] == pytest.approx(T_END)
    assert set(s.disconnected.names) == expected
    after = res.t > T_TRIP + 1e-9
    dis = s.disconnected.states
    assert len(dis) > 0
    X = np.column_stack([res[n] for n in s.state_names()])
    # frozen from the trip on, while the others move
    assert np.all(X[after][:, dis] == X[after][:1, dis])
    others = np.setdiff1d(np.arange(s.nx), dis)
    assert np.max(np.abs(X[after][-1, others] - X[after][0, others])) > 1e-4
    sources = [n for n in s.psse_machine.values() if n.startswith(("GENROU_102", "REGCA1_102"))]
    tripped = s.psse_machine[(102, unit)]
    P = _unit_power(res, sources)
    assert np.all(P[tripped][after] == 0.0) and P[tripped][0] > 1.0
    # Kirchhoff at bus 102: the transformer carries what the connected units produce
    flow = _transformer_flow(s, res)
    total = sum(P[n] for n in sources)
    assert np.max(np.abs(flow - total)) < 1e-5   # the network solve's tolerance, on 47 pu
    # the machines still connected take the lost power over at once
    rest0 = total[0] - P[tripped][0]
    assert total[after][0] - rest0 > 0.5 * P[tripped][0]


def test_trip_of_a_row_without_a_trippable_unit_is_refused_before_the_run():
    s = _system()
    with pytest.raises(DataError, match="gen-table row 0..8") as e:
        Simulator(s, dt=DT).run(0.1, events=[GeneratorTrip(99, 0.05)])
    assert e.value.field == "gen"
    # a machine is a unit; an ideal source (an infinite bus) is not
    s2 = System(two_machine_case())
    s2.add_machine("GENCLS", "G", 0, M=6.0, xd1=0.3)
    s2.add_component(InfiniteBus()).add_source("INF", 1)
    s2.setup()
    with pytest.raises(DataError, match="cannot be disconnected") as e:
        Simulator(s2, dt=DT).run(0.1, events=[GeneratorTrip(1, 0.05)])
    assert e.value.field == "gen" and "InfiniteBus 'INF'" in str(e.value)
    res = Simulator(s2, dt=DT).run(0.1, events=[GeneratorTrip(0, 0.05)])
    assert res.ok and res["G.Pe"][-1] == 0.0
