"""`weakgrid simulate`: a clear error for a combination a case does not have."""

from weakgrid.cli.main import main


def test_pq_baseline_is_refused_for_case2(capsys):
    assert main(["simulate", "case2-lv-microgrid", "--controller", "pq"]) == 2
    err = capsys.readouterr().err
    assert "variant" in err and "pq" in err


def test_reduced_upqc_is_refused_for_case2(capsys):
    assert main(["simulate", "case2-lv-microgrid", "--upqc", "reduced"]) == 2
    assert "reduced" in capsys.readouterr().err
