"""End to end: `weakgrid reproduce --quick` writes every file, and the files are sound."""

import json
import re
import xml.etree.ElementTree as ET

import matplotlib.image as mpimg
import pandas as pd
import pytest

from weakgrid.cli.main import main
from weakgrid.study.figures import figure_specs, panel_label
from weakgrid.study.report import COLUMNS
from weakgrid.study.reproduce import paper_studies

pytestmark = pytest.mark.slow


FIGURES = [(f["id"], f["title"], [(k, panel_label(k, f.get("machine"))) for k in f["panels"]],
            f["runs"])
           for st in paper_studies() for f in figure_specs(st, quick=True)]
RUN_IDS = [f"{sc['id']}-{c}" for st in paper_studies() for sc, c in st.runs(quick=True)]


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
    assert len(FIGURES) == 18 and len(RUN_IDS) == 12
    for rid in RUN_IDS:
        assert (output / "runs" / f"{rid}.parquet").exists()
        assert json.loads((output / "runs" / f"{rid}.json").read_text())["metrics"]["id"] == rid


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
    ids = RUN_IDS
    assert sorted(df["id"]) == sorted(ids)
    for key, _ in COLUMNS:
        assert key in df.columns
    md = (output / "metrics.md").read_text()
    assert all(i in md for i in ids)


def test_report_has_a_verdict_per_claim(output):
    claims = json.loads((output / "claims.json").read_text())["claims"]
    assert len(claims) == sum(len(st.data["claims"]) for st in paper_studies()) == 11
    assert all(c["verdict"] in ("reproduced", "partly", "tie", "not", "not run") for c in claims)
    html = (output / "report.html").read_text()
    assert all(c["id"] in html for c in claims)
    # the design models with their mode check, for both studies
    designs = json.loads((output / "designs.json").read_text())["designs"]
    assert {d["case"] for d in designs} == {"case1-weak-grid", "case2-lv-microgrid"}
    for d in designs:
        assert d["mode_check"]["ok"], d["modes"]     # within 5 % on the paper's grids


def test_report_is_self_contained_and_has_the_maps(output):
    html = (output / "report.html").read_text()
    refs = re.findall(r"""(?:src|href)\s*=\s*['"]([^'"]*)['"]""", html)
    assert refs and all(r.startswith("data:") for r in refs)      # no file outside the page
    assert "Where the claims hold" in html and "Protocol" in html
    table = pd.read_parquet(output / "sweep-quick.parquet")
    assert set(table["scenario"]) == {"c1-high-conv", "c2-high-f100"}
    for col in ("clip_fraction", "u_demanded_peak_pu", "omega_reach", "status", "failure",
                "wall_s", "upqc.rating"):
        assert col in table
    for st in paper_studies():
        for m in st.data["sweep"]["maps"]:
            assert (output / "maps" / f"map-{st.name}-{m.get('id', m['claim'])}.png").stat().st_size > 1000


def test_the_maps_drawn_on_the_cluster_are_those_drawn_here(output, tmp_path):
    """`reproduce` draws each study's maps on a worker of its local cluster
    (`weakgrid.study.engine._draw_maps_of`): the same images as drawn in this process, and the
    results come back in the studies' order."""
    from weakgrid.study.engine import _draw_maps_of
    from weakgrid.sweep import open_client

    studies = paper_studies()
    table = pd.read_parquet(output / "sweep-quick.parquet")
    tables = [table[table["scenario"].isin(st.data["sweep"]["scenarios"])]
              .dropna(axis=1, how="all") for st in studies]
    here = _draw_maps_of(studies, tables, tmp_path / "here", True)
    with open_client(None, 2) as client:
        there = _draw_maps_of(studies, tables, tmp_path / "there", True, client)
    assert len(here) == len(there) == 2
    for st, a, b in zip(studies, here, there):
        assert [m["spec"] for m in a] == [m["spec"] for m in b] == st.data["sweep"]["maps"]
        for ma, mb in zip(a, b):
            assert ma["path"].name == mb["path"].name and st.name in mb["path"].name
            assert ma["path"].read_bytes() == mb["path"].read_bytes()
            assert (output / "maps" / mb["path"].name).read_bytes() == mb["path"].read_bytes()
            pd.testing.assert_frame_equal(ma["cells"], mb["cells"])
