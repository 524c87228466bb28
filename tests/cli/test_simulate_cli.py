"""`weakgrid simulate STUDY`: clear errors for what a study does not have."""

from weakgrid.cli.main import main


def test_pq_baseline_is_refused_for_an_sg_study(capsys, tmp_path):
    # case 2 compares hji, lqr, pss-only: pq is not one of its controllers
    assert main(["simulate", "case2-lv-microgrid", "--scenario", "c2-high-f100",
                 "--controller", "pq"]) == 2
    err = capsys.readouterr().err
    assert "controller" in err and "pq" in err and "controllers.compare" in err


def test_unknown_scenario_is_refused(capsys):
    assert main(["simulate", "case1-weak-grid", "--scenario", "nope"]) == 2
    err = capsys.readouterr().err
    assert "--scenario" in err and "c1-high-conv" in err


def test_list(capsys):
    assert main(["simulate", "case1-weak-grid", "--list"]) == 0
    out = capsys.readouterr().out
    assert "c1-high-conv" in out and "nonlinear-29" in out
