"""Events checked once the grid's identifiers are resolved (study/runner.py ``make_events``).

The study file's own check compares references as written; these are the backstops for the
same mistakes written another way: a trip of the UPQC's own series branch given by its row,
and two overlapping faults at one bus named once by name and once by index.
"""

import pytest

from weakgrid.game.errors import ParameterError
from weakgrid.study.build import build_setup
from weakgrid.study.runner import Run, make_events
from weakgrid.study.studyfile import load_study


@pytest.fixture(scope="module")
def ieee9():
    return build_setup(load_study("ieee9-sg-upqc"))


def _run(*events):
    return Run("x-none", "ieee9-sg-upqc", "x", "high", "conventional", "none", 2.0,
               tuple(events), ())


def test_a_trip_of_the_upqc_branch_by_its_row_is_refused(ieee9):
    row = ieee9.upqc_branch
    with pytest.raises(ParameterError, match="UPQC's own series branch") as exc:
        make_events(ieee9, _run({"kind": "line_trip", "branch": row, "t": 1.0}))
    assert exc.value.field == "scenarios.x.events.0.branch"


def test_a_trip_of_another_branch_passes(ieee9):
    ev = make_events(ieee9, _run({"kind": "line_trip", "branch": {"from": "7", "to": "8"},
                                  "t": 1.0}))
    assert len(ev) == 1 and ev[0].branch != ieee9.upqc_branch


def _fault(bus, t_on, t_off):
    return {"kind": "fault", "bus": bus, "t_on": t_on, "t_off": t_off, "rf": 0.0, "xf": 0.02}


def test_overlapping_faults_at_one_bus_named_two_ways_are_refused(ieee9):
    # pandapower bus "6" (its name) is index 5
    with pytest.raises(ParameterError, match="overlaps the fault at the same bus") as exc:
        make_events(ieee9, _run(_fault("6", 1.0, 1.1), _fault(5, 1.05, 1.2)))
    assert exc.value.field == "scenarios.x.events.1.t_on"


def test_successive_faults_at_one_bus_pass(ieee9):
    assert len(make_events(ieee9, _run(_fault("6", 1.0, 1.1), _fault(5, 1.1, 1.2)))) == 2
