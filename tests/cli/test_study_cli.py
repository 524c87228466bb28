"""`weakgrid modes` and `weakgrid design --no-train` on a shipped study."""

from weakgrid.cli.main import main


def test_modes_table_marks_the_machine_mode_and_plots(tmp_path, capsys):
    png = tmp_path / "modes.png"
    assert main(["modes", "case2-lv-microgrid", "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    marked = [ln for ln in out.splitlines() if ln.strip().startswith("=>") and "Hz" not in ln]
    assert marked and "SG.omega" in marked[0]             # the SG's electromechanical mode
    assert png.stat().st_size > 5000


def test_design_prints_every_value_and_the_mode_check(capsys):
    assert main(["design", "case1-weak-grid", "--no-train"]) == 0
    out = capsys.readouterr().out
    for key in ("tau'", "Vs", "B", "a", "Vr_bar", "phi_s0", "Kron reduction", "mismatch"):
        assert key in out
    assert "a = 896.89" in out and "agree" in out


def test_modes_writes_the_table_and_the_state_matrix(tmp_path, capsys):
    """`modes --output/--state-matrix`: the CSV holds every mode and the npz's A has exactly
    the printed eigenvalues; B and C are the UPQC inputs and the controlled machine's speed."""
    import numpy as np
    import pandas as pd

    csv, npz = tmp_path / "modes.csv", tmp_path / "A.npz"
    assert main(["modes", "case2-lv-microgrid", "--output", str(csv), "--state-matrix",
                 str(npz)]) == 0
    table = pd.read_csv(csv)
    d = np.load(npz)
    lam = np.linalg.eigvals(d["A"])
    upper = lam[lam.imag >= 0]
    assert len(table) == len(upper)
    np.testing.assert_allclose(np.sort(table["imag"].to_numpy()), np.sort(upper.imag), atol=1e-8)
    assert d["B"].shape == (d["A"].shape[0], 2) and d["C"].shape == (1, d["A"].shape[0])
    assert list(d["outputs"])[0].endswith(".omega") and d["C"].sum() == 1.0
    assert "wrote" in capsys.readouterr().out


def test_modes_of_a_plain_case_match_the_state_matrix_and_the_simulator(tmp_path, capsys):
    """`modes CASE`: the CSV's eigenvalues are those of the npz's A (no inputs, every
    machine's speed as output), and A's eigenvalues are weakgrid.design.modes's of the same
    case read in Python."""
    from pathlib import Path

    import numpy as np
    import pandas as pd

    from weakgrid.design import modes
    from weakgrid.sim.io.cases import load_case

    data = Path(__file__).resolve().parents[1] / "data" / "psid" / "GENROU"
    raw, dyr = data / "ThreeBusMulti.raw", data / "ThreeBus_GENROU.dyr"
    csv, npz = tmp_path / "modes.csv", tmp_path / "A.npz"
    assert main(["modes", str(raw), "--dyr", str(dyr), "-o", str(csv), "--state-matrix",
                 str(npz)]) == 0
    d = np.load(npz)
    lam = np.linalg.eigvals(d["A"])
    table = pd.read_csv(csv)
    upper = lam[lam.imag >= 0]
    assert len(table) == len(upper)
    np.testing.assert_allclose(np.sort(table["imag"].to_numpy()), np.sort(upper.imag), atol=1e-8)
    assert d["B"].shape == (d["A"].shape[0], 0) and list(d["outputs"]) == ["GENROU_102_1.omega"]
    system = load_case(raw, dyr).system
    system.setup()
    ref = np.sort_complex(modes(system).eigenvalues)
    np.testing.assert_allclose(np.sort_complex(lam), ref, rtol=1e-9, atol=1e-9)
    assert "no inputs" in capsys.readouterr().out


def test_modes_refuses_study_options_on_a_case(capsys, tmp_path):
    m = tmp_path / "c.m"
    m.write_text("x")
    assert main(["modes", str(m), "--load", "high"]) == 2
    assert "--load" in capsys.readouterr().err
