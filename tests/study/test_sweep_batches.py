"""A study's sweep in batches of one grid (the seam for the batched simulator): the batches of
the case-1 quick sweep, and a batched sweep's table equal to the one-by-one sweep's."""

import copy

import pandas as pd

from weakgrid.study.batches import batch_key
from weakgrid.study.studyfile import load_study, study_from_dict
from weakgrid.study.sweep import run_study_sweep, sweep_points
from weakgrid.sweep import group

TIMES = ["wall_s", "sim_wall_s"]


def test_the_case1_quick_sweep_is_one_batch_per_load_and_controller():
    st = load_study("case1-weak-grid")
    pts = sweep_points(st, quick=True)
    batches = group(pts, key=lambda p: batch_key(p.inputs))
    load = "scenarios.c1-high-conv.load"
    assert len(pts) == 12 and len(batches) == 6
    for b in batches:
        members = [pts[i].params for i in b.rows]
        assert len({(m[load], m["controller"]) for m in members}) == 1
        assert sorted(m["upqc.rating"] for m in members) == [0.15, 0.6]
        name, run_load, upqc, ctl, *_ = b.key
        assert (name, run_load, ctl) == ("case1-weak-grid", members[0][load],
                                         members[0]["controller"])
        assert upqc == "conventional"
    assert [pts[b.rows[0]].params["controller"] for b in batches[:3]] == \
        ["hji", "nonlinear-29", "hji-bounded"]          # the sweep's order


def test_a_batched_study_sweep_gives_the_scalar_table(tmp_path):
    d = copy.deepcopy(load_study("case1-weak-grid").data)
    d["sweep"].update(controllers=["nonlinear-29"],
                      quick={"axes": {"upqc.rating": [0.15, 0.6],
                                      "scenarios.c1-high-conv.load": ["high", "low"]},
                             "t_end": 0.4})
    d["sweep"].pop("maps", None)
    st = study_from_dict(d)
    scalar = run_study_sweep(st, tmp_path / "scalar", quick=True, workers=0, progress=False)
    batched = run_study_sweep(st, tmp_path / "batched", quick=True, workers=0, progress=False,
                              batched=True)
    assert len(scalar) == 4
    pd.testing.assert_frame_equal(scalar.drop(columns=TIMES), batched.drop(columns=TIMES))
