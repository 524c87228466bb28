"""The newcomer path: `weakgrid train` writes a file that loads back to the same controller."""

import json
import subprocess
import sys

import numpy as np
import pytest

import weakgrid
from weakgrid.cli.main import build_parser, main
from weakgrid.models import load_controller, load_preset


def test_train_writes_a_file_that_loads_back(tmp_path, capsys):
    out = tmp_path / "c1.json"
    assert main(["train", "--preset", "case1-paper", "--output", str(out)]) == 0
    text = capsys.readouterr().out
    assert "converged" in text and "(30)" in text and "wrote" in text
    d = json.loads(out.read_text())
    assert d["weakgrid_version"] == weakgrid.__version__
    assert set(d["problem"]) >= {"model", "cost", "mesh", "basis", "initial_policy", "settings"}
    assert d["problem"]["model"]["a"] == pytest.approx(896.8810)
    assert d["iterations"]["outer"] >= 4 and len(d["weights"]) == 8
    loaded = load_controller(out)
    fresh = load_preset("case1-paper").train()
    x = load_preset("case1-paper").mesh.sample(500, seed=7)
    np.testing.assert_allclose(loaded.control(x), fresh.control(x), rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(loaded.weights, fresh.weights, rtol=0, atol=0)


def test_config_file(tmp_path):
    cfg = tmp_path / "mine.toml"
    cfg.write_text("""
[model]
kind = "gti"
C = 0.05
tau = 15.0
Vs = 1.05
B = 4.0
Vr_bar = 0.98
T = 1e-3
Pin = 1.0
[cost]
Q = 0.01
R = 1.0
P = 1.0
gamma = 20.0
[mesh]
lower = [-1.0, -10.0]
upper = [1.0, 10.0]
step = [0.1, 1.0]
[initial_policy]
kind = "lqr"
""")
    out = tmp_path / "mine.json"
    assert main(["train", "--config", str(cfg), "-o", str(out), "-q"]) == 0
    assert load_controller(out).problem["model"]["source"]["Pin"] == 1.0


def test_config_errors_name_the_field(tmp_path, capsys):
    cfg = tmp_path / "bad.toml"
    cfg.write_text('[model]\nkind = "upqc-design"\nT = 1e-3\na = 10.0\nVr_bar = 1.0\n'
                   'phi_s0 = 0.3\nfoo = 1\n[cost]\nQ=1\nR=1\nP=1\ngamma=5\n'
                   '[mesh]\nlower=[-1,-1]\nupper=[1,1]\nstep=[0.1,0.1]\n'
                   '[initial_policy]\nkind="lqr"\n')
    assert main(["train", "--config", str(cfg)]) == 2
    err = capsys.readouterr().err
    assert "model.foo" in err and "unknown key" in err


def test_every_subcommand_has_help():
    parser = build_parser()
    sub = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    for name in sub.choices:
        r = subprocess.run([sys.executable, "-m", "weakgrid.cli.main", name, "--help"],
                           capture_output=True, text=True)
        assert r.returncode == 0 and "usage" in r.stdout
