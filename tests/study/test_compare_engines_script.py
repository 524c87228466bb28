"""scripts/compare_engines.py: the side-by-side of one study's run folders from several engines.

Synthetic run folders (a metrics.csv, a claims.json, one run file each): the table carries
every engine's value with its difference from the reference, a folder still under way is read
from its runs' json metrics, the claims are side by side, a figure per scenario is written.
"""

import importlib.util
import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from weakgrid.sim.results import Results
from weakgrid.sim.runfile import write_run

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "compare_engines.py"


@pytest.fixture(scope="module")
def ce():
    spec = importlib.util.spec_from_file_location("compare_engines", SCRIPT)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _folder(root: Path, name: str, speed_peak: float, verdict: str, csv: bool = True) -> Path:
    f = root / name
    (f / "runs").mkdir(parents=True)
    row = {"id": "s1-hji", "controller": "hji", "speed_peak_dev_pu": speed_peak,
           "vu_peak_pu": 0.1, "running_cost_18": 2.0 * speed_peak, "failed": False}
    if csv:
        pd.DataFrame([row]).to_csv(f / "metrics.csv", index=False)
        (f / "claims.json").write_text(json.dumps({"claims": [
            {"id": "C-x", "paper": "a claim", "verdict": verdict, "measured": ""}]}))
    (f / "runs" / "s1-hji.json").write_text(json.dumps({"metrics": row}))
    t = np.linspace(0.0, 1.0, 11)
    data = np.column_stack([1.0 + speed_peak * np.sin(t), 0.1 * t])
    write_run(f / "runs" / "s1-hji.parquet",
              Results(t, ["SG.omega", "U.Vu"], data, ["pu", "pu"], [1.0, 1.0]))
    return f


def test_table_claims_and_figure(ce, tmp_path):
    a = _folder(tmp_path, "ph", 0.02, "not")
    b = _folder(tmp_path, "dp", 0.015, "tie")
    c = _folder(tmp_path, "emt", 0.5, "", csv=False)        # still under way: json only
    out = tmp_path / "out"
    assert ce.main([str(out), "x", "--run", f"phasor={a}", "--run", f"DP={b}",
                    "--run", f"EMT={c}", "--metrics", "speed_peak_dev_pu,vu_peak_pu"]) == 0
    md = (out / "x-metrics.md").read_text()
    assert "| s1-hji | DP | 0.015 (-25 %) | 0.1 (+0 %) |" in md
    assert "| s1-hji | EMT | 0.5 (×25) |" in md
    assert "running cost" not in md                       # --metrics picked the columns
    long = pd.read_csv(out / "x-metrics.csv")
    dp = long[(long.engine == "DP") & (long.metric == "speed_peak_dev_pu")]
    assert dp.rel_diff.iloc[0] == pytest.approx(-0.25)
    claims = (out / "x-claims.md").read_text()
    assert "| C-x | a claim | not | tie | – |" in claims
    assert (out / "x-s1.png").stat().st_size > 0


def test_bad_arguments_are_refused_by_name(ce, tmp_path):
    a = _folder(tmp_path, "ph", 0.02, "not")
    with pytest.raises(SystemExit, match="LABEL=FOLDER"):
        ce.main([str(tmp_path / "o"), "x", "--run", str(a)])
    with pytest.raises(SystemExit, match="no metrics.csv and no finished run"):
        ce.main([str(tmp_path / "o"), "x", "--run", f"p={a}", "--run", f"q={tmp_path}"])
    with pytest.raises(SystemExit, match="--metrics: unknown"):
        ce.main([str(tmp_path / "o"), "x", "--run", f"p={a}", "--metrics", "nope"])


def test_peak_of_a_signal_from_the_run_files(ce, tmp_path):
    """--peak SIGNAL: max |y − y(0)| over each engine's run file, with its difference from the
    reference; a signal a run does not have is '–' (and a figure panel says so)."""
    a = _folder(tmp_path, "ph", 0.02, "not")
    b = _folder(tmp_path, "emt", 0.01, "tie")
    out = tmp_path / "out"
    assert ce.main([str(out), "x", "--run", f"phasor={a}", "--run", f"EMT={b}",
                    "--metrics", "speed_peak_dev_pu", "--peak", "SG.omega",
                    "--peak", "U.Vdc"]) == 0
    md = (out / "x-metrics.md").read_text()
    assert "SG.omega peak dev [pu] | U.Vdc peak dev [pu] |" in md
    # 1 + p sin(t) on [0, 1]: the largest deviation p sin(1)
    assert f"| s1-hji | phasor | 0.02 | {0.02 * np.sin(1.0):.4g} | – |" in md
    assert f"| s1-hji | EMT | 0.01 (-50 %) | {0.01 * np.sin(1.0):.4g} (-50 %) | – |" in md
