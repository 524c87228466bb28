"""`weakgrid simulate CASE`: a plain case file (PSS/E, MATPOWER, pandapower JSON) with events
from the command line, the run file read back, and bad input refused with exit 2 and a
message naming the option, the value and the fix (never a traceback)."""

import io
import sys
from pathlib import Path

import numpy as np
import pytest

from weakgrid.cli.main import main

DATA = Path(__file__).resolve().parents[1] / "data" / "psid" / "GENROU"
RAW, DYR = DATA / "ThreeBusMulti.raw", DATA / "ThreeBus_GENROU.dyr"

# a three-bus MATPOWER case: two generators, a load at bus 3
CASE_M = """function mpc = three_bus
mpc.version = '2';
mpc.baseMVA = 100;
%% bus_i type Pd Qd Gs Bs area Vm Va baseKV zone Vmax Vmin
mpc.bus = [
	1	3	0	0	0	0	1	1.02	0	138	1	1.1	0.9;
	2	2	0	0	0	0	1	1.01	0	138	1	1.1	0.9;
	3	1	150	30	0	0	1	1.0	0	138	1	1.1	0.9;
];
%% bus Pg Qg Qmax Qmin Vg mBase status Pmax Pmin
mpc.gen = [
	1	80	0	999	-999	1.02	100	1	200	0;
	2	70	0	999	-999	1.01	100	1	200	0;
];
%% fbus tbus r x b rateA rateB rateC ratio angle status angmin angmax
mpc.branch = [
	1	2	0.01	0.1	0.0	0	0	0	0	0	1	-360	360;
	1	3	0.01	0.1	0.0	0	0	0	0	0	1	-360	360;
	2	3	0.01	0.1	0.0	0	0	0	0	0	1	-360	360;
];
"""


def _run(argv, capsys):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    assert "Traceback" not in err
    return code, out, err


def test_psse_fault_run_file_matches_the_simulator(tmp_path, capsys):
    """The run file's machine speed is the in-memory simulation's, and the fault moves it."""
    from weakgrid import read_run
    from weakgrid.sim.events import Fault
    from weakgrid.sim.integrate import simulate
    from weakgrid.sim.io.psse import from_psse

    out = tmp_path / "run.parquet"
    code, text, _ = _run(["simulate", RAW, "--dyr", DYR, "--fault", "103,0.5,0.6",
                          "--t-end", "2", "-o", out], capsys)
    assert code == 0
    assert "fault at bus 103 from 0.5 s to 0.6 s" in text and "wrote" in text
    df = read_run(out)
    assert df.attrs["meta"]["case_format"] == "psse"
    system, _ = from_psse(RAW, DYR)
    ref = simulate(system, 2.0, events=[Fault(103, 0.5, 0.6)])
    w = "GENROU_102_1.omega"
    t_ref, w_ref = ref.t, ref[w]
    keep = np.r_[np.diff(t_ref) > 0, True]     # the post-event value of each breakpoint
    np.testing.assert_allclose(df["t"].to_numpy(), t_ref[keep])
    np.testing.assert_allclose(df[w].to_numpy(), w_ref[keep], rtol=0, atol=1e-12)
    before = df[w][df["t"] < 0.5]
    assert np.abs(before - before.iloc[0]).max() < 1e-8           # quiet before the fault
    assert np.abs(df[w] - before.iloc[0]).max() > 1e-4             # the fault moves it


def test_matpower_case_gets_classical_machines_and_a_trip(tmp_path, capsys):
    m = tmp_path / "three_bus.m"
    m.write_text(CASE_M)
    out = tmp_path / "run.parquet"
    code, text, _ = _run(["simulate", m, "--fault", "3,0.2,0.25", "--trip", "2-3,0.25",
                          "--t-end", "1", "-o", out], capsys)
    assert code == 0, text
    assert "(matpower): 3 buses, 3 branches, 2 machines" in text
    assert "branch row 2 opens at 0.25 s" in text
    from weakgrid import read_run

    df = read_run(out, ["*.omega"])
    assert sorted(df.columns) == ["GENCLS_1_1.omega", "GENCLS_2_1.omega", "t"]   # GENCLS_<bus>_<k>
    assert (df.drop(columns="t").sub(1.0).abs().max() > 1e-5).all()


def test_pandapower_json_case(tmp_path, capsys):
    import pandapower as pp
    import pandapower.networks as pn

    js = tmp_path / "case9.json"
    pp.to_json(pn.case9(), str(js))
    code, text, _ = _run(["simulate", js, "--load-step", "5,0.1,20", "--t-end", "0.5"],
                         capsys)
    assert code == 0, text
    assert "(pandapower): 9 buses" in text and "3 machines" in text
    assert "load step at bus 5 at 0.1 s: +20 MW" in text


def test_a_run_that_loses_synchronism_exits_3_and_says_so(tmp_path, capsys):
    m = tmp_path / "three_bus.m"
    m.write_text(CASE_M)
    out = tmp_path / "run.parquet"
    code, text, err = _run(["simulate", m, "--fault", "1,0.1,1.0", "--t-end", "3", "-o", out],
                           capsys)
    assert code == 3
    assert "ended unstable" in err and "simulation stopped at t =" in err
    assert out.exists() and "the run up to t =" in text       # what ran is kept


@pytest.mark.parametrize("argv, words", [
    (["--fault", "999,1.0,1.1"], ["--fault", "999", "no bus", "101, 102, 103"]),
    (["--fault", "103,1.0"], ["--fault", "'103,1.0'", "BUS,T_ON,T_OFF[,XF]"]),
    (["--fault", "103,1.2,1.1"], ["--fault", "T_ON < T_OFF"]),
    (["--fault", "103,a,1.1"], ["--fault", "'a' is not a number"]),
    (["--trip", "7,1.0"], ["--trip", "rows 0..2"]),
    (["--trip", "101-102-9,1.0"], ["--trip", "circuit id", "101-102-1"]),
    (["--load-step", "103"], ["--load-step", "BUS,T,DP[,DQ]"]),
    (["--record", "GENROU_102_1.omegaa"], ["--record", "no such signal",
                                           "GENROU_102_1.omega"]),
    (["--scenario", "x"], ["--scenario", "applies to a study"]),
    (["-o", "run.csv"], ["--output", ".parquet"]),
    (["--fault", "103,1.0,1.1", "--t-end", "1.05"], ["--t-end", "1.1"]),
])
def test_bad_input_is_refused_with_the_option_named(argv, words, capsys, tmp_path,
                                                    monkeypatch):
    monkeypatch.chdir(tmp_path)
    code, _, err = _run(["simulate", RAW, "--dyr", DYR, *argv], capsys)
    assert code == 2
    for w in words:
        assert w in err, (w, err)


def test_missing_case_file_and_study_options_on_a_case(capsys, tmp_path):
    code, _, err = _run(["simulate", tmp_path / "nope.raw"], capsys)
    assert code == 2 and "nope.raw" in err and "no such file" in err
    code, _, err = _run(["simulate", "case1-weak-grid", "--fault", "1,1,2"], capsys)
    assert code == 2 and "--fault" in err and "plain case" in err


def test_an_andes_case_without_andes_names_the_extra(tmp_path, capsys, monkeypatch):
    x = tmp_path / "case.xlsx"
    x.write_bytes(b"not read")
    monkeypatch.setitem(sys.modules, "andes", None)     # `import andes` fails
    code, _, err = _run(["simulate", x], capsys)
    assert code == 2 and "weakgrid[andes]" in err


class _Terminal(io.StringIO):
    def isatty(self):
        return True


@pytest.mark.parametrize("flag", [None, "--quiet", "--no-progress"])
def test_progress_on_stderr_only_without_quiet(flag, capsys, monkeypatch):
    """On a terminal the bar shows on stderr; --quiet and --no-progress remove it, and
    --quiet also the import notes (the library's informational messages)."""
    term = _Terminal()
    monkeypatch.setattr(sys, "stderr", term)
    code = main(["simulate", str(RAW), "--dyr", str(DYR), "--t-end", "1"]
                + ([flag] if flag else []))
    out = capsys.readouterr().out
    assert code == 0
    assert ("simulating" in term.getvalue()) == (flag is None)
    assert ("note:" in out) == (flag != "--quiet")
    assert "final state" in out                     # the results stay


def test_a_run_beyond_the_limits_is_refused_unless_forced(capsys):
    """steps × recorded variables: 10⁶ s at 1/120 s needs tens of GiB."""
    code, text, err = _run(["simulate", RAW, "--dyr", DYR, "--t-end", "1e6"], capsys)
    assert code == 2
    assert "--t-end" in err and "GiB" in err and "--force" in err and "recorded variables" in err


def test_ctrl_c_says_what_was_kept(tmp_path, capsys, monkeypatch):
    from weakgrid.sim.integrate import Simulator

    run = Simulator.run

    def interrupted(self, t_end, *a, progress=None, **kw):
        def stop(t):
            progress(t)
            if t >= 0.5:
                raise KeyboardInterrupt
        return run(self, t_end, *a, progress=stop if progress else None, **kw)

    monkeypatch.setattr(Simulator, "run", interrupted)
    out = tmp_path / "run.parquet"
    code, _, err = _run(["simulate", RAW, "--dyr", DYR, "--t-end", "2", "-o", out], capsys)
    assert code == 130
    assert "interrupted at t = 0.5" in err and "nothing was kept" in err
    assert "was not written" in err and not out.exists()


@pytest.mark.andes
def test_an_andes_case_runs_with_its_own_events(capsys):
    """An ANDES case (Kundur, its Toggle at 2 s) with a command-line fault; the file's event
    after the end is said and left out."""
    andes = pytest.importorskip("andes")
    case = andes.get_case("kundur/kundur_full.xlsx")
    code, text, _ = _run(["simulate", case, "--fault", "8,0.5,0.55", "--t-end", "1.5"],
                         capsys)
    assert code == 0, text
    assert "(andes): 10 buses" in text and "4 machines" in text
    assert "(in the case file): after the end, not reached" in text
    assert "fault at bus 8 from 0.5 s to 0.55 s" in text
