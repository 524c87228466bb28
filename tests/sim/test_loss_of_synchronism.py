"""Loss of synchronism is a swing of the rotor angles apart, not a large angle between machines.

Large grids operate with more than 180° between machines (case9241pegase 178°, ACTIVSg10k
236° at their power flow), which the old criterion (spread of the angles themselves > 180°)
took for a loss of synchronism at the first step. Oracle: three machines in a row, the outer
two behind phase shifters of +95° and -95°; a phase shifter rotates its side of the grid and
changes nothing else, so the shifted system must run exactly as the unshifted one (its outer
machines 190° further apart), and lose synchronism at the same instant after a fault that is
too long.
"""

import numpy as np
import pytest
from sim_cases import two_machine_case

from weakgrid.sim.errors import SimulationError
from weakgrid.sim.events import Fault
from weakgrid.sim.integrate import Simulator
from weakgrid.sim.network import SHIFT, VA
from weakgrid.sim.templates import classical_system

PHI = 95.0  # [deg] phase shifts at the outer buses' ends of their lines


def _system(shift):
    """Bus 1 (PV, 80 MW) -- shift +phi -- bus 2 (slack) -- shift -phi -- bus 3 (PV, 80 MW)."""
    c = two_machine_case(x_line=0.3, p=0.8)
    c["bus"] = np.vstack([c["bus"], c["bus"][0]])
    c["bus"][2, 0] = 3
    c["gen"] = np.vstack([c["gen"], c["gen"][0]])
    c["gen"][2, 0] = 3
    c["branch"] = np.vstack([c["branch"], c["branch"][0]])
    c["branch"][1, 0] = 3
    c["branch"][:, SHIFT] = [shift, -shift]
    c["bus"][[0, 2], VA] = [shift, -shift]             # the power flow's start on the stable side
    return classical_system(c, H=4.0, xd1=0.3, D=0.0, Sn=100.0)


def _run(shift, t_off, t_end=3.0):
    s = _system(shift)
    rec = [f"{n}.{q}" for n in s.machine_names for q in ("delta", "omega")]
    return Simulator(s, dt=1 / 120, tol=1e-10, record=rec).run(
        t_end, events=[Fault(1, 1.0, t_off)], on_failure="return")


def test_phase_shifted_machines_more_than_180_deg_apart_are_in_synchronism():
    s = _system(PHI)
    d = [s.z0[s.state_names().index(f"{n}.delta")] for n in s.machine_names]
    assert np.degrees(d[0] - d[2]) > 180.0               # the case is what it is meant to be
    a, b = _run(0.0, 1.1), _run(PHI, 1.1)
    assert a.ok and b.ok, b.failure
    for n, phi in (("GENCLS_1_1", PHI), ("GENCLS_2_1", 0.0), ("GENCLS_3_1", -PHI)):
        np.testing.assert_allclose(b[f"{n}.delta"] - np.radians(phi), a[f"{n}.delta"], atol=1e-8)
        np.testing.assert_allclose(b[f"{n}.omega"], a[f"{n}.omega"], atol=1e-10)
    assert np.ptp(a["GENCLS_1_1.delta"]) > 0.1                   # the fault swings the machines


def test_a_pole_slip_is_found_at_the_same_instant_with_and_without_the_shift():
    a, b = _run(0.0, 1.4), _run(PHI, 1.4)
    assert not a.ok and not b.ok
    for r in (a, b):
        assert isinstance(r.failure, SimulationError) and r.failure.cause == "loss of synchronism"
        assert "swings from the initial angles" in str(r.failure)
    assert a.failure.t == pytest.approx(b.failure.t, abs=1e-9)
    assert a.t[-1] > 1.0                                  # after the fault, not at the start
