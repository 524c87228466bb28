"""REGCA1 without ANDES: steady state, current injection, limits and bad input."""

import numpy as np
import pytest
from sim_cases import two_machine_case

from weakgrid.sim.errors import DataError
from weakgrid.sim.events import Fault
from weakgrid.sim.integrate import simulate
from weakgrid.sim.renewables import REGCA1
from weakgrid.sim.system import System

SG = dict(Sn=200, M=8.0, D=0.0, ra=0.003, xl=0.15, xd=1.8, xq=1.7, xd1=0.3, xq1=0.55, xd2=0.25,
          xq2=0.25, Td10=6.0, Td20=0.03, Tq10=0.4, Tq20=0.05, S10=0.05, S12=0.3)


def build(**re):
    s = System(two_machine_case(x_line=0.2, p=0.6))
    s.add_machine("GENROU", "SG", 1, **SG)
    c = s.add_component(REGCA1())
    c.add_regca1("PV", gen=0, Sn=100, **re)
    return s.setup()


def test_initial_point_is_an_equilibrium():
    s = build(Brkpt=0.8)
    F, ctx = s.residual(0.0, s.z0)
    assert np.max(np.abs(F)) < 1e-8
    # it injects the power-flow power of its generator row
    assert ctx.out["REGCA1.Pe"][0] == pytest.approx(0.6, abs=1e-9)


def test_low_voltage_cuts_active_current_and_recovers():
    s = build(Brkpt=0.8, Lvplsw=0)
    res = simulate(s, 3.0, dt=1 / 240, events=[Fault(bus=1, t_on=1.0, t_off=1.1, xf=0.05)])
    assert res.ok
    t = res.t
    lvg = np.asarray(res["PV.LVG"])
    assert lvg[(t > 1.01) & (t < 1.09)].max() < 1.0         # LVG acted during the dip
    ip = np.asarray(res["PV.Ipout"])
    assert ip[-1] == pytest.approx(ip[0], abs=1e-9)          # back to its (constant) command


def test_lvpl_limits_active_current_while_voltage_is_low():
    s = build(Brkpt=0.95, Zerox=0.5, Lvpl1=1.0, Lvpnt0=0.0, Lvpnt1=0.01)
    res = simulate(s, 2.0, dt=1 / 240, events=[Fault(bus=1, t_on=1.0, t_off=1.1, xf=0.08)])
    ip = np.asarray(res["PV.Ipout"])
    lvpl = np.asarray(res["PV.LVPL"])
    # held at the limit of the last Newton iterate: within the Newton tolerance of it
    assert np.all(ip <= lvpl + 1e-7)
    assert np.any(lvpl < 0.6)                                # the limit went below the 0.6 pu command
    assert np.isclose(ip[-1], 0.6 / abs(s.network.pf.V[0]), atol=1e-2)


def test_initial_current_beyond_lvpl_is_refused():
    with pytest.raises(DataError, match="Brkpt"):
        build(Brkpt=1.5, Zerox=0.5, Lvpl1=0.1)


def test_volim_below_initial_voltage_is_refused():
    with pytest.raises(DataError, match="Volim"):
        build(Brkpt=0.8, Volim=0.9)


def build_pvd1(shares=(0.5, 0.5), **kw):
    from weakgrid.sim.renewables import PVD1

    s = System(two_machine_case(x_line=0.2, p=0.6))
    s.add_machine("GENROU", "SG", 1, **SG)
    c = s.add_component(PVD1())
    for k, g in enumerate(shares):
        c.add_pvd1(f"D{k}", gen=0, Sn=100, gammap=g, gammaq=g, **kw)
    return s.setup()


def test_pvd1_shares_equilibrium_and_fault_ride_through():
    # wide frequency bands: one undamped machine without governor keeps a speed offset
    s = build_pvd1(ft0=55.0, ft1=56.0, ft2=64.0, ft3=65.0)
    F, ctx = s.residual(0.0, s.z0)
    assert np.max(np.abs(F)) < 1e-8
    assert ctx.out["PVD1.Pe"].sum() == pytest.approx(0.6, abs=1e-9)
    res = simulate(s, 3.0, dt=1 / 240, events=[Fault(bus=1, t_on=1.0, t_off=1.1, xf=0.05)])
    assert res.ok
    t = res.t
    R = np.asarray(res["D0.R"])
    assert R[(t > 1.02) & (t < 1.09)].max() < 1.0           # voltage trip band entered: current cut
    assert np.asarray(res["D0.Pe"])[-1] == pytest.approx(0.3, abs=2e-2)


def test_pvd1_shares_must_sum_to_one():
    with pytest.raises(DataError, match="gammap"):
        build_pvd1(shares=(0.5, 0.4))


def test_pvd1_initial_point_in_trip_band_refused():
    with pytest.raises(DataError, match="not a steady state"):
        build_pvd1(vt0=1.05, vt1=1.1, vt2=1.2, vt3=1.3)


def test_lvpl_release_resumes_from_the_limit_without_a_jump():
    """Regression: LVPL is an anti-windup limit that *resets* S0 (as ANDES). Holding S0 where it
    was and clipping the output instead left S0 at the 0.6-pu command while LVPL was 0.3 pu; when
    the filtered voltage passed Brkpt the output jumped by 0.3 pu in one step (and in ANDES's
    kundur_reg case with REECA1 the step could not converge)."""
    s = build(Brkpt=0.95, Zerox=0.5, Lvpl1=0.3, Lvpnt0=0.0, Lvpnt1=0.01, Tg=0.05)
    res = simulate(s, 2.0, dt=1 / 240, events=[Fault(bus=1, t_on=1.0, t_off=1.1, xf=0.08)])
    t, ip = res.t, np.asarray(res["PV.Ipout"])
    after = t > 1.1 + 1e-9
    assert ip[after].min() < 0.31                        # held at LVPL (<= Lvpl1) after clearing
    jumps = np.abs(np.diff(ip[after]))
    # released at Brkpt, S0 rises from the limit with the lag Tg: at most (0.6-0.3)*h/Tg per step
    assert jumps.max() < 0.3 * (1 / 240) / 0.05 * 1.05, jumps.max()
    assert ip[-1] == pytest.approx(0.6 / abs(s.network.pf.V[0]), abs=1e-2)


def test_lvpl_reset_convention_flag():
    """``LVPL_strict = 0`` (ANDES) resets S0 to LVPL only while dS0/dt >= 0. Without an
    electrical control the command is constant, S0 sits on it (dS0/dt = 0) when LVPL falls
    below it and is reset in both conventions: identical results. The flag takes 0 or 1."""
    kw = dict(Brkpt=0.95, Zerox=0.5, Lvpl1=0.3, Lvpnt0=0.0, Lvpnt1=0.01, Tg=0.05)
    ev = [Fault(bus=1, t_on=1.0, t_off=1.1, xf=0.08)]
    std = build(**kw)
    anc = build(LVPL_strict=0, **kw)
    assert not std.lim_pushing.any() and anc.lim_pushing.sum() == 1
    r_std, r_anc = simulate(std, 2.0, dt=1 / 240, events=ev), simulate(anc, 2.0, dt=1 / 240, events=ev)
    for r in (r_std, r_anc):
        s0, lvpl = np.asarray(r["PV.S0"]), np.asarray(r["PV.LVPL"])
        assert lvpl.min() < 0.31 and np.all(s0 <= lvpl + 1e-7)     # reset to LVPL in both
    # the same to the Newton tolerance (S0 at rest on its command: dS0/dt = 0 +- round-off)
    assert np.max(np.abs(np.asarray(r_std["PV.Ipout"]) - np.asarray(r_anc["PV.Ipout"]))) < 1e-7
    with pytest.raises(DataError, match="LVPL_strict"):
        build(LVPL_strict=0.5, **kw)


def build_shared(g_machine, g_conv, **gen):
    """Bus 1's generator row shared by a GENCLS (share g_machine) and a REGCA1 (g_conv)."""
    s = System(two_machine_case(x_line=0.2, p=0.6))
    s.add_machine("GENROU", "SG", 1, **SG)
    s.add_machine("GENCLS", "G1", 0, Sn=100, M=4.0, xd1=0.3, gammap=g_machine[0], gammaq=g_machine[1])
    c = s.add_component(REGCA1())
    c.add_regca1("PV", gen=0, Sn=100, Brkpt=0.8, gammap=g_conv[0], gammaq=g_conv[1])
    return s.setup(**gen)


def test_machine_and_converter_share_a_generator_row():
    # ANDES's ieee14_wt3n: a GENCLS that takes no power shares the slack row with a converter
    for gm, gc in [((0.3, 0.6), (0.7, 0.4)), ((0.0, 0.0), (1.0, 1.0))]:
        s = build_shared(gm, gc)
        F, ctx = s.residual(0.0, s.z0)
        assert np.max(np.abs(F)) < 1e-8
        pf = s.network.pf
        assert ctx.out["REGCA1.Pe"][0] == pytest.approx(gc[0] * pf.Pg[0], abs=1e-9)
        m = s.machine_number("G1")
        assert ctx.sig["Pe"][m] == pytest.approx(gm[0] * pf.Pg[0], abs=1e-9)
        assert ctx.sig["Qe"][m] == pytest.approx(gm[1] * pf.Qg[0], abs=1e-9)
    with pytest.raises(DataError, match="gammaq.*sum to 1.1"):
        build_shared((0.3, 0.7), (0.7, 0.4))
