"""`weakgrid verify` on the presets: the report is produced and the gap is stated."""

import json

import numpy as np
import pytest

import weakgrid
from weakgrid.cli.main import main


@pytest.mark.parametrize("preset", ["case1-paper", "case2-paper"])
def test_verify_preset_report(preset, tmp_path, capsys):
    rep = tmp_path / "v.json"
    assert main(["verify", "--preset", preset, "--points", "31", "--steps", "2500",
                 "--report", str(rep)]) == 0
    text = capsys.readouterr().out
    assert "max|J - V| / max V" in text and "gap mean" in text and "worst case" in text
    r = json.loads(rep.read_text())
    assert r["weakgrid_version"] == weakgrid.__version__ and r["problem"] == preset
    assert r["parameters"]["dp"]["n_points"] == [31, 31]
    ve, cl = r["value_error"], r["closed_loop"]
    assert 0 <= ve["median_relative_error"] <= ve["p90_relative_error"]
    assert ve["sup_error_over_max_V"] > 0
    # the DP is self-consistent: its policies achieve its value from the starts
    assert cl["dp_consistency"] < 0.01
    for key in ("no_disturbance", "worst_case"):
        g = cl[key]
        assert len(g["relative_gap"]) == len(cl["starts"]) == 8
        assert g["diverged_controller"] == 0 and g["diverged_dp"] == 0
        gap = (np.array(g["cost_controller"]) - g["cost_dp"]) / np.array(g["cost_dp"])
        np.testing.assert_allclose(gap, g["relative_gap"])
    # saddle-point inequality J(u, w*) ≥ J(u*, w*): no policy beats the DP's against w_dp
    # (up to the DP's own accuracy)
    assert cl["worst_case"]["min_relative_gap"] >= -2 * cl["dp_consistency"] - 1e-3


def test_verify_refuses_non_2_state(tmp_path, capsys):
    cfg = tmp_path / "lin3.toml"
    cfg.write_text("""
[model]
kind = "linear"
A = [[0.9, 0.1, 0.0], [0.0, 0.9, 0.1], [0.0, 0.0, 0.9]]
B = [[0.0], [0.0], [1.0]]
E = [[0.1], [0.0], [0.0]]
[cost]
Q = 1.0
R = 1.0
P = 1.0
gamma = 5.0
[mesh]
lower = [-1.0, -1.0, -1.0]
upper = [1.0, 1.0, 1.0]
step = [0.5, 0.5, 0.5]
[basis]
kind = "even"
degree = 2
[initial_policy]
kind = "lqr"
Q = 1.0
""")
    assert main(["verify", "--config", str(cfg)]) == 2
    assert "2-state" in capsys.readouterr().err


def test_verify_refuses_a_controller_of_another_model(trained_presets, tmp_path, capsys):
    f = tmp_path / "c1.json"
    trained_presets["case1-paper"][1].save(f)
    assert main(["verify", "--preset", "case2-paper", "--controller", str(f)]) == 2
    assert "--controller" in capsys.readouterr().err
