"""End to end: `weakgrid reproduce --quick` writes every file, and the files are sound."""

import json
import re
import xml.etree.ElementTree as ET

import matplotlib.image as mpimg
import pandas as pd
import pytest

from weakgrid.cli.main import main
from weakgrid.study.figures import FIGURES
from weakgrid.study.report import COLUMNS
from weakgrid.study.scenarios import paper_scenarios

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def output(tmp_path_factory):
    out = tmp_path_factory.mktemp("reproduce")
    assert main(["reproduce", "--quick", "--output", str(out)]) == 0
    return out


def test_every_file_is_written(output):
    for fig_id, *_ in FIGURES:
        assert (output / "figures" / f"{fig_id}.png").stat().st_size > 1000
        assert (output / "figures" / f"{fig_id}.svg").stat().st_size > 1000
    for name in ("metrics.csv", "metrics.md", "report.html", "claims.json"):
        assert (output / name).stat().st_size > 100
    for sc in paper_scenarios(quick=True):
        assert (output / "runs" / f"{sc.id}.parquet").exists()
        assert json.loads((output / "runs" / f"{sc.id}.json").read_text())["metrics"]["id"] == sc.id


def test_figures_are_valid_and_labelled(output):
    for fig_id, title, panels, _ in FIGURES:
        img = mpimg.imread(output / "figures" / f"{fig_id}.png")
        assert img.ndim == 3 and img.shape[0] > 200 and img.shape[1] > 300
        root = ET.parse(output / "figures" / f"{fig_id}.svg").getroot()
        texts = " ".join(t for t in root.itertext())
        assert "time [s]" in texts
        for _, ylabel in panels:
            assert ylabel in texts
            assert re.search(r"\[[^\]]+\]", ylabel)  # every axis names its unit


def test_table_holds_every_metric_for_every_run(output):
    df = pd.read_csv(output / "metrics.csv")
    ids = [s.id for s in paper_scenarios(quick=True)]
    assert sorted(df["id"]) == sorted(ids)
    for key, _ in COLUMNS:
        assert key in df.columns
    md = (output / "metrics.md").read_text()
    assert all(i in md for i in ids)


def test_report_has_a_verdict_per_claim(output):
    claims = json.loads((output / "claims.json").read_text())["claims"]
    assert len(claims) == 8
    assert all(c["verdict"] in ("reproduced", "partly", "not", "not run") for c in claims)
    html = (output / "report.html").read_text()
    assert all(c["id"] in html for c in claims)
