"""A fault's duration is a field of the study like its t_off: addressable by its dotted path,
sweepable, and it moves t_off with the fault's t_on."""

from __future__ import annotations

import copy

import pytest

from weakgrid.game.errors import ParameterError
from weakgrid.study.studyfile import get_path, load_study, set_path, study_from_dict
from weakgrid.study.sweep import run_point, sweep_points
from weakgrid.study.sweep_estimate import run_cost

EV = "scenarios.c1-high-conv.events.0"


def case1_with_sweep(axes, **sweep):
    st = load_study("case1-weak-grid")
    d = copy.deepcopy(st.data)
    d["sweep"] = {"scenarios": ["c1-high-conv"], "controllers": ["pss-only"], "axes": axes,
                  **sweep}
    d["claims"] = []
    return study_from_dict(d, source=st.source, base_dir=st.base_dir)


def test_duration_read_and_set_by_path():
    d = copy.deepcopy(load_study("case1-weak-grid").data)
    d.pop("sweep")     # its t_off axis is for the shipped t_on
    ev = get_path(d, EV)
    assert "duration" not in ev and (ev["t_on"], ev["t_off"]) == (0.2, 0.25)
    assert get_path(d, f"{EV}.duration") == 0.05              # t_off − t_on, rounded
    set_path(d, f"{EV}.duration", 0.1)
    assert "t_off" not in get_path(d, EV)                     # the end is given once
    set_path(d, f"{EV}.t_on", 0.3)                            # any order: t_off follows t_on
    ev = get_path(study_from_dict(d).data, EV)
    assert ev["t_off"] == pytest.approx(0.4) and "duration" not in ev
    set_path(d, f"{EV}.t_off", 0.35)                          # and back: t_off drops duration
    assert get_path(study_from_dict(d).data, EV)["t_off"] == 0.35


def test_duration_sweep_points_move_the_fault_end():
    st = case1_with_sweep({f"{EV}.duration": [0.02, 0.05, 0.1], f"{EV}.t_on": [0.2, 0.3]})
    pts = sweep_points(st)
    assert len(pts) == 6
    got = set()
    for pt in pts:
        ev = get_path(study_from_dict(pt.inputs["study"]).data, EV)
        dur, t_on = pt.params[f"{EV}.duration"], pt.params[f"{EV}.t_on"]
        assert ev["t_on"] == t_on and ev["t_off"] == pytest.approx(t_on + dur, abs=1e-12)
        got.add((t_on, dur))
    assert len(got) == 6
    # a longer fault costs more (the sweep starts its costliest runs first)
    cost = {pt.params[f"{EV}.duration"]: run_cost(pt.inputs) for pt in pts
            if pt.params[f"{EV}.t_on"] == 0.2}
    assert cost[0.02] < cost[0.05] < cost[0.1]


@pytest.mark.parametrize("axes, field, text", [
    ({f"{EV}.duration": [0.05, -0.01]}, f"sweep.axes.\"{EV}.duration\"", "duration"),
    ({f"{EV}.duration": [0.05, 10.0]}, f"sweep.axes.\"{EV}.duration\"", "t_end"),
    ({f"{EV}.duration": [0.05], f"{EV}.t_off": [0.3]}, f"sweep.axes.\"{EV}.t_off\"", "not both"),
])
def test_duration_sweep_refused_values(axes, field, text):
    with pytest.raises(ParameterError) as e:
        case1_with_sweep(axes)
    assert e.value.field == field and text in str(e.value)


def test_duration_sweep_runs_the_fault_it_says():
    """Run two points: the run's fault window is the swept one (and its metrics differ)."""
    st = case1_with_sweep({f"{EV}.duration": [0.02, 0.1]}, t_end=0.6)
    out = {pt.params[f"{EV}.duration"]: run_point(pt.inputs) for pt in sweep_points(st)}
    assert out[0.02]["fault"] == "0.2-0.22 s" and out[0.1]["fault"] == "0.2-0.3 s"
    assert out[0.1]["speed_peak_dev_pu"] > out[0.02]["speed_peak_dev_pu"]
