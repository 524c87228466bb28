"""A really full file system (a 64 KiB tmpfs): the previous file survives a failed write."""

from __future__ import annotations

import os
import subprocess

import pytest


@pytest.fixture
def small_fs(tmp_path):
    mnt = tmp_path / "small"
    mnt.mkdir()
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(mnt)],
                       capture_output=True, text=True)
    if r.returncode != 0:
        pytest.skip(f"cannot mount a small tmpfs here (needs root): {r.stderr.strip()}")
    yield mnt
    subprocess.run(["umount", str(mnt)], check=False)


def test_full_disk_keeps_the_previous_controller_file(small_fs, cli):
    target = small_fs / "ctl.json"
    code, _, err = cli(["train", "--preset", "case1-paper", "-q", "-o", target])
    assert code == 0, err
    before = target.read_bytes()
    st = os.statvfs(small_fs)
    (small_fs / "filler").write_bytes(b"0" * (st.f_bavail * st.f_frsize - 8192))  # 8 KiB left
    code, _, err = cli(["train", "--preset", "case2-paper", "-q", "-o", target])
    assert code == 3, err
    assert "no space left" in err and str(target) in err
    assert len(err.strip().splitlines()) <= 2
    assert target.read_bytes() == before
    assert sorted(p.name for p in small_fs.iterdir()) == ["ctl.json", "filler"]  # no temporary


def test_full_disk_keeps_the_previous_results_table(small_fs):
    """``Results.to_csv`` goes through the atomic writer too."""
    import numpy as np

    from weakgrid.sim.results import Results

    target = small_fs / "run.csv"
    target.write_text("t,x\n0,1\n")
    big = np.linspace(0, 1, 20000)

    class Fake:
        def to_frame(self, si=False, names=None):
            import pandas as pd

            return pd.DataFrame({"t": big, "x": big**2})

    with pytest.raises(OSError) as info:
        Results.to_csv(Fake(), target)
    assert info.value.filename == str(target)
    assert target.read_text() == "t,x\n0,1\n"
    assert sorted(p.name for p in small_fs.iterdir()) == ["run.csv"]
