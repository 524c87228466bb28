"""The PQ-controlled GTI's outer dc-voltage loop brings its dc link back to the set-point."""

import numpy as np

from sim_cases import build_gti_upqc_sg
from weakgrid.sim.events import Fault
from weakgrid.sim.integrate import simulate


def _run(kp_v, ki_v, t_end=8.0):
    s = build_gti_upqc_sg(mode="pq")
    g = s.components["GTI"]
    g.p["kp_v"][:] = kp_v
    g.p["ki_v"][:] = ki_v
    r = simulate(s, t_end, dt=2e-3, events=[Fault(3, 1.0, 1.05, xf=0.05)])
    assert r.ok
    return r


def test_steady_state_with_dc_loop_stays_put():
    s = build_gti_upqc_sg(mode="pq")
    g = s.components["GTI"]
    g.p["kp_v"][:], g.p["ki_v"][:] = 0.5, 2.0
    r = simulate(s, 3.0, dt=0.01)
    x = r.data[:, : s.nx]
    assert np.max(np.abs(x - x[0])) < 1e-8


def test_dc_loop_restores_the_dc_voltage():
    free = _run(0.0, 0.0)
    loop = _run(0.5, 2.0)
    Vc0 = 1.0
    off_free = abs(free["PV.Vc"][-1] - Vc0)
    off_loop = abs(loop["PV.Vc"][-1] - Vc0)
    # without the loop nothing pulls the dc link back after the fault's energy surplus
    assert off_free > 10 * off_loop
    assert off_loop < 2e-3
    # the integral state has absorbed the power mismatch: P_ac back at its pre-fault value
    assert abs(loop["PV.P_ac"][-1] - loop["PV.P_ac"][0]) < 1e-3
