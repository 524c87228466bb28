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
