"""The shipped studies beyond the paper: the design model checked against the full grid's
mode, and the newcomer path (`weakgrid design`, then `weakgrid run --quick`) end to end."""

import json

import pandas as pd
import pytest
from shipped import shipped_params, skip_without_andes

from weakgrid.cli.main import main
from weakgrid.study.build import build_setup
from weakgrid.study.engine import _design_notes, mode_check
from weakgrid.study.studyfile import load_study

EXAMPLES = ["ieee9-sg-upqc", "cigre-mv-wind-gti"]


@pytest.mark.parametrize("name", shipped_params())
def test_design_mode_agrees_or_the_study_reports_the_mismatch(name):
    skip_without_andes(name)
    st = load_study(name)
    for load in st.loads:
        s = build_setup(st, load)
        chk = mode_check(s)
        # the grid's mode is the controlled machine's: most of it on the paper's grids; on a
        # multi-machine grid a mode shared with a neighbour (ieee39-g3-upqc: G3 shares its
        # 1.2 Hz mode with G6, participation 0.31, the mismatch reported as MISMATCH)
        least = 0.5 if st.data["study"]["reproduce"] else 0.25
        assert chk["grid_lambda"] is not None and chk["participation"] > least
        notes = _design_notes(st, s, chk)
        assert chk["ok"] == (chk["mismatch"] <= 0.05)
        assert chk["ok"] or any("MISMATCH" in n for n in notes)
        if st.data["study"]["reproduce"]:        # the paper's grids: within 5 %
            assert chk["ok"], (name, load, chk["mismatch"])


@pytest.mark.slow
@pytest.mark.parametrize("name", EXAMPLES)
def test_newcomer_path_design_then_run(name, tmp_path, capsys):
    ctl = tmp_path / "c.controller.json"
    assert main(["design", name, "-o", str(ctl)]) == 0
    out = capsys.readouterr().out
    assert "mode check" in out and "design model (10)" in out
    assert json.loads(ctl.read_text())["weights"]
    assert main(["run", name, "--quick", "-o", str(tmp_path / "run")]) == 0
    df = pd.read_csv(tmp_path / "run" / "metrics.csv")
    st = load_study(name)
    assert sorted(df["id"]) == sorted(f"{sc['id']}-{c}" for sc, c in st.runs(quick=True))
    assert not df["failed"].any()
    assert (tmp_path / "run" / "report.html").stat().st_size > 1000
