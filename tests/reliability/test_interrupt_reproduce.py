"""Ctrl-C during `weakgrid reproduce`: one line, exit 130, finished runs kept; the re-run
does only the remaining runs (and keeps the finished files untouched)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import weakgrid


def _sigint_default():
    """In the child: Ctrl-C acts, even when this test runs in a background job (which starts
    its children with SIGINT ignored, so that Python would install no KeyboardInterrupt)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)

pytestmark = pytest.mark.slow

SCRIPT = Path(__file__).with_name("small_reproduce.py")
N_RUNS = 4


def _start(out):
    env = dict(os.environ, PYTHONPATH=str(Path(weakgrid.__file__).parents[1]))
    return subprocess.Popen([sys.executable, str(SCRIPT), str(out), str(N_RUNS), "0.4"],
                            preexec_fn=_sigint_default,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)


def _finished(out):
    return sorted((out / "runs").glob("*.json")) if (out / "runs").is_dir() else []


def test_interrupted_reproduce_resumes_with_the_remaining_runs_only(tmp_path):
    out = tmp_path / "rep"
    proc = _start(out)
    deadline = time.monotonic() + 600
    while len(_finished(out)) < 2:
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "no run finished in 10 minutes"
        time.sleep(0.05)
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 130, stderr
    assert "Traceback" not in stderr
    msg = [ln for ln in stderr.splitlines() if "error:" in ln]
    assert len(msg) == 1 and "interrupted" in msg[0] and "re-run" in msg[0]
    done = _finished(out)
    assert 2 <= len(done) < N_RUNS
    assert not (out / "report.html").exists()
    assert not [p for p in out.rglob("*") if p.name.endswith(".tmp")]
    kept = {p: (p.stat().st_mtime_ns, p.read_bytes()) for p in (out / "runs").iterdir()}

    proc = _start(out)
    stdout, stderr = proc.communicate(timeout=600)
    assert proc.returncode == 0, stderr
    assert f"kept {len(done)} finished result(s)" in stdout
    assert len(_finished(out)) == N_RUNS and (out / "report.html").exists()
    for p, (mtime, data) in kept.items():  # finished runs were not redone
        assert p.stat().st_mtime_ns == mtime and p.read_bytes() == data, p.name
