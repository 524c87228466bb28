"""Putting a UPQC series branch into a branch of a network (MATPOWER dict, pandapower net)."""

import numpy as np
import pytest

from weakgrid.design import insert_upqc_matpower, insert_upqc_pandapower
from weakgrid.game.errors import ParameterError
from weakgrid.sim.network import Network


def _case():
    bus = np.array([[1, 3, 0, 0, 0, 0, 1, 1.0, 0, 20, 1, 1.5, 0.5],
                    [2, 1, 50, 20, 0, 0, 1, 1.0, 0, 20, 1, 1.5, 0.5],
                    [3, 2, 30, 10, 0, 0, 1, 1.0, 0, 20, 1, 1.5, 0.5]], float)
    gen = np.array([[1, 0, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11,
                    [3, 40, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11], float)
    branch = np.array([[1, 2, 0.01, 0.1, 0.02, 0, 0, 0, 0, 0, 1, -360, 360],
                       [2, 3, 0.01, 0.1, 0.02, 0, 0, 0, 0, 0, 1, -360, 360]], float)
    return {"baseMVA": 100.0, "bus": bus, "gen": gen, "branch": branch}


@pytest.mark.parametrize("side", ["from", "to"])
def test_matpower_insertion_keeps_the_operating_point_for_a_negligible_impedance(side):
    case = _case()
    ref = Network(case)
    ref.solve_power_flow()
    new, k, r, b1 = insert_upqc_matpower(case, 1, side, 0.0, 1e-7)
    assert (r, b1) == ((2 if side == "from" else 3), 4)
    assert list(new["branch"][k, :2]) == [r, b1]            # from = the shunt bus r
    net = Network(new)
    net.solve_power_flow()
    assert np.allclose(net.pf.V[:3], ref.pf.V, atol=1e-6)
    assert abs(net.pf.V[3] - net.pf.V[net.index_of(r)]) < 1e-6
    # the original branch now ends at the new bus on that side
    col = 0 if side == "from" else 1
    assert new["branch"][1, col] == 4 and case["branch"][1, col] != 4


def test_matpower_insertion_refuses_bad_input():
    with pytest.raises(ParameterError, match="upqc.side"):
        insert_upqc_matpower(_case(), 0, "middle", 0.0, 0.1)
    with pytest.raises(ParameterError, match="upqc.branch"):
        insert_upqc_matpower(_case(), 5, "from", 0.0, 0.1)


def test_pandapower_insertion_into_case9():
    import pandapower as pp
    import pandapower.networks as pn

    net = pn.case9()
    pp.runpp(net)
    ref = net.res_bus.vm_pu.copy()
    res = insert_upqc_pandapower(net, "line", 3, "to", 0.0, 1e-6, 100.0)
    assert res["shunt_bus"] == 5 and net.line.at[3, "to_bus"] == res["series_bus"]
    assert net.impedance.at[res["impedance"], "from_bus"] == 5
    pp.runpp(net)
    assert np.allclose(net.res_bus.vm_pu.loc[ref.index], ref, atol=1e-5)
    with pytest.raises(ParameterError, match="upqc.index"):
        insert_upqc_pandapower(net, "line", 99, "to", 0.0, 0.1, 100.0)
