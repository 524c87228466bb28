"""Failures during a run and of the operating system: one or two lines, the right exit code,
no traceback (unless --debug), earlier results intact."""

from __future__ import annotations

import errno
import os

import pytest

import weakgrid.fileio as fileio
from weakgrid.models.problem import TrainingProblem


def _lines(err):
    """The non-blank lines of ``err`` (the CLI separates its error from what came before by a
    blank line: a slow training's checkpoint warning, then the error, is two lines)."""
    return [ln for ln in err.strip().splitlines() if ln.strip()]


def test_disk_full_during_write_keeps_the_previous_file(ws, cli, monkeypatch):
    real = os.fsync

    def full(fd):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(fileio.os, "fsync", full)
    ws.snapshot()
    code, _, err = cli(["train", "--preset", "case1-paper", "-q", "-o", ws.controller])
    monkeypatch.setattr(fileio.os, "fsync", real)
    assert code == 3 and "no space left" in err and "ctl.json" in err
    assert len(_lines(err)) <= 2
    ws.check_untouched()


def test_permission_denied_names_the_path(ws, cli, monkeypatch):
    def denied(*a, dir=None, **k):
        raise PermissionError(errno.EACCES, "Permission denied", str(dir))

    monkeypatch.setattr(fileio.tempfile, "mkstemp", denied)
    ws.snapshot()
    code, _, err = cli(["train", "--preset", "case1-paper", "-q", "-o", ws.controller])
    assert code == 2 and "permission denied" in err and str(ws.root) in err
    ws.check_untouched()


def test_interrupted_training_exits_130_with_one_line(ws, cli, monkeypatch):
    def stop(self, *a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(TrainingProblem, "train", stop)
    ws.snapshot()
    code, _, err = cli(["train", "--preset", "case1-paper", "-q", "-o", ws.controller])
    assert code == 130 and "interrupted" in err and len(_lines(err)) == 1
    ws.check_untouched()


def test_sigterm_is_an_interruption(ws, cli, monkeypatch):
    import signal

    def terminated(self, *a, **k):
        os.kill(os.getpid(), signal.SIGTERM)  # the CLI's handler turns it into an interruption
        raise AssertionError("SIGTERM was not handled")

    monkeypatch.setattr(TrainingProblem, "train", terminated)
    previous = signal.getsignal(signal.SIGTERM)
    code, _, err = cli(["train", "--preset", "case1-paper", "-q", "-o", ws.controller])
    assert code == 130 and "interrupted" in err
    assert signal.getsignal(signal.SIGTERM) == previous  # restored after the command


def test_simulator_error_is_a_run_failure(ws, cli, monkeypatch):
    from weakgrid.sim.errors import SimulationError
    import weakgrid.study.runner as runner

    def fail(sc, *a, **k):
        raise SimulationError(0.42, "newton", "no convergence with step 1e-05 s")

    monkeypatch.setattr(runner, "run_scenario", fail)
    code, _, err = cli(["simulate", "case1-weak-grid", "--t-end", "1"])
    assert code == 3 and "t = 0.42 s" in err and "newton" in err


def test_tolerance_below_round_off_is_named(ws, cli):
    """Regression: was reported as 'gamma = 20 is too small'."""
    code, _, err = cli(["train", "--preset", "case1-paper", "-q", "--tol", "1e-20",
                        "-o", ws.controller])
    assert code == 3 and "tol_w = 1e-20" in err and "round-off" in err
    assert "gamma" not in err


def test_an_internal_error_has_no_traceback_without_debug(ws, cli, monkeypatch, capsys):
    def bug(self, *a, **k):
        raise ZeroDivisionError("division by zero")

    monkeypatch.setattr(TrainingProblem, "train", bug)
    code, _, err = cli(["train", "--preset", "case1-paper", "-q"])
    assert code == 4 and "internal error ZeroDivisionError" in err and "--debug" in err
    from weakgrid.cli.main import main

    assert main(["--debug", "train", "--preset", "case1-paper", "-q"]) == 4
    assert "Traceback" in capsys.readouterr().err


def test_name_from_a_file_cannot_escape_the_folder(ws, cli):
    """A name read from a file that would become a path outside the folder is refused at
    load time, naming the field (it was quietly made '_x' before)."""
    cfg = ws.problem_with(lambda t: t.replace('name = "case1-paper"', 'name = "../x"'))
    work = ws.root / "work"
    work.mkdir()
    os.chdir(work)
    ws.snapshot()
    code, out, err = cli(["train", "--config", cfg, "-q"])
    assert code == 2 and "preset.name" in err and "'../x'" in err and "'_x'" in err, err
    assert list(work.iterdir()) == [] and not (ws.root / "x.controller.json").exists()
    ws.check_untouched()


def test_simulate_output_is_written_atomically_with_an_ordinary_mode(ws, cli, monkeypatch):
    import numpy as np

    import weakgrid.study.runner as runner
    from weakgrid.study.runner import RunRecord

    def fake(sc, *a, **k):
        t = np.linspace(0, 1, 5)
        return RunRecord(sc, {"failed": False, "x": 1.0}, {"t": t, "y": 2 * t})

    monkeypatch.setattr(runner, "run_scenario", fake)
    target = ws.root / "run.csv"
    target.write_text("old\n")
    code, _, err = cli(["simulate", "case1-weak-grid", "--t-end", "1", "-o", target])
    assert code == 0, err
    assert target.read_text().startswith("t,y")
    assert (target.stat().st_mode & 0o777) == 0o666 & ~_umask()


def _umask():
    m = os.umask(0)
    os.umask(m)
    return m


@pytest.mark.parametrize("fmt", ["c-law", "json"])
def test_export_never_leaves_half_an_output(ws, cli, monkeypatch, fmt):
    """C header + source appear together or not at all (a failing second write)."""
    out = ws.root / "o"
    assert cli(["export", ws.controller, "-d", out, "--format", fmt])[0] == 0
    ws.snapshot()
    calls = {"n": 0}
    real = fileio._finish

    def second_fails(tmp):
        calls["n"] += 1
        if calls["n"] == 2:
            raise OSError(errno.ENOSPC, "No space left on device", tmp)
        return real(tmp)

    monkeypatch.setattr(fileio, "_finish", second_fails)
    code, _, err = cli(["export", ws.controller, "-d", out, "--format", fmt])
    if fmt == "c-law":
        assert code == 3 and "no space left" in err
    ws.check_untouched()
