"""Study files, events, printouts and results speak the source's bus and branch identifiers.

A pandapower grid's bus is its pandapower index (or its name) everywhere: in the study file, in
the setup, in the design printout and in the result columns ``bus<index>.v``. The shipped
``case2-lv-microgrid`` keeps only the feeder's buses (``keep_buses``), so its pandapower
indices differ from positions in the converted table: the case that mixed the two numberings.
"""

import pytest

from weakgrid.game.errors import ParameterError
from weakgrid.sim.events import Fault, LineTrip
from weakgrid.sim.integrate import Simulator
from weakgrid.study.build import build_setup
from weakgrid.study.runner import Run, make_events
from weakgrid.study.studyfile import load_study

pn = pytest.importorskip("pandapower.networks")


@pytest.fixture(scope="module")
def lv():
    return build_setup(load_study("case2-lv-microgrid"))


def _pp_index(name):
    net = pn.create_cigre_network_lv()
    hit = net.bus.index[net.bus.name == name]
    assert len(hit) == 1
    return int(hit[0])


def _run(*events):
    return Run("x-none", "case2-lv-microgrid", "x", "high", "conventional", "none", 0.1,
               tuple(events), ())


def test_pandapower_buses_are_their_pandapower_index(lv):
    """Regression: the shunt bus 'Bus R1' (pandapower index 2) was simulator bus 0."""
    r1 = _pp_index("Bus R1")
    assert r1 != 0                                        # the grid does discriminate
    assert lv.shunt_bus == lv.bus("Bus R1") == lv.bus(r1) == r1
    net = lv.system.network
    assert net.bus_names[r1] == "Bus R1"
    assert lv.signals["shunt_bus_v"] == f"bus{r1}.v"
    # the design printout names the shunt bus by the same number (and its name)
    assert f'shunt bus {r1} ("Bus R1")' in lv.derivation.table()
    assert net.branch_names[lv.upqc_branch] == "UPQC series"     # the study's impedance name


def test_events_address_source_buses_and_act_there(lv):
    r15 = _pp_index("Bus R15")
    ev = make_events(lv, _run({"kind": "fault", "bus": "Bus R15", "t_on": 0.02, "t_off": 0.05,
                               "rf": 0.0, "xf": 1e-4},
                              {"kind": "fault", "bus": r15, "t_on": 0.2, "t_off": 0.3,
                               "rf": 0.0, "xf": 1e-4},
                              {"kind": "line_trip", "branch": "Line R4-R12", "t": 0.5}))
    assert isinstance(ev[0], Fault) and ev[0].bus == ev[1].bus == r15
    assert isinstance(ev[2], LineTrip) and ev[2].branch == lv.branch_names["Line R4-R12"]
    # the UPQC's own branch, by its name: addressed, and refused (tripping it disconnects it)
    with pytest.raises(ParameterError, match="UPQC's own series branch"):
        make_events(lv, _run({"kind": "line_trip", "branch": "UPQC series", "t": 0.5}))
    res = Simulator(lv.system, dt=2e-3, record=["bus*.v"]).run(0.06, events=ev[:1])
    k = (res.t > 0.025) & (res.t < 0.045)
    v = {n: float(res[n][k].mean()) for n in res.names}
    assert min(v, key=v.get) == f"bus{r15}.v" and v[f"bus{r15}.v"] < 0.05


@pytest.mark.parametrize("event, field, shown", [
    ({"kind": "fault", "bus": "Bus X", "t_on": 0.1, "t_off": 0.2, "rf": 0.0, "xf": 0.0},
     "events.0.bus", "Bus R1"),
    ({"kind": "fault", "bus": 999, "t_on": 0.1, "t_off": 0.2, "rf": 0.0, "xf": 0.0},
     "events.0.bus", "bus numbers"),
    ({"kind": "line_trip", "branch": "no such line", "t": 0.1}, "events.0.branch", "Line R1-R2"),
    ({"kind": "line_trip", "branch": 10_000, "t": 0.1}, "events.0.branch", "row 0.."),
])
def test_unknown_ids_list_valid_ones(lv, event, field, shown):
    with pytest.raises(ParameterError) as e:
        make_events(lv, _run(event))
    assert e.value.field.endswith(field) and shown in str(e.value)
