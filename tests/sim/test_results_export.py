"""Results: names, SI conversion, CSV/Parquet export and the plot helper."""

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pandas as pd

from sim_cases import two_machine_case
from weakgrid.sim.events import Fault
from weakgrid.sim.integrate import simulate
from weakgrid.sim.system import System


def _run():
    s = System(two_machine_case())
    s.add_machine("GENCLS", "G1", 0, M=6.0, D=1.0, xd1=0.25)
    s.add_machine("GENCLS", "G2", 1, M=60.0, xd1=0.1)
    s.setup()
    return simulate(s, 0.5, dt=0.01, events=[Fault(2, 0.1, 0.15, xf=0.1)])


def test_export_roundtrip(tmp_path):
    r = _run()
    for n in ("G1.delta", "G1.omega", "bus1.Vr", "bus1.Vi", "bus1.v", "G1.Pe", "G1.tm"):
        assert n in r
    assert r.unit("G1.Pe", si=True) == "MW"
    assert np.allclose(r.si("G1.Pe"), 100.0 * r["G1.Pe"])
    assert np.allclose(r.si("bus1.v"), 110.0 * r["bus1.v"])
    assert np.allclose(r.si("G1.delta"), np.degrees(r["G1.delta"]))
    r.to_csv(tmp_path / "a.csv", si=True)
    r.to_parquet(tmp_path / "a.parquet")
    a = pd.read_csv(tmp_path / "a.csv")
    b = pd.read_parquet(tmp_path / "a.parquet")
    # names are the variables' names; units live in attrs / Parquet metadata, not in names
    assert "G1.Pe" in a.columns and "G1.Pe" in b.columns and not any("[" in c for c in b.columns)
    assert np.allclose(a["G1.Pe"], r.si("G1.Pe"))
    assert np.array_equal(b["G1.omega"], r["G1.omega"])
    f = r.to_frame(si=True)
    assert list(f.columns) == ["t", *r.names] and f.attrs["units"]["G1.Pe"] == "MW"
    # the fault is visible: two samples at each event time
    assert np.sum(np.isclose(r.t, 0.1)) == 2


def test_plot_has_units():
    r = _run()
    ax = r.plot(["G1.Pe", "G2.Pe"], si=True)
    assert ax.get_xlabel() == "time [s]" and "MW" in ax.get_ylabel()


def test_network_from_pandapower():
    import pandapower.networks as pn

    from weakgrid.sim.network import Network

    net = Network.from_pandapower(pn.case9())
    pf = net.solve_power_flow()
    assert pf.mismatch < 1e-6 and net.nb == 9
