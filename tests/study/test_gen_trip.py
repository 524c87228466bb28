"""A generator trip in a study file (``kind = "gen_trip"``): validated, run as the simulator's
GeneratorTrip (the unit and its controls disconnected), described in the report's protocol."""

import numpy as np
import pytest

from weakgrid.game.errors import ParameterError
from weakgrid.study.protocol import describe_event
from weakgrid.study.runner import Run, run_scenario
from weakgrid.study.studyfile import read_study_dict, study_from_dict

T_TRIP = 0.2


def ieee9(events, t_end=0.4):
    """The shipped IEEE 9-bus study (G3 controlled) with one scenario of ``events``."""
    d, _ = read_study_dict("ieee9-sg-upqc")
    d["controllers"]["compare"] = ["pss-only"]
    d["scenarios"] = [{"id": "trip", "t_end": t_end, "events": events}]
    d.pop("sweep", None)
    d.pop("figures", None)
    return study_from_dict(d)


def test_gen_trip_disconnects_the_unit():
    st = ieee9([{"kind": "gen_trip", "machine": "G2", "t": T_TRIP}])
    rec = run_scenario(st, Run.of(st, st.scenarios()[0], "pss-only"))
    t = np.asarray(rec.results.t)
    pe2 = np.asarray(rec.results["G2.Pe"])
    pe1 = np.asarray(rec.results["G1.Pe"])
    before, after = t < T_TRIP - 1e-9, t > T_TRIP + 1e-9
    assert pe2[0] > 0.5 and np.ptp(pe2[before]) < 1e-6       # G2 carries 163 MW, steady
    assert np.all(pe2[after] == 0.0)                          # then records nothing
    assert pe1[after][-1] > pe1[0] + 0.5                      # the slack unit picks it up


@pytest.mark.parametrize("event, field, text", [
    ({"kind": "gen_trip", "machine": "G3", "t": 0.1}, "events.0.machine", "controlled machine"),
    ({"kind": "gen_trip", "machine": "G2", "t": 0.5}, "events.0.t", "after the run's end"),
    ({"kind": "gen_trip", "machine": "G2", "t": 0.1, "bus": 3}, "events.0.bus", "unknown field"),
    ({"kind": "gen_trip", "t": 0.1}, "events.0.machine", "missing"),
])
def test_gen_trip_validation(event, field, text):
    with pytest.raises(ParameterError, match=rf"{field}.*{text}"):
        ieee9([event])


def test_unknown_machine_is_refused_with_the_units():
    st = ieee9([{"kind": "gen_trip", "machine": "G9", "t": T_TRIP}])
    with pytest.raises(ParameterError, match=r"events.0.machine.*G9.*'G1', 'G2'"):
        run_scenario(st, Run.of(st, st.scenarios()[0], "pss-only"))


def test_gen_trip_described():
    assert describe_event({"kind": "gen_trip", "machine": "G2", "t": 1.5}) == \
        "machine G2 trips (disconnected with its controls) at t = 1.5 s"


def test_protocol_names_the_inserted_branch():
    """An insert given by branch (ANDES, MATPOWER, PSS/E) is named in the protocol (it read
    "inserted in  (series reactance …)" before)."""
    from weakgrid.study.protocol import protocol_of

    d, _ = read_study_dict("ieee9-sg-upqc")
    text = " ".join(protocol_of(study_from_dict(d)))
    assert "inserted in line 3 at its to end (series reactance x = 0.02 pu)" in text
    d["grid"] = {"kind": "andes", "file": "andes:ieee39/ieee39_full.xlsx"}
    d["dynamics"] = {}
    d["machine"] = {"name": "GENROU_3"}
    d["report"] = {"speed_of": "GENROU_3"}
    d["upqc"]["insert"] = {"branch": "Line_37", "side": "from", "x": 0.01}
    text = " ".join(protocol_of(study_from_dict(d)))
    assert "inserted in Line_37 at its from end (series reactance x = 0.01 pu)" in text
