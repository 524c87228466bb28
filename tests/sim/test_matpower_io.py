"""MATPOWER .m files load to the same network as the case dict."""

import numpy as np
import pytest

from weakgrid.sim.errors import DataError
from weakgrid.sim.io.matpower import load_matpower
from weakgrid.sim.network import Network

from sim_cases import two_machine_case

CASE_M = """function mpc = two_bus
mpc.version = '2';
mpc.baseMVA = 100;
%% bus_i type Pd Qd Gs Bs area Vm Va baseKV zone Vmax Vmin
mpc.bus = [
	1	2	0	0	0	0	1	1.0	0	110	1	1.5	0.5;
	2	3	0	0	0	0	1	1.0	0	110	1	1.5	0.5;
];
%% bus Pg Qg Qmax Qmin Vg mBase status Pmax Pmin
mpc.gen = [
	1	80	0	999	-999	1.0	100	1	999	-999;
	2	0	0	999	-999	1.0	100	1	999	-999;
];
%% fbus tbus r x b rateA rateB rateC ratio angle status angmin angmax
mpc.branch = [
	1	2	0.0	0.3	0.0	0	0	0	0	0	1	-360	360;
];
"""


def test_m_file_matches_the_dict(tmp_path):
    p = tmp_path / "two_bus.m"
    p.write_text(CASE_M)
    case = load_matpower(p)
    ref = two_machine_case()
    assert case["baseMVA"] == 100.0
    np.testing.assert_array_equal(case["bus"], ref["bus"])
    np.testing.assert_array_equal(case["branch"], ref["branch"])
    np.testing.assert_array_equal(case["gen"][:, :10], ref["gen"][:, :10])
    pf1 = Network(case).solve_power_flow()
    pf2 = Network(ref).solve_power_flow()
    np.testing.assert_allclose(pf1.V, pf2.V, atol=1e-12)


def test_bad_files(tmp_path):
    with pytest.raises(DataError, match="does not exist"):
        load_matpower(tmp_path / "nope.m")
    p = tmp_path / "x.txt"
    p.write_text("")
    with pytest.raises(DataError, match=".m or .mat"):
        load_matpower(p)
