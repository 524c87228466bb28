"""Sweeps of studies: [sweep] tables, `weakgrid sweep` (Dask, resume, scheduler address),
failures as rows, maps of where a claim holds, and the self-contained HTML report."""

from __future__ import annotations

import math
import os
import re
import signal
import subprocess
import sys
import time
from importlib import resources
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from weakgrid.cli.main import main
from weakgrid.game.errors import ParameterError
from weakgrid.study.report import write_html
from weakgrid.study.studyfile import get_path, load_study, set_path, study_from_dict
from weakgrid.study.sweep import run_point, sweep_points
from weakgrid.study.sweep_maps import map_cells
from weakgrid.sweep import expand, run_sweep


def _sigint_default():
    """In the child: Ctrl-C acts, even when this test runs in a background job (which starts
    its children with SIGINT ignored, so that Python would install no KeyboardInterrupt)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)

MARKER = "# ------------------------------------------------------------------ where the claims hold"

SMALL_SWEEP = """
[sweep]
mode = "product"
scenarios = ["c1-high-conv"]
controllers = ["nonlinear-29"]
t_end = T_END
[sweep.axes]
"upqc.rating" = RATINGS
"scenarios.c1-high-conv.events.0.bus" = [3, 99]
"""


INTERRUPT_SWEEP = """
[sweep]
mode = "points"
scenarios = ["c1-high-conv"]
controllers = ["nonlinear-29"]
t_end = 1.5
[sweep.axes]
"upqc.rating" = [0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3]
"scenarios.c1-high-conv.events.0.bus" = [3, 3, 3, 3, 3, 3, 99, 99, 99, 99, 99, 99]
"scenarios.c1-high-conv.events.0.t_off" = [0.25, 0.25, 0.25, 0.25, 0.25, 0.25, 0.3, 0.3, 0.3, 0.3, 0.3, 0.3]
"""


def _small_study(tmp_path, ratings=(0.05, 0.1, 0.15, 0.2, 0.25, 0.3), t_end=0.35) -> Path:
    """Case 1 with a small sweep: ratings × {bus 3, a bus that does not exist (fails)}."""
    src = resources.files("weakgrid") / "data" / "studies" / "case1-weak-grid.toml"
    text = src.read_text(encoding="utf-8")
    text = text[: text.index(MARKER)] + SMALL_SWEEP.replace("RATINGS", str(list(ratings))).replace(
        "T_END", str(t_end))
    p = tmp_path / "small.toml"
    p.write_text(text, encoding="utf-8")
    return p


def _tab(df):
    return df.drop(columns=[c for c in ("wall_s", "sim_wall_s", "traceback_tail")
                            if c in df]).reset_index(drop=True)


def test_expand_uses_the_studys_paths():
    st = load_study("case1-weak-grid")
    pts = expand(st.data, {"scenarios.c1-low-conv.load": ["high"], "upqc.rating": [0.3, 0.6]},
                 getter=get_path, setter=set_path)
    assert [p.params["upqc.rating"] for p in pts] == [0.3, 0.6]
    for p in pts:   # a list element addressed by its id, not by its position
        assert get_path(p.inputs, "scenarios.c1-low-conv.load") == "high"
        assert p.inputs["scenarios"][2]["id"] == "c1-low-conv"
        assert p.inputs["scenarios"][2]["load"] == "high"
    assert st.data["scenarios"][2]["load"] == "low"   # the base is not modified


def test_sweep_points_of_a_shipped_study():
    st = load_study("case1-weak-grid")
    sw = st.data["sweep"]
    pts = sweep_points(st)
    n = math.prod(len(v) for v in sw["axes"].values()) * len(sw["controllers"])
    chk = sw["dt_check"]                                 # these points again at T/2
    n_half = math.prod(len(chk.get(k, v)) for k, v in sw["axes"].items()) * \
        len(sw["controllers"])
    assert len(pts) == n + n_half and n_half > 0
    half = [p for p in pts if p.params["dt_factor"] == 0.5]
    assert len(half) == n_half
    assert all(p.params[k] in v for p in half for k, v in chk.items())
    p = pts[0]
    assert p.inputs["scenario"] == "c1-high-conv" and p.inputs["design_load"] == "high"
    assert get_path(p.inputs["study"], "upqc.rating") == p.params["upqc.rating"]
    quick = sweep_points(st, quick=True)
    assert len(quick) < len(pts) and all(q.params["dt_factor"] == 1.0 for q in quick)


def test_run_cost_ranks_longer_runs_first():
    """The cost that orders a sweep's runs grows with the simulated time, the fault's duration
    and a halved step (twice the steps), and not with what does not change the work."""
    from weakgrid.study.sweep_estimate import run_cost

    st = load_study("case1-weak-grid")
    pts = sweep_points(st)
    base = next(p for p in pts if p.params["dt_factor"] == 1.0)
    half = next(p for p in pts if p.params["dt_factor"] == 0.5)
    c = run_cost(base.inputs)
    assert run_cost(half.inputs) == pytest.approx(2 * run_cost(dict(half.inputs, dt_factor=1.0)),
                                                  rel=1e-3)
    assert run_cost(dict(base.inputs, t_end=2 * base.inputs["t_end"])) > c
    by_fault = {}
    for p in pts:
        if p.params["dt_factor"] == 1.0:
            by_fault.setdefault(p.params["scenarios.c1-high-conv.events.0.t_off"], set()).add(
                run_cost(p.inputs))
    assert all(len(v) == 1 for v in by_fault.values())   # the rating, the load: same cost
    costs = [by_fault[t].pop() for t in sorted(by_fault)]
    assert costs == sorted(costs) and costs[0] < costs[-1]


@pytest.mark.parametrize("path, word", [("upqc.ratin", "ratin"),
                                        ("scenarios.nope.load", "nope")])
def test_bad_sweep_axis_names_the_field(path, word):
    st = load_study("case1-weak-grid")
    d = dict(st.data, sweep=dict(st.data["sweep"], axes={path: [1.0]}))
    with pytest.raises(ParameterError, match=word):
        study_from_dict(d)


def test_failing_run_is_a_row_with_its_cause(tmp_path):
    st = load_study(_small_study(tmp_path))
    pts = [p for p in sweep_points(st) if p.params["upqc.rating"] in (0.15, 0.3)]
    table = run_sweep(pts, run_point, cache_dir=tmp_path / "c", workers=0, progress=False)
    assert len(table) == 4
    bad = table[table["scenarios.c1-high-conv.events.0.bus"] == 99]
    good = table[table["scenarios.c1-high-conv.events.0.bus"] == 3]
    assert (bad["status"] == "failed").all() and (good["status"] == "ok").all()
    assert bad["failure"].str.contains("99").all()          # the cause names the bad value
    assert np.isfinite(good["control_cost"]).all() and (good["control_cost"] > 0).all()
    # the rating bounds what is applied, not what is demanded
    assert (good["u_applied_peak_pu"] <= good["upqc.rating"] + 1e-12).all()
    assert (good["u_demanded_peak_pu"] >= good["u_applied_peak_pu"]).all()


def test_sweep_against_a_scheduler_address_gives_the_default_table(tmp_path):
    from distributed import LocalCluster

    study = _small_study(tmp_path, ratings=(0.1, 0.15))
    assert main(["sweep", str(study), "--workers", "0", "-o", str(tmp_path / "serial"),
                 "--no-progress"]) == 0
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster:
        assert main(["sweep", str(study), "--scheduler", cluster.scheduler_address,
                     "-o", str(tmp_path / "remote"), "--no-progress"]) == 0
    a = pd.read_parquet(tmp_path / "serial" / "case1-weak-grid-sweep.parquet")
    b = pd.read_parquet(tmp_path / "remote" / "case1-weak-grid-sweep.parquet")
    assert len(a) == 4
    assert list(a["status"] == "failed") == list(a["scenarios.c1-high-conv.events.0.bus"] == 99)
    pd.testing.assert_frame_equal(_tab(a), _tab(b))


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_weakgrid_sweep_interrupted_and_restarted_completes_the_same_table(tmp_path, sig):
    # runs long enough (1.5 s simulated each) that the signal lands while some still run,
    # however loaded the machine is. A batch's records are written when it ends, so the 6
    # failing runs (bus 99) get another clearing time, hence a batch of their own, which
    # ends first (their preparation fails); two batches of 3 and 3 ended within 40 ms of
    # each other once, and the signal found nothing left to interrupt.
    study = _small_study(tmp_path, t_end=1.5)
    text = study.read_text(encoding="utf-8")
    study.write_text(text[: text.rindex("\n[sweep]\n")] + INTERRUPT_SWEEP, encoding="utf-8")
    out = tmp_path / "out"
    cache = out / "cache"
    cmd = [sys.executable, "-m", "weakgrid.cli.main", "sweep", str(study), "-o", str(out),
           "--workers", "2", "--no-progress"]
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    p = subprocess.Popen(cmd, preexec_fn=_sigint_default, env=env, stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE,
                         text=True)
    t0 = time.time()
    while len(list(cache.glob("*.json"))) < 2 and time.time() - t0 < 180:
        time.sleep(0.05)
    p.send_signal(sig)
    stdout, err = p.communicate(timeout=180)
    assert p.returncode == 130, (stdout, err)
    assert "interrupted" in stdout and "Traceback" not in err
    done = {q.name: q.stat().st_mtime_ns for q in cache.glob("*.json")}
    assert 2 <= len(done) < 12
    p2 = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300)
    assert p2.returncode == 0, p2.stderr
    assert f"{len(done)} already done" in p2.stdout + p2.stderr
    # no finished run ran again: its cached record is untouched
    assert {q.name: q.stat().st_mtime_ns for q in cache.glob("*.json") if q.name in done} == done
    resumed = pd.read_parquet(out / "case1-weak-grid-sweep.parquet")
    assert main(["sweep", str(study), "--workers", "0", "-o", str(tmp_path / "ref"),
                 "--no-progress"]) == 0
    ref = pd.read_parquet(tmp_path / "ref" / "case1-weak-grid-sweep.parquet")
    pd.testing.assert_frame_equal(_tab(resumed), _tab(ref))


def _cells_table():
    """A synthetic sweep table: 2 ratings × 1 duration × 1 load, controllers a and b, plus the
    dt-halving repeat of rating 0.1."""
    rows = []
    def row(r, c, cost, dt=1.0, status="ok"):
        rows.append({"scenario": "s", "upqc.rating": r, "t_off": 0.25, "load": "high",
                     "controller": c, "dt_factor": dt, "status": status, "cost": cost})
    row(0.1, "a", 1.00)
    row(0.1, "b", 1.02)          # 2 % apart ...
    row(0.1, "a", 1.03, 0.5)     # ... while halving the step moves a by 3 %: a tie
    row(0.1, "b", 1.02, 0.5)
    row(0.3, "a", 0.50)
    row(0.3, "b", 1.00)          # 50 % less, far beyond the uncertainty: holds
    row(0.5, "a", 0.01, status="failed")
    row(0.5, "b", 1.00)
    return pd.DataFrame(rows)


def test_map_cells_ties_wins_and_failures():
    spec = {"claim": "X", "kind": "ratio", "metric": "cost", "a": "a", "b": "b",
            "holds_below": 0.8}
    cells = map_cells(_cells_table(), spec, ["upqc.rating", "t_off", "load"])
    v = dict(zip(cells["upqc.rating"], cells["verdict"]))
    # a failed where b finished: a loss, counted as "not" (it was "failed" only); at 0.1 the
    # ratio 0.98 is within the 3 % uncertainty of 1 but far above the threshold 0.8: not
    assert v == {0.1: "not", 0.3: "holds", 0.5: "not"}
    # against the claim's threshold 1 the same cell is a tie
    c1 = map_cells(_cells_table(), dict(spec, holds_below=1.0), ["upqc.rating", "t_off", "load"])
    assert dict(zip(c1["upqc.rating"], c1["verdict"]))[0.1] == "tie"
    val = dict(zip(cells["upqc.rating"], cells["value"]))
    assert val[0.3] == pytest.approx(0.5) and math.isnan(val[0.5])
    # without the dt check there is no uncertainty: 0.98 is then "not" (above 0.8)
    t = _cells_table()
    cells2 = map_cells(t[t["dt_factor"] == 1.0], spec, ["upqc.rating", "t_off", "load"])
    assert dict(zip(cells2["upqc.rating"], cells2["verdict"]))[0.1] == "not"


def test_a_ratio_tie_is_judged_against_the_claims_threshold():
    """A ratio within the runs' uncertainty of holds_below (0.8) is a tie, whatever its
    distance from 1; one within the uncertainty of 1 but not of 0.8 is not a tie."""
    t = _cells_table()
    t.loc[(t["upqc.rating"] == 0.1) & (t["controller"] == "a"), "cost"] = [0.81, 0.834]
    t.loc[(t["upqc.rating"] == 0.1) & (t["controller"] == "b"), "cost"] = 1.0
    spec = {"claim": "X", "kind": "ratio", "metric": "cost", "a": "a", "b": "b",
            "holds_below": 0.8}
    cells = map_cells(t, spec, ["upqc.rating", "t_off", "load"])
    c = cells[cells["upqc.rating"] == 0.1].iloc[0]
    # |0.81 − 0.8| = 0.01 ≤ 0.024 (step halving moves a by 0.024, 3 %): a tie at the threshold
    assert c["verdict"] == "tie" and c["value"] == pytest.approx(0.81)
    assert c["uncertainty"] == pytest.approx(0.024)        # in the ratio's units (b = 1)
    # 10 % below the threshold: holds, not a tie
    t.loc[(t["upqc.rating"] == 0.1) & (t["controller"] == "a"), "cost"] = [0.70, 0.721]
    c = map_cells(t, spec, ["upqc.rating", "t_off", "load"])
    assert dict(zip(c["upqc.rating"], c["verdict"]))[0.1] == "holds"


def test_a_ratio_maps_colours_turn_at_the_claims_threshold():
    """The diverging colour scale of a ratio map is centred where holds turns into not (its
    holds_below), not at a ratio of 1; a wins map's at 1; a value map has none."""
    from weakgrid.study.sweep_maps import colour_centre

    assert colour_centre({"kind": "ratio", "holds_below": 0.8}) == 0.8
    assert colour_centre({"kind": "ratio"}) == 1.0
    assert colour_centre({"kind": "wins"}) == 1.0
    assert colour_centre({"kind": "value"}) is None


def test_map_cell_without_value_has_a_reason_not_a_verdict():
    """A settling-time ratio where a finished run never settles: no value, no ✗, the reason."""
    t = _cells_table()
    t = t[(t["dt_factor"] == 1.0) & (t["upqc.rating"] == 0.3)].copy()
    t.loc[t["controller"] == "a", "cost"] = np.nan       # a finished but has no value
    spec = {"claim": "X", "kind": "ratio", "metric": "speed_settling_s", "a": "a", "b": "b"}
    t = t.rename(columns={"cost": "speed_settling_s"})
    cells = map_cells(t, spec, ["upqc.rating", "t_off", "load"])
    assert cells["verdict"].tolist() == [None]
    assert cells["note"].tolist() == ["a: no settling"]
    for kind in ("value", "stable"):
        c = map_cells(t, dict(spec, kind=kind, holds_within=[0, 1]),
                      ["upqc.rating", "t_off", "load"])
        assert c["note"].tolist() == ["a: no settling"]
        if kind == "value":
            assert c["verdict"].tolist() == [None]
    # a failed run: the note names it
    t2 = _cells_table()
    cells = map_cells(t2[t2["dt_factor"] == 1.0], dict(spec, metric="cost"),
                      ["upqc.rating", "t_off", "load"])
    assert dict(zip(cells["upqc.rating"], cells["note"]))[0.5] == "a failed: failed"


def test_report_is_one_self_contained_file(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    ax.plot([0, 1], [0, 1])
    png = tmp_path / "figs" / "f.png"
    png.parent.mkdir()
    fig.savefig(png)
    plt.close(fig)
    claims = [{"id": "C", "case": "c", "paper": "p", "rule": "r", "verdict": "partly",
               "measured": "m", "map_setting": "high: 1.04 (not)",
               "map_region": "holds at 0.3, 0.6"}]
    maps = [{"study": "s", "claim": "C", "title": "t", "at_setting": "1.04", "region": "r",
             "n_holds": 1, "n_cells": 2, "path": png}]
    report = write_html(tmp_path / "out" / "report.html", claims=claims,
                        metrics=[{"id": "r1", "control_cost": 0.1}], figures=[png],
                        designs=[], meta={"title": "t"}, maps=maps, protocol=["a change"])
    html = report.read_text()
    moved = tmp_path / "elsewhere.html"
    report.rename(moved)
    for p in png.parent.glob("*"):
        p.unlink()
    text = moved.read_text()
    assert text == html
    refs = re.findall(r"""(?:src|href)\s*=\s*['"]([^'"]*)['"]|url\(([^)]*)\)""", text)
    refs = [a or b for a, b in refs]
    assert len(refs) == 2 and all(r.startswith("data:image/png;base64,") for r in refs)
    assert "holds at 0.3, 0.6" in text and "a change" in text


def test_ratio_cell_where_only_the_baseline_fails_holds():
    """HJI settles while LQR loses synchronism: the ratio has no value, but the claim holds
    there (as for "wins"); the note and the region name the baseline's failure."""
    t = _cells_table()
    t = t[t["dt_factor"] == 1.0].copy()
    t.loc[(t["upqc.rating"] == 0.5) & (t["controller"] == "a"), "status"] = "ok"
    t.loc[(t["upqc.rating"] == 0.5) & (t["controller"] == "b"), "status"] = "failed"
    t["failure"] = np.where(t["status"] == "failed",
                            "t = 1.2 s: loss of synchronism: rotor angle spread 181 deg", "")
    spec = {"claim": "X", "kind": "ratio", "metric": "cost", "a": "a", "b": "b",
            "holds_below": 0.8}
    cells = map_cells(t, spec, ["upqc.rating", "t_off", "load"])
    c = cells[cells["upqc.rating"] == 0.5].iloc[0]
    assert c["verdict"] == "holds" and math.isnan(c["value"])
    assert c["note"] == "b failed: loss of synchronism" and "loss of synchronism" in c["detail"]
    from weakgrid.study.sweep_maps import map_summaries
    s = map_summaries([{"spec": spec, "cells": cells, "mark": None,
                        "axes": ("upqc.rating", "t_off", "load")}])[0]
    assert "0.5 (b failed: loss of synchronism)" in s["region"] and "0.3" in s["region"]


def _lost_table(kind_col="cost"):
    t = _cells_table()
    t = t[t["dt_factor"] == 1.0].copy()
    t["failure"] = np.where(t["status"] == "failed", "simulation stopped at t = 3.427 s: "
                            "loss of synchronism (rotor angle spread 181 deg)", "")
    return t


@pytest.mark.parametrize("kind", ["ratio", "wins"])
def test_an_hji_failure_where_the_baseline_survives_is_not(kind):
    """Losses are counted: a (HJI) loses synchronism at rating 0.5 while b finishes — the cell
    is "not (a failed: loss of synchronism)", no longer a neutral "failed"; both failing stays
    "failed"."""
    t = _lost_table()
    spec = {"claim": "X", "kind": kind, "metric": "cost", "metrics": ["cost"], "a": "a",
            "b": "b", "holds_below": 0.8}
    cells = map_cells(t, spec, ["upqc.rating", "t_off", "load"])
    c = cells[cells["upqc.rating"] == 0.5].iloc[0]
    assert c["verdict"] == "not" and math.isnan(c["value"])
    assert c["note"] == "a failed: loss of synchronism"
    from weakgrid.study.sweep_maps import map_summaries
    s = map_summaries([{"spec": spec, "cells": cells, "mark": None,
                        "axes": ("upqc.rating", "t_off", "load")}])[0]
    assert "not at 0.5 (a failed: loss of synchronism)" in s["region"]
    t.loc[t["upqc.rating"] == 0.5, "status"] = "failed"          # both fail: no comparison
    cells = map_cells(t, spec, ["upqc.rating", "t_off", "load"])
    assert cells[cells["upqc.rating"] == 0.5].iloc[0]["verdict"] == "failed"


def test_map_tie_within_the_metrics_definition_band():
    """Without any step-halving check, a 2 % difference in settling time is a tie when the
    settling time moves by 3 % with the band (1.5–3 %): the same rule as the claim table."""
    t = _cells_table()
    t = t[(t["dt_factor"] == 1.0) & (t["upqc.rating"] == 0.1)].copy()
    t = t.rename(columns={"cost": "speed_settling_s"})
    spec = {"claim": "X", "kind": "ratio", "metric": "speed_settling_s", "a": "a", "b": "b",
            "holds_below": 1.0}
    cells = map_cells(t, spec, ["upqc.rating", "t_off", "load"])
    assert cells["verdict"].tolist() == ["holds"]           # 1.00 < 1.02, no band: a win
    t["speed_settling_s_def_unc"] = np.where(t["controller"] == "a", 0.03, 0.0)
    cells = map_cells(t, spec, ["upqc.rating", "t_off", "load"])
    assert cells["verdict"].tolist() == ["tie"]
    assert cells["uncertainty"].iloc[0] == pytest.approx(0.03 / 1.02)
    w = map_cells(t, dict(spec, kind="wins", metrics=["speed_settling_s"]),
                  ["upqc.rating", "t_off", "load"])
    assert w["verdict"].tolist() == ["tie"]


def _diverged_table():
    """Rating 0.3 of the synthetic table, both runs finished; a's cost 50 % below b's."""
    t = _cells_table()
    t = t[(t["dt_factor"] == 1.0) & (t["upqc.rating"] == 0.3)].copy()
    t["failure"] = ""
    t["speed_verdict"] = "stable"
    t["vdc_verdict"] = "stable"
    return t


@pytest.mark.parametrize("kind", ["ratio", "wins"])
def test_map_cell_with_both_runs_diverged_is_no_comparison(kind):
    """Regression (stability first in the maps): both runs finished but their dc links ran
    away — main compared their costs (a win, ratio 0.5); now no value, 'no comparison'."""
    t = _diverged_table()
    spec = {"claim": "X", "kind": kind, "metric": "cost", "metrics": ["cost"], "a": "a",
            "b": "b", "holds_below": 0.8}
    axes = ["upqc.rating", "t_off", "load"]
    c = map_cells(t, spec, axes).iloc[0]
    assert c["verdict"] == "holds" and c["value"] == pytest.approx(0.5)     # both stable
    t["vdc_verdict"] = "unstable"
    c = map_cells(t, spec, axes).iloc[0]
    assert c["verdict"] == "no comparison" and math.isnan(c["value"])
    assert c["note"] == "both unstable: no comparison"
    assert "a not stable: dc link unstable" in c["detail"] and "b not stable" in c["detail"]
    from weakgrid.study.sweep_maps import map_summaries
    s = map_summaries([{"spec": spec, "cells": map_cells(t, spec, axes), "mark": None,
                        "axes": tuple(axes)}])[0]
    assert "no comparison (both runs unstable) at 0.3" in s["region"] and s["n_holds"] == 0


@pytest.mark.parametrize("kind", ["ratio", "wins"])
def test_map_cell_where_only_one_run_diverged(kind):
    """The claim's run unstable (a lower cost, but undamped): a loss, named; only the
    baseline unstable: holds without comparing, named."""
    t = _diverged_table()
    spec = {"claim": "X", "kind": kind, "metric": "cost", "metrics": ["cost"], "a": "a",
            "b": "b", "holds_below": 0.8}
    axes = ["upqc.rating", "t_off", "load"]
    t.loc[t["controller"] == "a", "speed_verdict"] = "undamped"
    c = map_cells(t, spec, axes).iloc[0]
    assert c["verdict"] == "not" and math.isnan(c["value"])
    assert c["note"] == "a not stable: SG speed undamped"
    t["speed_verdict"] = "stable"
    t.loc[t["controller"] == "b", "vdc_verdict"] = "unstable"
    c = map_cells(t, spec, axes).iloc[0]
    assert c["verdict"] == "holds" and c["note"] == "b not stable: dc link unstable"


def test_no_comparison_cell_is_drawn_with_its_mark(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    from weakgrid.study.maps import plot_map

    t = _diverged_table()
    t["vdc_verdict"] = "unstable"
    spec = {"claim": "X", "kind": "ratio", "metric": "cost", "a": "a", "b": "b"}
    cells = map_cells(t, spec, ["upqc.rating", "t_off", "load"])
    fig = plot_map(cells, "upqc.rating", "t_off", "value", verdict="verdict", note="note",
                   path=tmp_path / "m.png")
    texts = [tx.get_text() for ax in fig.axes for tx in ax.texts]
    assert any("n/c" in tx for tx in texts)
    assert any(getattr(p, "get_hatch", lambda: None)() for ax in fig.axes for p in ax.patches)
    assert "both runs unstable: no comparison" in fig.get_suptitle().replace("\n", " ")
