"""The type-3 wind-turbine models (WTDTA1, WTARA1, WTPTA1, WTTQA1) built through the Python API,
without ANDES: initial point, links, and the drive train's torsional mode against its equations."""

from __future__ import annotations

import numpy as np
import pytest
from sim_cases import two_machine_case

from weakgrid.sim.errors import DataError
from weakgrid.sim.integrate import simulate
from weakgrid.sim.renewables import REECA1, REGCA1, WTARA1, WTDTA1, WTPTA1, WTTQA1
from weakgrid.sim.system import System

SG = dict(Sn=200, M=8.0, D=2.0, ra=0.003, xl=0.15, xd=1.8, xq=1.7, xd1=0.3, xq1=0.55, xd2=0.25,
          xq2=0.25, Td10=6.0, Td20=0.03, Tq10=0.4, Tq20=0.05, S10=0.05, S12=0.3)
FLAGS = dict(PFFLAG=0, VFLAG=0, QFLAG=0, PFLAG=0, PQFLAG=0)


def build(chain=("WTDTA1", "WTARA1", "WTPTA1", "WTTQA1"), dt=None, ree="EC"):
    s = System(two_machine_case(x_line=0.2, p=0.5))
    s.add_machine("GENROU", "SG", 1, **SG)
    s.add_component(REGCA1()).add_regca1("WT", gen=0, Sn=100, Brkpt=0.8, Lvplsw=0, Lvpnt1=0.5)
    s.add_component(REECA1()).add_reeca1("EC", "WT", **FLAGS)
    if "WTDTA1" in chain:
        s.add_component(WTDTA1()).add_wtdta1("DT", ree, **(dt or {}))
    if "WTARA1" in chain:
        s.add_component(WTARA1()).add_wtara1("AR", "DT", Ka=0.007)
    if "WTPTA1" in chain:
        s.add_component(WTPTA1()).add_wtpta1("PT", "AR", Kpw=10.0, Kiw=5.0)
    if "WTTQA1" in chain:
        s.add_component(WTTQA1()).add_wttqa1("TQ", "PT", Tflag=0, Kpp=1.0, Kip=0.5)
    return s.setup()


def test_initial_point_is_an_equilibrium_on_the_speed_map():
    s = build()
    F, ctx = s.residual(0.0, s.z0)
    assert np.max(np.abs(F)) < 1e-9
    # Pe0 = 0.5 pu lies between p2 = 0.4 (0.72) and p3 = 0.6 (0.86): w = 0.79
    dt = s.components["WTDTA1"]
    assert s.z0[dt.idx("wt")][0] == pytest.approx(0.79) and s.z0[dt.idx("wg")][0] == pytest.approx(0.79)
    assert s.z0[dt.idx("Tsh")][0] == pytest.approx(0.5 / 0.79)
    assert ctx.out["WTTQA1.Pref"][0] == pytest.approx(0.5) and ctx.out["REECA1.Pref"][0] == pytest.approx(0.5)
    assert ctx.out["WTARA1.Pm"][0] == pytest.approx(0.5)


def test_links_are_checked():
    with pytest.raises(DataError) as e:
        build(ree="nope")
    assert e.value.field == "ree"
    with pytest.raises(DataError) as e:
        build(dt=dict(Htfrac=1.0))
    assert e.value.field == "Htfrac"


def test_fault_runs_and_the_pitch_acts():
    from weakgrid.sim.events import Fault

    s = build()
    res = simulate(s, 3.0, dt=1 / 240, events=[Fault(bus=1, t_on=1.0, t_off=1.1, xf=0.05)])
    assert res.ok
    wg = res["DT.wg"]
    assert wg.max() > 0.79 + 1e-3          # the generator speeds up while the fault blocks its power
    assert res["PT.theta"].max() > 1e-4    # the turbine above its reference pitches
    assert res["PT.theta"].min() >= 0.0    # never below thmin


def test_torsional_mode_of_the_drive_train():
    """Without torque control and aerodynamics the drive train sees constant Pm and Pe, so a
    shaft-torque kick makes it ring at the mode of its three equations, linearized here from
    the block diagram: Ht2 dwt = -Pm/wt^2 dwt - dT - D (dwt - dwg), Hg2 dwg = Pe/wg^2 dwg + dT +
    D (dwt - dwg), dT' = K (dwt - dwg), K = Ht2 Hg2 Freq1^2 / (2 H)."""
    H, frac, f1, D = 4.0, 0.3, 2.0, 0.2
    s = build(chain=("WTDTA1",), dt=dict(H=H, Htfrac=frac, Freq1=f1, Dshaft=D))
    dt = s.components["WTDTA1"]
    k = int(dt.idx("Tsh")[0])
    s.z0[k] += 0.01
    res = simulate(s, 12.0, dt=1 / 480)
    assert res.ok
    rel = res["DT.wt"] - res["DT.wg"]
    Ht2, Hg2 = 2 * H * frac, 2 * H * (1 - frac)
    K = Ht2 * Hg2 * f1 ** 2 / (2 * H)
    P = 0.5                                              # Pm = Pe = p0 at w0 = 1
    A = np.array([[(-P - D) / Ht2, D / Ht2, -1 / Ht2],
                  [D / Hg2, (P - D) / Hg2, 1 / Hg2],
                  [K, -K, 0.0]])
    lam = np.linalg.eigvals(A)
    osc = lam[np.argmax(np.abs(lam.imag))]
    t = res.t
    up = np.nonzero((rel[:-1] < 0) & (rel[1:] >= 0))[0]
    tz = t[up] - rel[up] * (t[up + 1] - t[up]) / (rel[up + 1] - rel[up])
    w_sim = 2 * np.pi / np.mean(np.diff(tz))
    assert w_sim == pytest.approx(abs(osc.imag), rel=2e-3)
    # without damping terms the mode is Freq1 rad/s (ANDES's reading of Freq1)
    A0 = A.copy()
    A0[:2, :2] = 0.0
    assert np.max(np.abs(np.linalg.eigvals(A0).imag)) == pytest.approx(f1, rel=1e-12)
    # decay of the envelope as the eigenvalue's real part
    pk = np.array([np.max(np.abs(rel[(t >= a) & (t < b)])) for a, b in zip(tz[:-1], tz[1:])])
    rate = np.polyfit(tz[:-1], np.log(pk), 1)[0]
    assert rate == pytest.approx(osc.real, rel=0.05)
