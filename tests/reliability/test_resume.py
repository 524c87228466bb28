"""Resume by content hash: a finished run is loaded only when its inputs are the same."""

from __future__ import annotations

import numpy as np

from weakgrid.manifest import MANIFEST_NAME, Manifest
from weakgrid.study.cache import inputs_key, load_run, remove_stale, save_run
from weakgrid.study.runner import Run, RunRecord


def Scenario(sid, case, load, upqc, controller, t_on, t_off, t_end):
    return Run(sid, case, "sc", load, upqc, controller, t_end,
               ({"kind": "fault", "bus": 3, "t_on": t_on, "t_off": t_off, "rf": 0.0,
                 "xf": 0.1},), ((t_on, t_off),))


C1 = "case1-weak-grid"


def _rec(sc):
    t = np.linspace(0, 1, 11)
    tk = np.linspace(0, 1, 4)
    return RunRecord(sc, {"id": sc.id, "failed": False, "settling": float("nan")},
                     {"t": t, "speed": np.sin(t)}, {"note": "x"},
                     samples={"tk": tk, "running_cost": tk**2, "x_design[0]": tk,
                              "x_design[1]": -tk})


def test_a_finished_run_round_trips_and_a_changed_input_is_redone(tmp_path):
    sc = Scenario("a", C1, "high", "conventional", "pq", 0.2, 0.25, 1.0)
    key = inputs_key(scenario=sc.to_dict())
    save_run(_rec(sc), tmp_path, key)
    got = load_run(tmp_path, sc, key, RunRecord)
    assert got is not None and np.isnan(got.metrics["settling"])
    np.testing.assert_array_equal(got.sample("x_design"), _rec(sc).sample("x_design"))
    np.testing.assert_array_equal(got.samples["tk"], np.linspace(0, 1, 4))
    np.testing.assert_array_equal(got.series["speed"], np.sin(np.linspace(0, 1, 11)))
    longer = Scenario("a", C1, "high", "conventional", "pq", 0.2, 0.25, 2.0)
    assert inputs_key(scenario=longer.to_dict()) != key
    assert load_run(tmp_path, longer, inputs_key(scenario=longer.to_dict()), RunRecord) is None
    (tmp_path / "a.parquet").unlink()  # an incomplete run is redone
    assert load_run(tmp_path, sc, key, RunRecord) is None


def test_stale_runs_of_an_earlier_plan_are_removed_with_a_warning(tmp_path):
    for sid in ("keep", "old"):
        sc = Scenario(sid, C1, "high", "conventional", "pq", 0.2, 0.25, 1.0)
        save_run(_rec(sc), tmp_path, "k")
    Manifest(tmp_path).claim(tmp_path.iterdir(), force=True)   # the files weakgrid wrote
    (tmp_path / "mine.json").write_text("{}")          # the user's: never removed
    said = []
    assert remove_stale(tmp_path, ["keep"], said.append) == ["old"]
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        MANIFEST_NAME, "keep.json", "keep.parquet", "mine.json"]
    assert "stale" in said[0] and "old" in said[0]
    assert remove_stale(tmp_path, ["keep"], said.append) == []


def test_a_forged_or_edited_record_is_refused_with_a_warning(tmp_path, caplog):
    import json
    import logging

    sc = Scenario("f", C1, "high", "conventional", "pq", 0.2, 0.25, 1.0)
    key = inputs_key(scenario=sc.to_dict())
    save_run(_rec(sc), tmp_path, key)
    assert load_run(tmp_path, sc, key, RunRecord) is not None
    p = tmp_path / "f.json"
    good = p.read_text()
    d = json.loads(good)
    d["metrics"]["failed"] = True                # a well-formed record with another result
    p.write_text(json.dumps(d))
    with caplog.at_level(logging.WARNING, logger="weakgrid"):
        assert load_run(tmp_path, sc, key, RunRecord) is None
    assert any("checksum" in r.getMessage() for r in caplog.records)
    p.write_text(good)                           # the signals edited: refused as well
    import pandas as pd
    df = pd.read_parquet(tmp_path / "f.parquet")
    df["speed"] *= 2
    df.to_parquet(tmp_path / "f.parquet")
    assert load_run(tmp_path, sc, key, RunRecord) is None


def test_a_forged_sweep_record_is_refused_and_run_again(tmp_path, caplog):
    import json
    import logging

    from weakgrid.sweep import expand, run_sweep

    pts = expand({"x": 1.0}, {"x": [1.0, 2.0]})
    t1 = run_sweep(pts, _double, cache_dir=tmp_path, workers=0, progress=False)
    rec_path = tmp_path / f"{t1['key'][0]}.json"
    d = json.loads(rec_path.read_text())
    d["metrics"]["v"] = 99.0
    rec_path.write_text(json.dumps(d))
    with caplog.at_level(logging.WARNING, logger="weakgrid"):
        t2 = run_sweep(pts, _double, cache_dir=tmp_path, workers=0, progress=False)
    assert list(t2["v"]) == [2.0, 4.0]           # recomputed, not the forged 99
    assert any("checksum" in r.getMessage() for r in caplog.records)


def _double(inputs):
    return {"v": 2.0 * inputs["x"]}
