"""`weakgrid gamma` on a preset: prints γ*, the bracket and the history; writes files."""

import json


import weakgrid
from weakgrid.cli.main import main
from weakgrid.game.gamma_search import worst_case_rollout_check
from weakgrid.models import load_controller, load_preset


def test_gamma_preset_writes_controller_and_report(tmp_path, capsys):
    out, rep = tmp_path / "c2.json", tmp_path / "r.json"
    assert main(["gamma", "--preset", "case2-paper", "--rtol", "0.05", "--rollout-steps", "1500",
                 "-o", str(out), "--report", str(rep)]) == 0
    text = capsys.readouterr().out
    assert "gamma* =" in text and "bracket" in text and "accepted" in text
    r = json.loads(rep.read_text())
    assert r["weakgrid_version"] == weakgrid.__version__
    assert r["parameters"]["rtol"] == 0.05 and r["problem"] == "case2-paper"
    lo, hi = r["bracket"]
    assert r["linear_limit"] <= lo < hi <= load_preset("case2-paper").cost.gamma
    assert (hi - lo) <= 0.05 * hi
    hist = r["history"]
    assert hi == min(t["gamma"] for t in hist if t["accepted"])
    assert all(t["gamma"] < hi for t in hist if not t["accepted"])
    assert all(t["reason"] for t in hist)
    # the written controller is the one at γ* and satisfies the acceptance conditions
    ctl = load_controller(out)
    assert ctl.cost.gamma == hi
    mesh = load_preset("case2-paper").mesh
    _, ew = ctl.block_eigenvalues(mesh.points)
    assert ew.max() < 0
    ok, final, _ = worst_case_rollout_check(ctl, mesh, 1500)
    assert ok and final <= 0.05
    # below the bracket's lower end the preset's own start is rejected
    assert any(not t["accepted"] for t in hist)


def test_gamma_bad_option_is_reported(capsys):
    assert main(["gamma", "--preset", "case1-paper", "--rtol", "2"]) == 2
    err = capsys.readouterr().err
    assert "rtol" in err and "(0, 1)" in err
