"""Negative series resistance (legal in PSS/E and MATPOWER network equivalents).

case9241pegase has 75 branches with ``BR_R < 0``, ACTIVSg10k has some too; they used to be
refused. Oracles: circuit theory (the branch's active-power loss is ``R |I|^2``, here < 0),
and the series equivalence of two branches with a bus between them that carries nothing: a
branch ``(R, X)`` split into ``(R + d, X/2)`` and ``(-d, X/2)`` is the same two-port, so the
power flow and the whole time-domain trajectory must be those of the single branch.
"""

import warnings

import numpy as np
import pytest
from sim_cases import two_machine_case

from weakgrid.sim.errors import DataWarning
from weakgrid.sim.events import Fault
from weakgrid.sim.integrate import Simulator
from weakgrid.sim.network import BR_R, BR_X, Network
from weakgrid.sim.templates import classical_system

R, X, D_R = 0.02, 0.3, 0.05   # [pu] the line, and how much resistance the split moves


def _single():
    c = two_machine_case(x_line=X, p=0.8)
    c["branch"][0, BR_R] = R
    return c


def _split():
    """The line 1-2 as 1-3 (R + D_R, X/2) and 3-2 (-D_R, X/2); bus 3 is a PQ bus with nothing."""
    c = _single()
    mid = c["bus"][0].copy()
    mid[[0, 1, 2, 3]] = [3, 1, 0.0, 0.0]
    c["bus"] = np.vstack([c["bus"], mid])
    a, b = c["branch"][0].copy(), c["branch"][0].copy()
    a[[1, BR_R, BR_X]] = [3, R + D_R, X / 2]
    b[[0, BR_R, BR_X]] = [3, -D_R, X / 2]
    c["branch"] = np.vstack([a, b])
    return c


def test_negative_resistance_is_accepted_with_a_warning_naming_the_branch():
    with pytest.warns(DataWarning, match=r"1 branch.*negative series resistance.*branch 1 \(3-2\) "
                                         r"BR_R = -0.05.*negative_resistance = \[1\]"):
        net = Network(_split())
    assert net.negative_resistance == {1}
    assert net.branch[1, BR_R] == -D_R


def test_declared_negative_resistance_is_silent():
    with warnings.catch_warnings():
        warnings.simplefilter("error", DataWarning)
        net = Network({**_split(), "negative_resistance": [1]})
    assert net.negative_resistance == {1}


def test_power_flow_loss_of_a_negative_resistance_branch_is_r_i_squared():
    """Two buses joined only by a branch with R < 0: the branch generates R |I|^2 < 0 of loss."""
    c = _single()
    c["branch"][0, BR_R] = -0.01
    c["bus"][1, 2] = 50.0                      # a load at the slack bus, 50 MW
    with pytest.warns(DataWarning, match="negative series resistance"):
        net = Network(c)
    pf = net.solve_power_flow()
    i = (pf.V[0] - pf.V[1]) / complex(-0.01, X)
    loss = -0.01 * abs(i) ** 2                 # [pu] circuit theory
    assert loss < -1e-4
    gen_minus_load = pf.Pg.sum() - 0.5
    np.testing.assert_allclose(gen_minus_load, loss, rtol=1e-9, atol=1e-12)


def _run(case):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DataWarning)
        s = classical_system(case, H=4.0, xd1=0.3, D=0.0)
    F, _ = s.residual(0.0, s.z0)
    res = Simulator(s, dt=1 / 120, tol=1e-10, record=[f"{n}.omega" for n in s.machine_names]
                    + [f"{n}.delta" for n in s.machine_names]).run(
        3.0, events=[Fault(1, 1.0, 1.1)])
    return s, F, res


def test_split_with_a_negative_resistance_is_the_single_branch_in_power_flow_and_time_domain():
    s1, F1, r1 = _run(_single())
    s2, F2, r2 = _run(_split())
    # the initial point is an equilibrium, in both
    assert np.max(np.abs(F1)) < 1e-8 and np.max(np.abs(F2)) < 1e-8
    # the same operating point at buses 1 and 2 (bus 3 of the split is extra)
    v1, v2 = s1.network.pf.V, s2.network.pf.V
    np.testing.assert_allclose(v2[:2], v1, atol=1e-9)
    # and the same trajectory through a fault at bus 1
    assert r1.ok and r2.ok
    swing = np.ptp(r1[f"{s1.machine_names[0]}.delta"])
    assert swing > 0.05                        # the fault moves the machines
    for n in s1.machine_names:
        for q in ("omega", "delta"):
            np.testing.assert_allclose(r2[f"{n}.{q}"], r1[f"{n}.{q}"], atol=1e-8)
