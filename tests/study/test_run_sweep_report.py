"""`weakgrid run` says what it runs (the runs, the sweep's size) before it runs it, and a study's
sweep appears in the report (a table of its runs; its maps when the study draws some)."""

from __future__ import annotations

import copy
import math
import re

import pandas as pd
import pytest

from weakgrid.study.engine import run_studies
from weakgrid.study.studyfile import load_study, study_from_dict

EV = "scenarios.c1-high-conv.events.0"


def tiny_case1(sweep):
    """Case 1 cut to one scenario and the PSS-only baseline, 0.4-s runs, with ``sweep``."""
    st = load_study("case1-weak-grid")
    d = copy.deepcopy(st.data)
    sc = next(s for s in d["scenarios"] if s["id"] == "c1-high-conv")
    sc.update(controllers=["pss-only"], t_end=0.4, quick={"t_end": 0.4})
    d["scenarios"] = [sc]
    d["claims"], d["figures"] = [], []
    d["sweep"] = sweep
    return study_from_dict(d, source=st.source, base_dir=st.base_dir)


@pytest.mark.slow
def test_quick_run_announces_and_reports_its_sweep(tmp_path):
    st = tiny_case1({"scenarios": ["c1-high-conv"], "controllers": ["pss-only"], "t_end": 0.4,
                     "axes": {"upqc.rating": [0.1, 0.2, 0.3], f"{EV}.duration": [0.02]},
                     "quick": {"axes": {"upqc.rating": [0.1, 0.3],
                                        f"{EV}.duration": [0.02, 0.05]}}})
    said = []
    out = run_studies([st], tmp_path, quick=True, log=said.append, progress=False, workers=0)
    first = said[:2]       # before anything runs: the runs, then the sweep and where it goes
    assert first[0] == ("case1-weak-grid: 1 run (--quick: each scenario's quick settings): "
                        "c1-high-conv-pss-only")
    assert "[sweep.quick], 4 runs: upqc.rating (2) × " + f"{EV}.duration (2)" in first[1]
    assert 'the report\'s section "Sweep of case1-weak-grid"' in first[1]
    assert "sweep-quick.parquet" in first[1]
    table = pd.read_parquet(tmp_path / "sweep-quick.parquet")
    assert len(table) == 4 and (table["status"] == "ok").all()
    page = (tmp_path / "report.html").read_text(encoding="utf-8")
    sec = page[page.index("<h2>Sweep of case1-weak-grid</h2>"):]
    sec = sec[:sec.index("</details>")]
    assert "<details open>" in sec                       # no map drawn: the table is the result
    assert "4 runs</summary>" in sec and "sweep-quick.parquet" in sec
    rows = re.findall(r"<tr><td>(.*?)</td><td>(.*?)</td>", sec)
    assert sorted((float(a), float(b)) for a, b in rows) == \
        [(0.1, 0.02), (0.1, 0.05), (0.3, 0.02), (0.3, 0.05)]
    assert "speed peak dev. [pu]" in sec
    # the sweep's own values are in the table: a longer fault swings the SG more
    peak = table.set_index(["upqc.rating", f"{EV}.duration"])["speed_peak_dev_pu"]
    assert peak[(0.1, 0.05)] > peak[(0.1, 0.02)]
    assert out["sweep"] is not None and len(out["sweep"]) == 4


@pytest.mark.slow
def test_maps_runs_fill_the_workers_while_the_scenario_runs_end(tmp_path):
    """On a cluster, the maps' runs are submitted with the scenario runs (below them in
    priority): a worker with no scenario run left goes on with the maps instead of idling
    until the last scenario run ends (before, the maps started only then, after their
    estimate's probe). Checked on Dask's task stream of 2 workers and one scenario run."""
    from distributed import Client, LocalCluster, get_task_stream

    st = tiny_case1({"scenarios": ["c1-high-conv"], "controllers": ["pss-only"], "t_end": 0.4,
                     "axes": {"upqc.rating": [0.1, 0.2, 0.3, 0.4], f"{EV}.duration": [0.02]}})
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, Client(cluster) as client:
        with get_task_stream(client) as ts:
            out = run_studies([st], tmp_path, log=lambda s: None, progress=False,
                              scheduler=cluster.scheduler_address)
    span = {}
    for task in ts.data:
        kind = "maps" if task["key"].startswith("weakgrid-run-") else "scenario"
        for s in task["startstops"]:
            if s["action"] == "compute":
                lo, hi = span.get(kind, (math.inf, -math.inf))
                span[kind] = (min(lo, s["start"]), max(hi, s["stop"]))
    assert set(span) == {"maps", "scenario"}
    assert span["maps"][0] < span["scenario"][1]     # a map run began before the scenario ended
    assert len(out["sweep"]) == 4 and (out["sweep"]["status"] == "ok").all()
    assert (tmp_path / "runs" / "c1-high-conv-pss-only.parquet").exists()
