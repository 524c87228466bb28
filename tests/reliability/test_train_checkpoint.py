"""Checkpoints of `weakgrid train`: resumed only for the same inputs, a damaged one is
reported and ignored, and a resumed training gives the same weights bit for bit."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from weakgrid.cli.train import checkpoint_path, training_key
from weakgrid.game.checkpoint import (CheckpointError, StaleCheckpointError, load_checkpoint,
                                      save_checkpoint)
from weakgrid.models import load_preset, load_problem

ROW = re.compile(r"^\s+(\d+)\s+\d+\s+\S+e[+-]\d+", re.M)


@pytest.fixture(scope="module")
def states():
    """The state after every outer iteration of case1-paper, and the finished controller."""
    kept = []
    ctl = load_preset("case1-paper").train(checkpoint=kept.append)
    return kept, ctl


def _rows(out):
    return [int(k) for k in ROW.findall(out)]


@pytest.mark.parametrize("k", [1, 7, 30, -1])
def test_resumed_training_equals_the_uninterrupted_one_bit_for_bit(tmp_path, states, k):
    kept, ref = states
    path = save_checkpoint(tmp_path / "c.npz", kept[k - 1 if k > 0 else k], "key")
    got = load_preset("case1-paper").train(start=load_checkpoint(path, "key"))
    np.testing.assert_array_equal(got.weights, ref.weights)
    assert [r.max_du for r in got.history] == [r.max_du for r in ref.history]
    assert got.iterations == ref.iterations


def test_the_cli_resumes_a_checkpoint_of_the_same_inputs_only(ws, cli, states):
    kept, ref = states
    problem = load_preset("case1-paper")
    out = ws.root / "c.controller.json"
    ckpt = checkpoint_path(out)
    save_checkpoint(ckpt, kept[9], training_key(problem, problem.settings))

    code, stdout, err = cli(["train", "--preset", "case1-paper", "-o", out, "--tol", "1e-6"])
    assert code == 0, err  # another tolerance: other inputs, started over
    assert "is of other inputs" in stdout and _rows(stdout)[0] == 1
    assert not ckpt.exists()

    save_checkpoint(ckpt, kept[9], training_key(problem, problem.settings))
    edited = ws.problem_with(lambda t: t.replace("gamma = 20.0", "gamma = 21.0"))
    p2 = load_problem(edited)
    assert training_key(p2, p2.settings) != training_key(problem, problem.settings)

    code, stdout, err = cli(["train", "--preset", "case1-paper", "-o", out])
    assert code == 0, err
    assert "resuming from the checkpoint" in stdout and "10 finished outer iteration(s)" in stdout
    assert _rows(stdout) == list(range(11, len(ref.history) + 1))
    np.testing.assert_array_equal(json.loads(out.read_text())["weights"], ref.weights)
    assert not ckpt.exists()


@pytest.mark.parametrize("damage", ["garbage", "truncated", "empty", "header"])
def test_a_damaged_checkpoint_is_reported_and_ignored(ws, cli, states, damage):
    kept, ref = states
    problem = load_preset("case1-paper")
    key = training_key(problem, problem.settings)
    out = ws.root / "c.controller.json"
    ckpt = save_checkpoint(checkpoint_path(out), kept[9], key)
    data = ckpt.read_bytes()
    if damage == "garbage":
        ckpt.write_bytes(b"\x00not a checkpoint" * 10)
    elif damage == "truncated":
        ckpt.write_bytes(data[: len(data) // 2])
    elif damage == "empty":
        ckpt.write_bytes(b"")
    else:  # a valid .npz that is not a checkpoint
        with open(ckpt, "wb") as fh:
            np.savez(fh, meta=np.array('{"format": "something else"}'))
    with pytest.raises(CheckpointError) as e:
        load_checkpoint(ckpt, key)
    assert not isinstance(e.value, StaleCheckpointError)
    code, stdout, err = cli(["train", "--preset", "case1-paper", "-o", out])
    assert code == 0, err
    warn = [ln for ln in err.splitlines() if ln.strip()]
    assert len(warn) == 1 and "warning" in warn[0] and str(ckpt) in warn[0]
    assert "damaged" in warn[0] and "starting over" in warn[0]
    assert _rows(stdout)[0] == 1
    np.testing.assert_array_equal(json.loads(out.read_text())["weights"], ref.weights)
    assert not ckpt.exists()


def test_restart_ignores_a_checkpoint(ws, cli, states):
    kept, _ = states
    problem = load_preset("case1-paper")
    out = ws.root / "c.controller.json"
    save_checkpoint(checkpoint_path(out), kept[9], training_key(problem, problem.settings))
    code, stdout, _ = cli(["train", "--preset", "case1-paper", "-o", out, "--restart"])
    assert code == 0 and "resuming" not in stdout and _rows(stdout)[0] == 1


def test_a_checkpoint_of_another_mesh_is_refused_by_the_solver(states):
    from weakgrid.game.errors import ShapeError

    kept, _ = states
    from dataclasses import replace

    p = load_preset("case1-paper")
    state = replace(kept[3], policy=kept[3].policy[:-1])  # one mesh point fewer
    with pytest.raises(ShapeError, match="checkpoint policy"):
        p.train(start=state)


def test_the_key_changes_with_every_input_and_with_the_code(monkeypatch):
    from dataclasses import replace

    import weakgrid.hashing as cache   # the one content hash (with the code fingerprint)

    p = load_preset("case1-paper")
    key = training_key(p, p.settings)
    assert training_key(load_preset("case1-paper"), p.settings) == key  # reproducible
    others = [training_key(p.with_input_bound(0.5), p.settings),       # --u-bound
              training_key(p.with_gamma(25.0), p.settings),            # the cost
              training_key(p, replace(p.settings, max_inner=100)),     # the solver
              training_key(load_preset("case2-paper"), p.settings)]    # another problem
    monkeypatch.setattr(cache, "code_fingerprint", lambda: "another version of the code")
    others.append(training_key(p, p.settings))
    assert len({key, *others}) == len(others) + 1
