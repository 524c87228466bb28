"""The run file: every signal by name, units in Parquet metadata, one row per instant."""

import numpy as np
import pyarrow.parquet as pq
import pytest

import weakgrid
from sim_cases import two_machine_case
from weakgrid.sim.errors import DataError
from weakgrid.sim.events import Fault
from weakgrid.sim.integrate import simulate
from weakgrid.sim.runfile import read_meta, read_samples, read_run, run_signals, write_run
from weakgrid.sim.system import System


def _run():
    s = System(two_machine_case())
    s.add_machine("GENCLS", "G1", 0, M=6.0, D=1.0, xd1=0.25)
    s.add_machine("GENCLS", "G2", 1, M=60.0, xd1=0.1)
    s.setup()
    return simulate(s, 0.5, dt=0.01, events=[Fault(2, 0.1, 0.15, xf=0.1)])


def test_every_signal_by_name_units_in_metadata(tmp_path):
    r = _run()
    p = write_run(tmp_path / "r.parquet", r, meta={"study": "x", "dt": 0.01})
    schema = pq.read_schema(p)
    assert set(r.names) <= set(schema.names)
    assert not any("[" in n for n in schema.names)          # no units inside names
    f = schema.field("G1.Pe").metadata
    assert f[b"unit"] == b"pu (Sb)" and f[b"si_unit"] == b"MW" and float(f[b"si_factor"]) == 100.0
    assert b"Sb = 100 MVA" == f[b"base"]
    assert schema.field("bus1.v").metadata[b"base"] == b"bus base 110 kV"
    assert read_meta(p)["study"] == "x" and read_meta(p)["weakgrid_version"] == weakgrid.__version__
    assert run_signals(p) == r.names


def test_read_back_exact_and_one_row_per_instant(tmp_path):
    r = _run()
    p = write_run(tmp_path / "r.parquet", r)
    df = weakgrid.read_run(p)
    assert np.all(np.diff(df["t"].to_numpy()) > 0)          # one row per instant
    full = read_run(p, pre_event=True)
    assert len(full) == len(r.t) and np.array_equal(full["G1.omega"].to_numpy(), r["G1.omega"])
    pre = full["pre_event"].to_numpy()
    # the fault's two breakpoints: a pre-event row each, followed by the post-event row
    for t_ev in (0.1, 0.15):
        i = np.flatnonzero(np.isclose(r.t, t_ev))
        assert len(i) == 2 and pre[i[0]] and not pre[i[1]]
    assert pre.sum() == len(r.t) - len(np.unique(r.t))
    post = ~pre
    assert np.array_equal(df["G1.omega"].to_numpy(), r["G1.omega"][post])
    assert df.attrs["units"]["G1.Pe"] == "pu (Sb)"
    si = read_run(p, ["G1.Pe", "bus*.v"], si=True)
    buses = [n for n in r.names if n.startswith("bus") and n.endswith(".v")]
    assert len(buses) >= 2 and list(si.columns) == ["t", "G1.Pe", *buses]
    assert si.attrs["units"]["G1.Pe"] == "MW"
    assert np.allclose(si["G1.Pe"], r.si("G1.Pe")[post])


def test_samples_alongside(tmp_path):
    r = _run()
    tk = np.array([0.0, 0.01, 0.02])
    u = np.arange(6.0).reshape(3, 2)
    p = write_run(tmp_path / "r.parquet", r, samples={"tk": tk, "u_applied": u,
                                                      "cost": np.array([1.0, np.nan, 3.0])})
    s = read_samples(p)
    assert list(s.columns) == ["t", "u_applied[0]", "u_applied[1]", "cost"]
    assert np.array_equal(s["t"], tk) and np.array_equal(s[["u_applied[0]", "u_applied[1]"]], u)
    assert np.isnan(s["cost"][1])
    assert len(read_run(p, pre_event=True)) == len(r.t)      # samples don't pad the instants
    with pytest.raises(DataError, match="one value"):
        write_run(tmp_path / "bad.parquet", r, samples={"t": tk, "u": np.zeros(4)})


def test_unknown_signal_lists_closest(tmp_path):
    p = write_run(tmp_path / "r.parquet", _run())
    with pytest.raises(DataError, match=r"G1\.omega"):
        read_run(p, ["G1.omegaa"])


def test_not_a_run_file(tmp_path):
    import pandas as pd

    q = tmp_path / "plain.parquet"
    pd.DataFrame({"a": [1.0]}).to_parquet(q)
    with pytest.raises(DataError, match="not a weakgrid run file"):
        read_run(q)


def test_read_run_is_imported_lazily():
    """``import weakgrid`` stays cheap: no numpy, pandas or pyarrow until a run is read."""
    import subprocess
    import sys

    code = ("import sys, weakgrid; heavy = {'numpy', 'pandas', 'pyarrow'} & set(sys.modules); "
            "assert not heavy, heavy; f = weakgrid.read_run; "
            "assert f.__module__ == 'weakgrid.sim.runfile'")
    subprocess.run([sys.executable, "-c", code], check=True)
