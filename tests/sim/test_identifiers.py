"""Every importer keeps the source's identifiers: bus numbers, machine and branch names.

A result column of a machine or a bus is named by its source id, and an event addressed by a
source bus number acts at that bus (a three-phase fault there pulls that bus's voltage lowest).
The oracle of "acts at the right bus": during a bolted fault the faulted bus has the smallest
voltage magnitude of the network, and it is the only one near zero.
"""

from pathlib import Path

import numpy as np
import pytest

from weakgrid.sim.events import Fault
from weakgrid.sim.integrate import simulate
from weakgrid.sim.io.matpower import load_matpower
from weakgrid.sim.io.psse import from_psse
from weakgrid.sim.templates import classical_system

DATA = Path(__file__).resolve().parents[1] / "data"
RAW = DATA / "psse_reader" / "raw" / "GENROU__ThreeBusMulti.raw"   # buses 101, 102, 103
DYR = DATA / "psse_reader" / "ThreeBus_GENROU.dyr"                 # GENCLS at 101, GENROU at 102


def _faulted_bus(res, network, t_on, t_off):
    """The bus with the lowest voltage during the fault, and its voltage there [pu]."""
    k = np.nonzero((res.t > t_on + 1e-6) & (res.t < t_off - 1e-6))[0]
    v = {int(b): float(np.mean(res[f"bus{int(b)}.v"][k])) for b in network.bus_ids}
    low = min(v, key=v.get)
    return low, v


def _check_fault_at(system, bus, t_on=0.1, t_off=0.15):
    res = simulate(system, 0.3, dt=5e-3, events=[Fault(bus=bus, t_on=t_on, t_off=t_off, xf=1e-4)])
    low, v = _faulted_bus(res, system.network, t_on, t_off)
    assert low == bus and v[bus] < 0.05, v
    return res


# ---------------------------------------------------------------------------------- PSS/E
def test_psse_bus_numbers_machine_ids_and_branch_names():
    system, _ = from_psse(RAW, DYR)
    net = system.network
    assert sorted(int(b) for b in net.bus_ids) == [101, 102, 103]
    assert "GENROU_102_1" in system.machine_names
    assert any(n and n.startswith("101-102-") for n in net.branch_names)   # "I-J-CKT"
    system.setup()
    res = _check_fault_at(system, 103)
    assert "GENROU_102_1.omega" in res.names and "bus103.v" in res.names


# ---------------------------------------------------------------------------------- ANDES
@pytest.mark.andes
def test_andes_route_keeps_psse_bus_numbers():
    """Regression: ANDES's buses were renumbered 1..n (bus 103 became 3)."""
    andes = pytest.importorskip("andes")
    from weakgrid.sim.io.andes import from_andes

    ss = andes.load(str(RAW), addfile=str(DYR), setup=False, no_output=True,
                    default_config=True)
    system, _ = from_andes(ss, include_events=False)
    assert sorted(int(b) for b in system.network.bus_ids) == [101, 102, 103]
    assert system.andes_bus_id == {101: 101, 102: 102, 103: 103}
    system.setup()
    res = _check_fault_at(system, 103)
    assert "bus103.v" in res.names and "bus3.v" not in res.names


@pytest.mark.andes
def test_andes_device_names_are_their_idx():
    """Regression: ANDES's own idx ``GENROU_4`` gave the name ``GENROU_GENROU_4``."""
    pytest.importorskip("andes")
    from weakgrid.sim.io.andes import device_name, from_andes
    from weakgrid.sim.peer.andes_case import load_case

    ss = load_case("ieee14/ieee14_full.xlsx")
    system, _ = from_andes(ss, include_events=False)
    assert system.machine_names == list(ss.GENROU.idx.v)          # "GENROU_1" ... as ANDES
    assert system.components["EXST1"].names == list(ss.EXST1.idx.v)
    assert system.network.branch_names == list(ss.Line.idx.v)      # "Line_1" ...
    assert system.andes_device[("GENROU", "GENROU_1")] == "GENROU_1"
    # an idx that is not ANDES's generated one keeps the model in front
    assert device_name("GENROU", 3) == "GENROU_3" and device_name("REGCA1", "RE1") == "REGCA1_RE1"
    kundur, _ = from_andes(load_case("kundur/kundur_full.xlsx"), include_events=False)
    assert kundur.machine_names == ["GENROU_1", "GENROU_2", "GENROU_3", "GENROU_4"]


@pytest.mark.andes
def test_andes_idx_that_are_not_integers_are_numbered_in_order():
    pytest.importorskip("andes")
    from weakgrid.sim.io.andes import bus_numbers

    assert bus_numbers([1001, 7, 3]) == ({1001: 1001, 7: 7, 3: 3}, True)
    assert bus_numbers(["1001", "7"]) == ({"1001": 1001, "7": 7}, True)
    assert bus_numbers(["A", "B"]) == ({"A": 1, "B": 2}, False)


# ---------------------------------------------------------------------------------- MATPOWER
CASE_M = """function mpc = ids
mpc.version = '2';
mpc.baseMVA = 100;
mpc.bus = [
	101	3	0	0	0	0	1	1.0	0	110	1	1.5	0.5;
	205	2	50	10	0	0	1	1.0	0	110	1	1.5	0.5;
	307	1	80	20	0	0	1	1.0	0	110	1	1.5	0.5;
];
mpc.gen = [
	101	0	0	999	-999	1.0	100	1	999	-999;
	205	30	0	999	-999	1.0	100	1	999	-999;
	205	20	0	999	-999	1.0	100	1	999	-999;
];
mpc.branch = [
	101	205	0.01	0.1	0.0	0	0	0	0	0	1	-360	360;
	205	307	0.01	0.1	0.0	0	0	0	0	0	1	-360	360;
	101	307	0.01	0.1	0.0	0	0	0	0	0	1	-360	360;
];
mpc.bus_name = {
	'North';
	'South';
	'Mine';
};
"""


def test_matpower_bus_numbers_and_generators_by_bus(tmp_path):
    """Regression: the classical template named machines G0, G1, … by 0-based gen row."""
    p = tmp_path / "ids.m"
    p.write_text(CASE_M)
    s = classical_system(load_matpower(p))
    assert s.machine_names == ["GENCLS_101_1", "GENCLS_205_1", "GENCLS_205_2"]
    assert [int(b) for b in s.network.bus_ids] == [101, 205, 307]
    assert s.network.bus_names == {101: "North", 205: "South", 307: "Mine"}   # mpc.bus_name
    res = _check_fault_at(s, 307)
    assert "GENCLS_205_2.omega" in res.names and "bus307.v" in res.names


# ---------------------------------------------------------------------------------- pandapower
def _pandapower_net():
    pp = pytest.importorskip("pandapower")
    net = pp.create_empty_network(sn_mva=100.0, f_hz=50.0)
    for i, name in ((10, "North"), (20, "South"), (30, "Mine")):
        pp.create_bus(net, 110.0, index=i, name=name)
    pp.create_ext_grid(net, 10, vm_pu=1.0, name="Grid")
    pp.create_gen(net, 20, p_mw=40.0, vm_pu=1.0, name="Hydro", sn_mva=100.0)
    pp.create_gen(net, 30, p_mw=10.0, vm_pu=1.0, sn_mva=50.0)       # no name: its index
    pp.create_load(net, 30, p_mw=60.0, q_mvar=10.0)
    for a, b in ((10, 20), (20, 30), (10, 30)):
        pp.create_line_from_parameters(net, a, b, 10.0, 0.1, 0.4, 10.0, 1.0, name=f"{a}-{b}")
    return net


def test_pandapower_bus_index_and_element_names():
    """Regression: pandapower buses became ppc positions + 1 (bus 30 was 3), machines G<row>."""
    net = _pandapower_net()
    s = classical_system(net, f_hz=50.0, Sn=100.0)   # pandapower gens have PMAX = 1e9 MW
    assert s.machine_names == ["GENCLS_Grid", "GENCLS_Hydro", "GENCLS_gen_1"]
    assert [int(b) for b in s.network.bus_ids] == [10, 20, 30]
    assert s.network.bus_names == {10: "North", 20: "South", 30: "Mine"}
    assert s.network.branch_names == ["10-20", "20-30", "10-30"]
    assert s.network.bus_label(30) == '30 ("Mine")'
    res = _check_fault_at(s, 30)
    assert "GENCLS_Hydro.omega" in res.names and "bus30.v" in res.names


def test_pandapower_fused_buses_take_the_smallest_index():
    import pandapower as pp

    from weakgrid.sim.network import Network

    net = _pandapower_net()
    pp.create_bus(net, 110.0, index=40, name="Mine B")
    pp.create_switch(net, 30, 40, et="b", closed=True)      # fused with bus 30 by the conversion
    nw = Network.from_pandapower(net)
    assert nw.pandapower_bus[40] == nw.pandapower_bus[30] == 30
    assert [int(b) for b in nw.bus_ids] == [10, 20, 30]


def test_pandapower_generated_names_are_unique():
    from weakgrid.sim.network import _element_names

    # duplicate or empty names fall back to "<table>_<index>", so every id stays unique
    got = _element_names([("gen", 0, "A"), ("gen", 1, "A"), ("gen", 2, None), None,
                          ("ext_grid", 0, "gen_2"), ("ext_grid", 1, "Hydro")])
    assert got == ["gen_0", "gen_1", "gen_2", None, "ext_grid_0", "Hydro"]
    got = _element_names([("ext_grid", 0, "gen_1"), ("gen", 1, None)])   # named first
    assert got == ["ext_grid_0", "gen_1"]
