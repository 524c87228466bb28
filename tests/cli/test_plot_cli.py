"""`weakgrid plot RUN SIGNAL...`: a figure of a run file's signals; bad names refused."""

import numpy as np
import pytest

from weakgrid.cli.main import main
from weakgrid.sim.results import Results
from weakgrid.sim.runfile import write_run


@pytest.fixture
def run_file(tmp_path):
    t = np.array([0.0, 0.5, 1.0, 1.0, 1.5, 2.0])           # a breakpoint at 1 s
    names = ["G1.omega", "G2.omega", "G1.Pe", "bus7.v"]
    data = np.column_stack([1 + 0.01 * t, 1 - 0.01 * t, 0.8 + 0 * t, 1.0 - 0.1 * (t > 1)])
    res = Results(t, names, data, ["speed", "speed", "power", "voltage"],
                  [2 * np.pi * 60, 2 * np.pi * 60, 100.0, 230.0])
    return write_run(tmp_path / "run.parquet", res, meta={"study": "s"})


def test_plot_writes_png_beside_the_run(run_file, capsys):
    assert main(["plot", str(run_file), "G*.omega", "G1.Pe"]) == 0
    out = run_file.with_suffix(".png")
    assert out.is_file() and out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert str(out) in capsys.readouterr().out


def test_plot_to_a_given_file_in_si(run_file, tmp_path):
    target = tmp_path / "fig" / "speeds.svg"
    assert main(["plot", str(run_file), "bus7.v", "G1.omega", "--si", "-o", str(target)]) == 0
    text = target.read_text()
    assert "kV" in text and "rad/s" in text        # one panel per unit, SI labels


@pytest.mark.parametrize("bad", ["G1.omegaa", "G3.*"])
def test_unknown_signal_lists_the_closest_names(run_file, capsys, bad):
    assert main(["plot", str(run_file), "G1.Pe", bad]) == 2
    err = capsys.readouterr().err
    assert bad in err and "G1.omega" in err and "Traceback" not in err
    assert not run_file.with_suffix(".png").exists()


def test_not_a_run_file(tmp_path, capsys):
    p = tmp_path / "x.parquet"
    p.write_text("not parquet")
    assert main(["plot", str(p), "G1.omega"]) == 2
    assert "Parquet" in capsys.readouterr().err
    assert main(["plot", str(tmp_path / "missing.parquet"), "G1.omega"]) == 2
