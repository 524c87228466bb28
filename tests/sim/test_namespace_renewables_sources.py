"""The renewable models (REGCA1, REECA1, REECB1, REPCA1, PVD1, ESD1, the type-3 wind chain
WTDTA1, WTARA1, WTPTA1, WTTQA1) and the ideal sources (InfiniteBus, PVSource) on another array
namespace: the residual and every output on ``array_api_strict`` equal NumPy's bit for bit, at
the initial point and at points far enough out to take their limits, dips and trips."""

from __future__ import annotations

import numpy as np
import pytest
from test_namespace import _check, _no_numpy_on_strict_arrays, _points, _same  # noqa: F401

from weakgrid.sim.namespace import namespace_models, on_namespace
from weakgrid.sim.renewables import (ESD1, PVD1, REECA1, REECB1, REGCA1, REPCA1, WTARA1, WTDTA1,
                                     WTPTA1, WTTQA1)
from weakgrid.sim.sources import InfiniteBus, PVSource
from weakgrid.sim.system import System

xps = pytest.importorskip("array_api_strict")

SG = dict(Sn=200, M=8.0, D=2.0, ra=0.003, xl=0.15, xd=1.8, xq=1.7, xd1=0.3, xq1=0.55, xd2=0.25,
          xq2=0.25, Td10=6.0, Td20=0.03, Tq10=0.4, Tq20=0.05, S10=0.05, S12=0.3)
FLAGS = dict(PFFLAG=0, VFLAG=0, QFLAG=0, PFLAG=0, PQFLAG=0)


def star_case(p=(0.5, 0.4, 0.3, 0.2), x_line=0.2):
    """Buses 1..n+1: a generator of ``p[k]`` pu at bus k+1 (PV), each on a line to bus n+1 (the
    slack's), and a line between buses 1 and 2 (MATPOWER form)."""
    n = len(p)
    bus = np.array([[k + 1, 2 if k < n else 3, 0, 0, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5]
                    for k in range(n + 1)], dtype=float)
    gen = np.array([[k + 1, (list(p) + [0.0])[k] * 100, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11
                    for k in range(n + 1)], dtype=float)
    branch = [[k + 1, n + 1, 0.01, x_line, 0.0, 0, 0, 0, 0, 0, 1, -360, 360] for k in range(n)]
    branch.append([1, 2, 0.02, 0.3, 0.0, 0, 0, 0, 0, 0, 1, -360, 360])
    return {"baseMVA": 100.0, "bus": bus, "gen": gen, "branch": np.array(branch, dtype=float)}


def converters_and_sources():
    """REGCA1 (two shares of one row: the currents added at a repeated bus; LVPL on and off,
    PSS/E's interface and rates), PVD1 (P and Q priority, recovery factors on and off, a
    Q-V droop and frequency droop), ESD1 (state of charge between its limits), a PVSource and
    an InfiniteBus (the slack)."""
    s = System(star_case(p=(0.5, 0.4, 0.3)))
    reg = s.add_component(REGCA1())
    reg.add_regca1("R0", gen=0, Sn=100, gammap=0.6, gammaq=0.6, Brkpt=0.8, Lvplsw=1, Lvpnt1=0.5)
    reg.add_regca1("R1", gen=0, Sn=80, gammap=0.4, gammaq=0.4, Brkpt=0.9, Lvplsw=0, Lvpnt0=0.3,
                   Lvpnt1=0.6, psse_interface=1, rates_per_s=1, Khv=0.7, Volim=1.1)
    pv = s.add_component(PVD1())
    pv.add_pvd1("D0", gen=1, Sn=100, gammap=0.3, gammaq=0.3, pqflag=1, ddn=2.0, fdbd=-0.01,
                ft0=59.0, ft1=59.5, ft2=60.5, ft3=61.0)
    pv.add_pvd1("D1", gen=1, Sn=60, gammap=0.3, gammaq=0.3, pqflag=0, recflag=0, xc=0.05,
                v0=0.95, v1=1.05, dqdv=-2.0, ialim=1.1)
    es = s.add_component(ESD1())
    es.add_pvd1("E0", gen=1, Sn=100, gammap=0.4, gammaq=0.4, SOCmin=0.2, SOCmax=0.8, SOCinit=0.5,
                En=0.5, EtaC=0.9, EtaD=0.95, pqflag=0)
    pvs = PVSource()
    pvs.add_source("S2", 2)
    s.add_component(pvs)
    inf = InfiniteBus()
    inf.add_source("S3", 3)
    s.add_component(inf)
    return s.setup()


def electrical_and_plant_controls():
    """REGCA1 + REECA1 (P and Q priority, every flag on and off, VDL tables, Thld > 0 and < 0,
    the dip and post-dip holds), REECB1 (ANDES's and PSS/E's forms) and REPCA1 on both types
    (a monitored line and a terminal measurement), with a GENROU as the slack."""
    s = System(star_case(p=(0.5, 0.4, 0.3, 0.2)))
    s.add_machine("GENROU", "SG", 4, **SG)
    reg = s.add_component(REGCA1())
    for k in range(4):
        reg.add_regca1(f"R{k}", gen=k, Sn=100, Brkpt=0.8, Lvplsw=k % 2, Lvpnt1=0.5)
    ec = s.add_component(REECA1())
    ec.add_reeca1("A0", "R0", **FLAGS, Thld=0.5, Iqfrz=0.1, Thld2=0.3, Vq1=0.2, Vq2=0.5, Vq3=0.8,
                  Vq4=1.2, Iq1=0.5, Iq2=0.8, Iq3=1.0, Iq4=1.2, Vp1=0.2, Vp2=0.5, Vp3=0.8, Vp4=1.2,
                  Ip1=0.5, Ip2=0.8, Ip3=1.0, Ip4=1.2, Imax=1.3, Kqv=2.0, dbd1=-0.05, dbd2=0.05)
    ec.add_reeca1("A1", "R1", PFFLAG=1, VFLAG=1, QFLAG=1, PFLAG=1, PQFLAG=1, Thld=-0.5, Imax=1.2,
                  Tiq=0.0, Tpord=0.0, Kqv=1.5)
    eb = s.add_component(REECB1())
    eb.add_reeca1("B0", "R2", PFFLAG=0, VFLAG=1, QFLAG=1, PQFLAG=0, wecc=1, VMIN=0.9, VMAX=1.1)
    eb.add_reeca1("B1", "R3", **{k: v for k, v in FLAGS.items() if k != "PFLAG"}, wecc=0, Imax=1.1)
    pc = s.add_component(REPCA1())
    pc.add_repca1("P0", "A0", line=0, VCFlag=1, RefFlag=1, Fflag=1, PLflag=1, dbd1=-0.01,
                  dbd2=0.01, Kc=0.0, Rc=0.0, Xc=0.1)
    pc.add(("P1"), {"ree": "B0", "line": None, "terminal": True},
           dict(VCFlag=0, RefFlag=0, Fflag=0, PLflag=0, Kc=0.02, Vfrz=0.7))
    return s.setup()


def wind_chains():
    """Three type-3 turbines: two with the full chain (drive train, aerodynamics, pitch and
    torque control: Tflag 0 and 1, the speed reset of wg), one with drive train and
    aerodynamics alone (no pitch: theta0); the first with PFLAG = 1 in its REECA1."""
    s = System(star_case(p=(0.5, 0.4, 0.3)))
    s.add_machine("GENROU", "SG", 3, **SG)
    reg = s.add_component(REGCA1())
    ec = s.add_component(REECA1())
    for k in range(3):
        reg.add_regca1(f"W{k}", gen=k, Sn=100, Brkpt=0.8, Lvplsw=0, Lvpnt1=0.5)
        ec.add_reeca1(f"E{k}", f"W{k}", **{**FLAGS, "PFLAG": int(k == 0)})
    dt = s.add_component(WTDTA1())
    ar = s.add_component(WTARA1())
    for k in range(3):
        dt.add_wtdta1(f"DT{k}", f"E{k}")
        ar.add_wtara1(f"AR{k}", f"DT{k}", Ka=0.007 * (k + 1), theta0=0.0)
    pt = s.add_component(WTPTA1())
    pt.add_wtpta1("PT0", "AR0", Kpw=10.0, Kiw=5.0)
    pt.add_wtpta1("PT2", "AR2", Kpw=8.0, Kiw=4.0, thmax=10.0)
    tq = s.add_component(WTTQA1())
    tq.add_wttqa1("TQ0", "PT0", Tflag=0, Kpp=1.0, Kip=0.5, wg_reset=1)
    tq.add_wttqa1("TQ2", "PT2", Tflag=1, Kpp=0.5, Kip=0.3)
    return s.setup()


def _far_points(system, seed):
    """``_points`` and two more: every bus voltage scaled to 45 % (dips, low-voltage current
    management, LVPL, trips) and to 125 % (high-voltage current management), the states moved
    by up to ±0.1."""
    rng = np.random.default_rng(seed)
    z0 = system.z0
    vb = np.array([k for b in range(system.network.nb) for k in system.bus_vars(b)])
    low, high = z0 + rng.uniform(-0.1, 0.1, z0.shape), z0 + rng.uniform(-0.1, 0.1, z0.shape)
    low[vb], high[vb] = 0.45 * z0[vb], 1.25 * z0[vb]
    return np.concatenate([_points(system, seed), low[None], high[None]])


BUILDERS = {"converters_and_sources": converters_and_sources,
            "electrical_and_plant_controls": electrical_and_plant_controls,
            "wind_chains": wind_chains}


@pytest.mark.parametrize("name", list(BUILDERS))
def test_the_renewables_and_ideal_sources_evaluate_on_the_strict_namespace_as_on_numpy(name):
    system = BUILDERS[name]()
    assert namespace_models(system) == []
    _check(system, _far_points(system, seed=7))
    _check(system, _far_points(system, seed=8))


def test_the_electrical_controls_holds_evaluate_on_the_strict_namespace_as_on_numpy():
    """REECA1 in and after a dip (the held PI outputs, power order and Ipmax, Thld and Thld2
    running), REPCA1 below Vfrz (its held error), REGCA1's PSS/E voltage estimate; then the
    discrete memory updated at an accepted point (``accept``) on both namespaces."""
    system = electrical_and_plant_controls()
    ec, pc = system.components["REECA1"], system.components["REPCA1"]
    ec._dip_prev = np.array([True, False])
    ec._t_thld = np.array([-np.inf, 0.4])
    ec._t_thld2 = np.array([0.2, -np.inf])
    ec._piq_hold = ec._piq_hold + 0.3
    ec._piv_hold = ec._piv_hold - 0.2
    ec._pord_hold = ec._pord_hold * 0.5
    ec._ipmax_hold = ec._ipmax_hold * 0.7
    ec._s4_hold = ec._s4_hold + 0.1
    pc._ehold = np.array([0.02, -0.03])
    Z = _far_points(system, seed=9)
    _check(system, Z)
    other = on_namespace(system, xps)
    _, ctx = system.device_residual(0.0, Z[2])
    _, ctxs = other.device_residual(0.0, xps.asarray(Z[2]))
    for model in ("REECA1", "REECB1", "REPCA1"):
        system.components[model].accept(0.5, ctx)
        other.components[model].accept(0.5, ctxs)
    for model, keys in (("REECA1", ("_t_thld", "_t_thld2", "_piq_hold", "_piv_hold", "_s4_hold",
                                    "_pord_hold", "_ipmax_hold")),
                        ("REECB1", ("_piq_hold", "_piv_hold", "_s4_hold", "_pord_hold")),
                        ("REPCA1", ("_ehold",))):
        for k in keys:
            _same(getattr(system.components[model], k), getattr(other.components[model], k),
                          f"{model}.{k}")


def test_regca1_psse_voltage_estimate_accept_on_the_strict_namespace_as_on_numpy():
    system = converters_and_sources()
    Z = _far_points(system, seed=10)
    other = on_namespace(system, xps)
    _, ctx = system.device_residual(0.0, Z[1])
    _, ctxs = other.device_residual(0.0, xps.asarray(Z[1]))
    system.components["REGCA1"].accept(0.0, ctx)
    other.components["REGCA1"].accept(0.0, ctxs)
    _same(system.components["REGCA1"]._vest, other.components["REGCA1"]._vest, "_vest")
    _check(system, Z)      # the next evaluation with the updated estimate
