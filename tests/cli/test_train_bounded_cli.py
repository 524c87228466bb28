"""The input bound in design settings: problem files, the study hook and `weakgrid train`."""

import numpy as np
import pytest

from weakgrid.cli.main import main
from weakgrid.game import ParameterError
from weakgrid.models import load_controller, load_preset, load_problem

BASE = """
[model]
kind = "upqc-design"
T = 8.100248e-4
a = 896.8810
Vr_bar = 0.8337510
phi_s0 = 0.3136904
[cost]
Q = 0.01
R = 1.0
P = 1.0
gamma = 20.0
{extra}
[mesh]
lower = [-1.0, -10.0]
upper = [1.0, 10.0]
step = [0.12, 1.2]
[initial_policy]
kind = "nonlinear-29"
gain = 125.0
phase = 0.069
"""


def write(tmp_path, extra):
    cfg = tmp_path / "b.toml"
    cfg.write_text(BASE.format(extra=extra))
    return cfg


def test_problem_file_bound_trains_and_reports(tmp_path, capsys):
    cfg = write(tmp_path, 'u_bound = 0.15\nu_bound_shape = "disk"')
    p = load_problem(cfg)
    assert p.input_bound.shape == "disk" and p.input_bound.limit.tolist() == [0.15]
    out = tmp_path / "b.json"
    assert main(["train", "--config", str(cfg), "-o", str(out), "-q"]) == 0
    text = capsys.readouterr().out
    assert "‖u‖ ≤ 0.15" in text and "binds on" in text
    ctl = load_controller(out)
    assert ctl.cost.bound.limit.tolist() == [0.15]
    assert ctl.cost.bound.ratio(ctl.control(p.mesh.points)).max() <= 1.0


def test_cli_bound_overrides_the_preset(tmp_path, capsys):
    out = tmp_path / "c2.json"
    assert main(["train", "--preset", "case2-paper", "--u-bound", "0.1", "--u-bound-shape",
                 "box", "-o", str(out), "-q"]) == 0
    text = capsys.readouterr().out
    assert "|u_i| ≤ 0.1, 0.1" in text and "published" not in text
    assert load_controller(out).cost.bound.shape == "box"


@pytest.mark.parametrize("extra, field", [
    ("u_bound = -0.1", "cost.u_bound"),
    ('u_bound = 0.1\nu_bound_shape = "ring"', "cost.u_bound_shape"),
    ('u_bound_shape = "box"', "cost.u_bound"),
    ("u_bound = [0.1, 0.2]", "cost.u_bound"),  # a disk takes one value
    ("u_bound = 0.1\nR = [[1.0, 0.0], [0.0, 2.0]]", "cost.R"),
])
def test_bad_bounds_name_the_field(tmp_path, capsys, extra, field):
    text = BASE.format(extra=extra)
    if "R = [[" in extra:
        text = text.replace("R = 1.0\n", "", 1)
    cfg = tmp_path / "bad.toml"
    cfg.write_text(text)
    with pytest.raises(ParameterError, match=field.replace(".", r"\.")):
        load_problem(cfg)
    assert main(["train", "--config", str(cfg)]) == 2  # bad input
    assert field in capsys.readouterr().err


def test_rating_hook_defaults_to_the_rating_unless_the_file_sets_a_bound(tmp_path):
    p = load_preset("case1-paper")
    assert p.input_bound is None
    r = p.with_rating(0.15)
    assert r.input_bound.limit.tolist() == [0.15] and r.input_bound.shape == "disk"
    assert r.name == "case1-paper-bounded" and r.published == {}
    own = load_problem(write(tmp_path, "u_bound = 0.3"))
    assert own.with_rating(0.15).input_bound.limit.tolist() == [0.3]
    assert p.with_input_bound(0.1, "box").with_input_bound(None).input_bound is None
    assert np.isclose(r.with_gamma(25.0).input_bound.limit[0], 0.15)
