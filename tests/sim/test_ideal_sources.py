"""Ideal sources (weakgrid.sim.sources) against analytic results, without ANDES.

A GENCLS machine (bus 1) on a lossless line to an :class:`InfiniteBus` (bus 2) is the textbook
single-machine-infinite-bus system: the source must hold its bus phasor exactly, the energy
``W = M wb dw^2/2 - Pm d + E V/X (1 - cos(d - theta))`` must be conserved without damping, and the
small-signal frequency must be ``sqrt(wb K / M) / 2pi`` with ``K = E V cos(d0 - theta) / X``.
"""

import numpy as np
import pytest

from weakgrid.sim.errors import DataError
from weakgrid.sim.integrate import Simulator
from weakgrid.sim.sources import InfiniteBus, PVSource
from weakgrid.sim.system import System

from sim_cases import two_machine_case

XL, XD1, M = 0.3, 0.25, 6.0


def _smib(source=InfiniteBus):
    sys = System(two_machine_case(x_line=XL))
    sys.add_machine("GENCLS", "G1", 0, Sn=100, M=M, D=0.0, ra=0.0, xd1=XD1)
    src = source()
    src.add_source("S2", 1)
    sys.add_component(src)
    sys.setup()
    return sys


def test_initial_point_solves_the_dae():
    sys = _smib()
    F, ctx = sys.residual(0.0, sys.z0)
    assert np.max(np.abs(F)) < 1e-10
    assert ctx.out["InfiniteBus.P"][0] == pytest.approx(-0.8, abs=1e-9)   # absorbs the machine's 0.8 pu


def test_infinite_bus_holds_its_phasor_and_conserves_energy():
    sys = _smib()
    z0 = sys.z0.copy()
    c = sys.components["GENCLS"]
    z0[c.idx("omega")[0]] += 0.004
    sys.z0 = z0
    res = Simulator(sys, dt=1e-3, tol=1e-11).run(5.0)
    assert res.ok
    V2 = res["bus2.Vr"] + 1j * res["bus2.Vi"]
    V20 = sys.network.pf.V[1]
    assert np.max(np.abs(V2 - V20)) < 1e-9
    E, Pm, wb = sys.sig_defaults["vf0"][0], sys.sig_defaults["tm0"][0], c.wb[0]
    th, v = np.angle(V20), abs(V20)
    d, w = res["G1.delta"], res["G1.omega"]
    W = 0.5 * M * wb * (w - 1) ** 2 - Pm * d + E * v / (XL + XD1) * (1 - np.cos(d - th))
    kinetic0 = 0.5 * M * wb * 0.004 ** 2
    assert np.ptp(d) > 0.01 and np.ptp(W) / kinetic0 < 1e-4
    # small-signal frequency
    K = E * v * np.cos(sys.sig_defaults["delta0"][0] - th) / (XL + XD1)
    f_an = np.sqrt(wb * K / M) / (2 * np.pi)
    s = w - 1
    up = np.nonzero((s[:-1] < 0) & (s[1:] >= 0))[0]
    tc = res.t[up] - s[up] * (res.t[up + 1] - res.t[up]) / (s[up + 1] - s[up])
    f_sim = (len(tc) - 1) / (tc[-1] - tc[0])
    assert f_sim == pytest.approx(f_an, rel=2e-3)


def test_pv_source_holds_p_and_voltage_magnitude():
    # the slack row as a PV source: P = its power-flow value (-0.8), |V| held; its angle floats
    sys = _smib(PVSource)
    z0 = sys.z0.copy()
    z0[sys.components["GENCLS"].idx("omega")[0]] += 0.004
    sys.z0 = z0
    res = Simulator(sys, dt=1e-3, tol=1e-11).run(2.0)
    assert res.ok
    V2 = res["bus2.Vr"] + 1j * res["bus2.Vi"]
    assert np.ptp(np.abs(V2)) < 1e-9 and np.ptp(res["S2.P"]) < 1e-9
    assert res["S2.P"][0] == pytest.approx(-0.8, abs=1e-9)
    # no inertia anywhere and P balanced: the machine's electrical power stays 0.8, its speed drifts
    assert np.ptp(np.angle(V2)) > 1e-3


def test_two_sources_on_one_bus_refused():
    sys = System(two_machine_case())
    sys.add_machine("GENCLS", "G1", 0, Sn=100, M=M, D=0.0, ra=0.0, xd1=XD1)
    src = InfiniteBus()
    src.add_source("S2", 1)
    sys.add_component(src)
    pv = PVSource()
    pv.add_source("S3", 1)
    sys.add_component(pv)
    with pytest.raises(DataError, match="ideal source"):
        sys.setup()
