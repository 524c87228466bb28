"""classical_system takes a pandapower network object (a dict subclass), as its name does."""

import numpy as np

from weakgrid.sim.templates import classical_system, matpower_case


def test_a_pandapower_net_is_converted_not_taken_as_a_case_dict():
    import pandapower.networks as pn

    net = pn.case9()
    case = matpower_case(net)
    by_name = matpower_case("case9")
    assert {"baseMVA", "bus", "gen", "branch"} <= set(case)   # (and the source's names)
    for k in ("bus", "gen", "branch"):
        np.testing.assert_allclose(case[k], by_name[k])
    s = classical_system(net)
    assert s.machine_names == ["GENCLS_ext_grid_0", "GENCLS_gen_0", "GENCLS_gen_1"]
