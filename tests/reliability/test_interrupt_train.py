"""Ctrl-C or SIGTERM during `weakgrid train`: one line, exit 130, the finished outer
iterations kept in a checkpoint beside the output; the re-run of the same command continues
from it (it does not redo them) and writes the same weights, bit for bit, as a training that
was never interrupted."""

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
from weakgrid.models import load_preset

pytestmark = pytest.mark.slow

SCRIPT = Path(__file__).with_name("paced_train.py")
ROW = re.compile(r"^\s+(\d+)\s+\d+\s+\S+e[+-]\d+")  # a row of the iteration table


def _sigint_default():
    """In the child: Ctrl-C acts, even when this test runs in a background job (which starts
    its children with SIGINT ignored, so that Python would install no KeyboardInterrupt)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _start(out):
    env = dict(os.environ, PYTHONPATH=str(Path(weakgrid.__file__).parents[1]),
               WEAKGRID_TEST_PACE="0.1")
    return subprocess.Popen(
        [sys.executable, str(SCRIPT), "train", "--preset", "case1-paper", "-o", str(out)],
        preexec_fn=_sigint_default, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        env=env, cwd=out.parent)


def _rows(stdout):
    return [int(m.group(1)) for m in map(ROW.match, stdout.splitlines()) if m]


@pytest.fixture(scope="module")
def reference():
    """The controller of an uninterrupted training (in this process)."""
    return load_preset("case1-paper").train()


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
def test_interrupted_training_resumes_and_gives_the_same_weights(tmp_path, reference, sig):
    out = tmp_path / "c.controller.json"
    ckpt = tmp_path / "c.controller.checkpoint.npz"
    proc = _start(out)
    seen, deadline = [], time.monotonic() + 300
    while len(_rows("\n".join(seen))) < 3:  # three outer iterations finished
        line = proc.stdout.readline()
        assert line or proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "no outer iteration in 5 minutes"
        seen.append(line.rstrip("\n"))
    proc.send_signal(sig)
    rest, stderr = proc.communicate(timeout=120)
    stdout = "\n".join(seen) + "\n" + rest
    assert proc.returncode == 130, stderr
    assert "Traceback" not in stderr
    msg = [ln for ln in stderr.splitlines() if ln.strip()]
    assert len(msg) == 1 and "interrupted" in msg[0] and "re-run" in msg[0], stderr
    done = _rows(stdout)
    n_kept = int(re.search(r"kept (\d+) finished outer iteration", stdout).group(1))
    # every reported iteration is kept (one more if the signal came between the two)
    assert done == list(range(1, len(done) + 1)) and n_kept in (done[-1], done[-1] + 1)
    assert n_kept < len(reference.history), "the training finished before the signal"
    assert ckpt.is_file() and not out.exists()
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]

    proc = _start(out)  # the same command again
    stdout, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 0, stderr
    assert (f"resuming from the checkpoint {ckpt.name}: {n_kept} finished outer iteration(s) "
            f"kept, continuing at iteration {n_kept + 1}") in stdout.replace(str(tmp_path) + "/",
                                                                           "")
    redone = _rows(stdout)  # only the remaining iterations were done
    assert redone == list(range(n_kept + 1, len(reference.history) + 1))
    rec = json.loads(out.read_text())
    np.testing.assert_array_equal(rec["weights"], reference.weights)  # bit for bit
    assert [h["max_du"] for h in rec["history"]] == [r.max_du for r in reference.history]
    assert rec["iterations"]["outer"] == len(reference.history)
    assert not ckpt.exists()  # a finished training removes its checkpoint


def test_a_killed_training_resumes_from_its_last_periodic_checkpoint(tmp_path, reference):
    """SIGKILL (or a power cut): no handler runs, yet the iterations saved by the periodic
    checkpoint (every second) are not redone, and the result is the same."""
    out = tmp_path / "c.controller.json"
    ckpt = tmp_path / "c.controller.checkpoint.npz"
    proc = _start(out)
    deadline = time.monotonic() + 300
    while not ckpt.exists():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "no checkpoint in 5 minutes"
        time.sleep(0.02)
    proc.kill()
    proc.communicate(timeout=60)
    assert proc.returncode == -signal.SIGKILL
    n_saved = len(np.load(ckpt, allow_pickle=False)["weights"])  # a complete file
    assert 1 <= n_saved < len(reference.history)
    assert not out.exists()

    proc = _start(out)
    stdout, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 0, stderr
    assert f"{n_saved} finished outer iteration(s) kept" in stdout
    assert _rows(stdout) == list(range(n_saved + 1, len(reference.history) + 1))
    np.testing.assert_array_equal(json.loads(out.read_text())["weights"], reference.weights)
