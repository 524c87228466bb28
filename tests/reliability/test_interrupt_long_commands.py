"""Ctrl-C during `weakgrid gamma`, `verify` and `design`: one line, exit 130, the finished
work kept in a checkpoint beside the output; the re-run of the same command says what it
kept, does only the remaining work (counted from the printed rows) and gives the same result
as a run that was never interrupted (same γ*, bracket and weights; the same DP iterations
and report; the same weights, bit for bit); the checkpoint is removed at the end.

The commands run in a subprocess (`paced_train.py`: the real command with pauses in its
loops, so that the signal falls between two steps).
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import weakgrid
from weakgrid.cli.main import main as _main

SCRIPT = Path(__file__).with_name("paced_train.py")
STUDY = Path(weakgrid.__file__).parent / "data" / "studies" / "case1-weak-grid.toml"
TRIAL = re.compile(r"^\s+(\d+)\s+\S+\s+(?:accepted|rejected)\s")  # a row of gamma's table
DP_ROW = re.compile(r"^\s+(\d+)\s+\S+e[+-]\d+\s+\S+e[+-]\d+\s+\d+\s+[\d.]+$")  # verify's DP


def main(argv):
    return _main([str(a) for a in argv])


def _sigint_default():
    """In the child: Ctrl-C acts, even when this test runs in a background job (which starts
    its children with SIGINT ignored, so that Python would install no KeyboardInterrupt)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _start(argv, cwd, **pace):
    env = dict(os.environ, PYTHONPATH=str(Path(weakgrid.__file__).parents[1]),
               **{f"WEAKGRID_TEST_PACE{k}": str(v) for k, v in pace.items()})
    return subprocess.Popen([sys.executable, str(SCRIPT), *map(str, argv)],
                            preexec_fn=_sigint_default, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, env=env, cwd=cwd)


def _interrupt_when(proc, ready, sig=signal.SIGINT):
    """Read stdout until ``ready(lines)``, send ``sig``; return (stdout, stderr)."""
    seen, deadline = [], time.monotonic() + 300
    while not ready(seen):
        line = proc.stdout.readline()
        assert line or proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "not ready in 5 minutes"
        seen.append(line.rstrip("\n"))
    proc.send_signal(sig)
    rest, stderr = proc.communicate(timeout=120)
    return "\n".join(seen) + "\n" + rest, stderr


def _check_interrupted(proc, stderr, folder):
    assert proc.returncode == 130, stderr
    assert "Traceback" not in stderr
    msg = [ln for ln in stderr.splitlines() if ln.strip()]
    assert len(msg) == 1 and "interrupted" in msg[0] and "re-run" in msg[0], stderr
    assert not [p for p in folder.iterdir() if ".tmp" in p.name]


def _rows(pattern, stdout):
    return [int(m.group(1)) for m in map(pattern.match, stdout.splitlines()) if m]


def _run_rest(argv, cwd, **pace):
    proc = _start(argv, cwd, **pace)
    stdout, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 0, stderr
    assert "Traceback" not in stderr
    return stdout.replace(str(cwd) + "/", "")


@pytest.mark.slow
def test_an_interrupted_gamma_search_resumes_without_redoing_its_trials(tmp_path):
    args = ["gamma", "--preset", "case2-paper", "--rtol", "0.05", "--rollout-steps", "1500"]
    ref_dir = tmp_path / "ref"
    ref_dir.mkdir()
    assert main(args + ["-o", ref_dir / "g.json", "--report", ref_dir / "r.json"]) == 0
    ref = json.loads((ref_dir / "r.json").read_text())
    ref_ctl = json.loads((ref_dir / "g.json").read_text())
    n_ref = len(ref["history"])

    out, rep = tmp_path / "g.json", tmp_path / "r.json"
    ckpt = tmp_path / "g.gamma.checkpoint.npz"
    argv = args + ["-o", out.name, "--report", rep.name]
    proc = _start(argv, tmp_path, **{"": 0, "_TRIAL": 0.4})
    stdout, stderr = _interrupt_when(proc, lambda seen: len(_rows(TRIAL, "\n".join(seen))) >= 3)
    _check_interrupted(proc, stderr, tmp_path)
    done = _rows(TRIAL, stdout)
    n_kept = int(re.search(r"kept (\d+) decided trial\(s\)", stdout).group(1))
    # every reported trial is kept (one more if the signal came between the two)
    assert done == list(range(1, len(done) + 1)) and n_kept in (done[-1], done[-1] + 1)
    assert n_kept < n_ref, "the search finished before the signal"
    assert ckpt.is_file() and not out.exists() and not rep.exists()

    stdout = _run_rest(argv, tmp_path, **{"": 0, "_TRIAL": 0})
    assert f"resuming from the checkpoint {ckpt.name}: {n_kept} decided trial(s) kept" in stdout
    kept_rows = [ln for ln in stdout.splitlines() if TRIAL.match(ln) and "(kept)" in ln]
    new_rows = [int(TRIAL.match(ln).group(1)) for ln in stdout.splitlines()
                if TRIAL.match(ln) and "(kept)" not in ln]
    assert len(kept_rows) == n_kept  # shown, not run again
    assert new_rows == list(range(n_kept + 1, n_ref + 1))
    assert (f"{n_ref} trials ({n_ref - n_kept} run now, {n_kept} kept from the "
            "checkpoint)") in stdout
    got = json.loads(rep.read_text())
    assert got["gamma_star"] == ref["gamma_star"] and got["bracket"] == ref["bracket"]
    assert [(t["gamma"], t["accepted"], t["reason"]) for t in got["history"]] == \
        [(t["gamma"], t["accepted"], t["reason"]) for t in ref["history"]]
    ctl = json.loads(out.read_text())
    np.testing.assert_array_equal(ctl["weights"], ref_ctl["weights"])  # bit for bit
    assert ctl["problem"]["cost"] == ref_ctl["problem"]["cost"]
    assert not ckpt.exists()


@pytest.mark.slow
def test_an_interrupted_verify_keeps_its_training_and_dp_iterations(tmp_path):
    args = ["verify", "--preset", "case1-paper", "--points", "31", "--steps", "2500"]
    (tmp_path / "ref").mkdir()
    assert main(args + ["--report", tmp_path / "ref" / "v.json"]) == 0
    ref = json.loads((tmp_path / "ref" / "v.json").read_text())
    n_ref = len(ref["dp"]["history"])

    argv = args + ["--report", "v.json"]
    dp_ckpt, train_ckpt = (tmp_path / f"v.{k}.checkpoint.npz" for k in ("dp", "training"))
    proc = _start(argv, tmp_path, **{"": 0, "_DP": 0.5})
    stdout, stderr = _interrupt_when(proc, lambda seen: len(_rows(DP_ROW, "\n".join(seen))) >= 2)
    _check_interrupted(proc, stderr, tmp_path)
    done = _rows(DP_ROW, stdout)
    n_kept = int(re.search(r"kept (\d+) finished DP iteration\(s\)", stdout).group(1))
    assert done == list(range(1, len(done) + 1)) and n_kept in (done[-1], done[-1] + 1)
    assert n_kept < n_ref, "the DP finished before the signal"
    assert dp_ckpt.is_file() and train_ckpt.is_file() and not (tmp_path / "v.json").exists()

    stdout = _run_rest(argv, tmp_path, **{"": 0, "_DP": 0})
    # the finished training is not redone, nor the finished DP iterations
    m = re.search(r"trained now: (\d+) outer iterations \((\d+) kept from the checkpoint\)",
                  stdout)
    assert m and m.group(1) == m.group(2), stdout
    assert (f"resuming the DP from the checkpoint {dp_ckpt.name}: {n_kept} finished "
            f"iteration(s) kept, continuing at iteration {n_kept + 1}") in stdout
    assert _rows(DP_ROW, stdout) == list(range(n_kept + 1, n_ref + 1))
    got = json.loads((tmp_path / "v.json").read_text())
    strip = ("seconds",)
    assert [{k: v for k, v in h.items() if k not in strip} for h in got["dp"]["history"]] == \
        [{k: v for k, v in h.items() if k not in strip} for h in ref["dp"]["history"]]
    assert got["value_error"] == ref["value_error"]  # the same numbers, exactly
    assert got["closed_loop"] == ref["closed_loop"]
    assert not dp_ckpt.exists() and not train_ckpt.exists()


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_an_interrupted_design_resumes_its_training(tmp_path, sig):
    study = tmp_path / "study.toml"
    study.write_text(STUDY.read_text())
    (tmp_path / "ref").mkdir()
    assert main(["design", study, "-o", tmp_path / "ref" / "c.controller.json"]) == 0
    ref = json.loads((tmp_path / "ref" / "c.controller.json").read_text())
    n_ref = ref["iterations"]["outer"]

    out = tmp_path / "c.controller.json"
    ckpt = tmp_path / "c.controller.checkpoint.npz"
    argv = ["design", study.name, "-o", out.name]
    proc = _start(argv, tmp_path, **{"": 0.1})

    def ready(seen):  # a periodic checkpoint was written during the training
        if any(ln.startswith("HJI training:") for ln in seen) and ckpt.exists():
            return True
        time.sleep(0.05)
        return False
    stdout, stderr = _interrupt_when(proc, ready, sig)
    _check_interrupted(proc, stderr, tmp_path)
    n_kept = int(re.search(r"kept (\d+) finished outer iteration\(s\)", stdout).group(1))
    assert 1 <= n_kept < n_ref and ckpt.is_file() and not out.exists()

    stdout = _run_rest(argv, tmp_path, **{"": 0})
    assert (f"resuming from the checkpoint {ckpt.name}: {n_kept} finished outer iteration(s) "
            f"kept, continuing at iteration {n_kept + 1}") in stdout
    assert (f"HJI: {n_ref} outer iterations ({n_ref - n_kept} now, {n_kept} kept from the "
            "checkpoint)") in stdout
    got = json.loads(out.read_text())
    np.testing.assert_array_equal(got["weights"], ref["weights"])  # bit for bit
    assert [h["max_du"] for h in got["history"]] == [h["max_du"] for h in ref["history"]]
    assert not ckpt.exists()


def test_a_changed_input_ignores_the_checkpoint_and_restart_starts_over(tmp_path, capsys):
    """A stale checkpoint (other inputs) is said to be so and ignored; `--restart` ignores a
    valid one; a damaged one is one warning line."""
    from weakgrid.cli._checkpoint import checkpoint_path

    args = ["gamma", "--preset", "case2-paper", "--rtol", "0.05", "--rollout-steps", "1500",
            "--max-trials", "3", "-o", tmp_path / "g.json"]
    ckpt = checkpoint_path(tmp_path / "g.json", "gamma")

    def interrupt_after_two(monkeypatch_target):
        """Run `args` in-process, stopped (KeyboardInterrupt) after 2 decided trials."""
        import weakgrid.game.gamma_search as g   # `gamma` imports it when it runs

        real = g.search_min_gamma

        def stopping(*a, progress=None, **kw):
            n = [0]

            def prog(t):
                progress(t)
                n[0] += 1
                if n[0] == 2:
                    raise KeyboardInterrupt
            return real(*a, progress=prog, **kw)
        monkeypatch_target.setattr(g, "search_min_gamma", stopping)

    mp = pytest.MonkeyPatch()
    interrupt_after_two(mp)
    assert main(args) == 130
    mp.undo()
    assert "kept 2 decided trial(s)" in capsys.readouterr().out and ckpt.exists()
    # another --rollout-steps: other inputs
    assert main([a if a != "1500" else "1400" for a in args]) == 0
    out = capsys.readouterr().out
    assert "is of other inputs" in out and "(kept)" not in out and not ckpt.exists()

    mp = pytest.MonkeyPatch()
    interrupt_after_two(mp)
    assert main(args) == 130
    mp.undo()
    capsys.readouterr()
    assert main(args + ["--restart"]) == 0
    out = capsys.readouterr().out
    assert "resuming" not in out and "(kept)" not in out and not ckpt.exists()

    ckpt.write_bytes(b"not a checkpoint")
    assert main(args) == 0
    cap = capsys.readouterr()
    warn = [ln for ln in cap.err.splitlines() if ln.strip()]
    assert len(warn) == 1 and "warning" in warn[0] and ckpt.name in warn[0]
    assert "(kept)" not in cap.out and not ckpt.exists()


def test_a_checkpoint_that_cannot_be_written_is_one_warning_and_the_work_goes_on(
        tmp_path, capsys, monkeypatch):
    """Disk full (or a read-only folder) while saving a checkpoint: the search goes on to
    the same result, with one warning line; no temporary is left."""
    import errno

    import weakgrid.game.checkpoint as g   # `gamma` imports its writer when it runs

    args = ["gamma", "--preset", "case2-paper", "--rtol", "0.05", "--rollout-steps", "1500",
            "--max-trials", "3", "--report"]
    assert main(args + [tmp_path / "ref.json"]) == 0
    capsys.readouterr()

    def full(path, *a):
        raise OSError(errno.ENOSPC, "No space left on device", str(path))
    monkeypatch.setattr(g, "save_search_checkpoint", full)
    assert main(args + [tmp_path / "r.json"]) == 0
    cap = capsys.readouterr()
    warn = [ln for ln in cap.err.splitlines() if ln.strip()]
    assert len(warn) == 1 and "cannot write the checkpoint" in warn[0] and \
        "r.gamma.checkpoint.npz" in warn[0] and "no space left" in warn[0], cap.err
    ref, got = (json.loads((tmp_path / n).read_text()) for n in ("ref.json", "r.json"))
    assert got["bracket"] == ref["bracket"] and got["gamma_star"] == ref["gamma_star"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.json", "ref.json"]


def test_verify_and_design_ignore_a_checkpoint_of_other_inputs(tmp_path, capsys):
    """The same for `verify` (its training and its DP) and `design`: a checkpoint of other
    inputs is said to be so, ignored (the work starts at iteration 1) and replaced."""
    from weakgrid.cli._checkpoint import checkpoint_path
    from weakgrid.game.checkpoint import DPState, save_checkpoint, save_dp_checkpoint
    from weakgrid.models import load_preset

    states = []
    load_preset("case1-paper").train(checkpoint=states.append)
    rep = tmp_path / "v.json"
    save_checkpoint(checkpoint_path(rep, "training"), states[3], "other inputs")
    save_dp_checkpoint(checkpoint_path(rep, "dp"), DPState(1, np.zeros((961, 2)),
                                                           np.zeros(961), np.zeros(961),
                                                           [{"iteration": 1}]), "other")
    assert main(["verify", "--preset", "case1-paper", "--points", "31", "--steps", "500",
                 "--report", rep]) == 0
    out = capsys.readouterr().out
    assert out.count("is of other inputs") == 2 and "kept from the checkpoint" not in out
    assert _rows(DP_ROW, out)[0] == 1 and "resuming" not in out
    assert not checkpoint_path(rep, "dp").exists()

    study = tmp_path / "study.toml"
    study.write_text(STUDY.read_text())
    out_file = tmp_path / "c.controller.json"
    save_checkpoint(checkpoint_path(out_file), states[3], "other inputs")
    assert main(["design", study, "-o", out_file]) == 0
    out = capsys.readouterr().out
    assert "is of other inputs" in out and "kept from the checkpoint" not in out
    assert not checkpoint_path(out_file).exists()
