"""REGCA1's PSS/E converter interface (``psse_interface``): P and Q with a per-step voltage estimate.

PSS/E computes a current-source converter's P and Q with ``Vest``, relaxed towards ``|V|`` by
halves once per integration step (``Vest_k = (Vest_(k-1) + |V_k|)/2``), while the network receives
the current itself (module docstring of :mod:`weakgrid.sim.renewables.regca1`; measured on PSS/E's
RENA results in ``tests/psse/test_rena_interface.py``). Checked here on a small grid with a fault:
the recursion holds at every recorded point, the network does not see it, and the default
(ANDES's, continuous) form is untouched.
"""

import numpy as np
import pytest
from sim_cases import two_machine_case

from weakgrid.sim.events import Fault
from weakgrid.sim.integrate import simulate
from weakgrid.sim.renewables import REGCA1
from weakgrid.sim.system import System

SG = dict(Sn=200, M=8.0, D=0.0, ra=0.003, xl=0.15, xd=1.8, xq=1.7, xd1=0.3, xq1=0.55, xd2=0.25,
          xq2=0.25, Td10=6.0, Td20=0.03, Tq10=0.4, Tq20=0.05, S10=0.05, S12=0.3)
DT = 1 / 240


def _run(**re):
    s = System(two_machine_case(x_line=0.2, p=0.6))
    s.add_machine("GENROU", "SG", 1, **SG)
    c = s.add_component(REGCA1())
    c.add_regca1("PV", gen=0, Sn=100, Brkpt=0.8, **re)
    s.setup()
    res = simulate(s, 1.5, dt=DT, events=[Fault(bus=1, t_on=1.0, t_off=1.1, xf=0.6)])
    assert res.ok
    bus = s.network.bus_ids[int(c.bus[0])]
    return s, c, res, bus


def _arrays(res, bus):
    t = np.asarray(res.t)
    v = np.asarray(res[f"bus{bus}.v"])
    return t, v, np.asarray(res["PV.Pe"]), np.asarray(res["PV.Qe"]), np.asarray(res["PV.Ipout"]), \
        np.asarray(res["PV.Iqout"])


def test_psse_interface_is_a_per_step_relaxation_of_the_power_voltage():
    s, c, res, bus = _run(psse_interface=1)
    assert hasattr(c, "accept")                         # discrete memory: updated at accepted points
    t, v, pe, qe, ip, iq = _arrays(res, bus)
    vest_rec = pe / ip                                  # the voltage P is computed with
    np.testing.assert_allclose(qe, iq * vest_rec, rtol=1e-10, atol=1e-14)   # one factor for P and Q
    # every recorded point k: Vest_k = (Vest_(k-1) + |V_k|)/2, Vest_(k-1) of the previous
    # accepted point (the pre-event record at the event time is one; so is the post-event one)
    np.testing.assert_allclose(vest_rec[1:], 0.5 * (vest_rec[:-1] + v[1:]), rtol=0, atol=1e-12)
    # at the fault: half the voltage step, then the rest by halves
    k = int(np.nonzero(np.isclose(t, 1.0))[0][-1])      # post-fault record
    assert v[k] < v[k - 1] - 0.05                       # a real voltage step
    assert vest_rec[k] == pytest.approx(0.5 * (v[k - 1] + v[k]), abs=1e-12)


def test_network_receives_the_current_not_the_estimated_power():
    """Without an electrical control nothing feeds back P or Q: the bus voltages of the PSS/E
    interface and of the continuous form are the same, only the converter's P and Q differ."""
    _, _, r1, bus = _run(psse_interface=1)
    _, c0, r0, _ = _run()
    assert not hasattr(c0, "accept")                    # the default keeps no memory
    t1, v1, pe1, _, ip1, _ = _arrays(r1, bus)
    t0, v0, pe0, _, ip0, _ = _arrays(r0, bus)
    np.testing.assert_array_equal(t1, t0)
    np.testing.assert_allclose(v1, v0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(ip1, ip0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(pe0, ip0 * v0, rtol=1e-12)   # continuous: P = Ipout |V|
    assert np.abs(pe1 - pe0).max() > 1e-3                 # the estimate lags the fault's voltage step


def test_psse_reader_sets_the_interface_other_routes_keep_the_default():
    assert REGCA1.psse_params({"Tg": 0.02}, _Ctx())["psse_interface"] == 1.0
    assert next(p for p in REGCA1.params if p.name == "psse_interface").default == 0.0


class _Ctx:
    mbase = 100.0
