"""REECA1 without ANDES: steady states of the flag combinations, the voltage-dip logic, the
current limiter and the zero-parameter conventions (the ANDES peer check is in
``test_reeca1_peer.py``)."""

import numpy as np
import pytest
from sim_cases import two_machine_case

from weakgrid.sim.errors import DataError
from weakgrid.sim.events import Fault
from weakgrid.sim.integrate import simulate
from weakgrid.sim.renewables import REECA1, REGCA1
from weakgrid.sim.system import System

SG = dict(Sn=200, M=8.0, D=2.0, ra=0.003, xl=0.15, xd=1.8, xq=1.7, xd1=0.3, xq1=0.55, xd2=0.25,
          xq2=0.25, Td10=6.0, Td20=0.03, Tq10=0.4, Tq20=0.05, S10=0.05, S12=0.3)
FLAGS = dict(PFFLAG=0, VFLAG=0, QFLAG=0, PFLAG=0, PQFLAG=0)
FAULT = [Fault(bus=1, t_on=1.0, t_off=1.1, xf=0.05)]


def build(reg=None, **reec):
    s = System(two_machine_case(x_line=0.2, p=0.6))
    s.add_machine("GENROU", "SG", 1, **SG)
    s.add_component(REGCA1()).add_regca1("PV", gen=0, Sn=100, Brkpt=0.8, Lvplsw=0, Lvpnt1=0.5,
                                         **(reg or {}))
    s.add_component(REECA1()).add_reeca1("EC", "PV", **{**FLAGS, **reec})
    return s.setup()


def run(s, t=2.0):
    res = simulate(s, t, dt=1 / 240, events=FAULT)
    assert res.ok
    return res


@pytest.mark.parametrize("flags", [
    dict(), dict(PFFLAG=1), dict(PQFLAG=1), dict(QFLAG=1, Vref1=1.0), dict(QFLAG=1, PQFLAG=1, Vref1=1.0),
])
def test_initial_point_is_an_equilibrium(flags):
    s = build(**flags)
    F, ctx = s.residual(0.0, s.z0)
    assert np.max(np.abs(F)) < 1e-9
    assert ctx.out["REECA1.Ipcmd"][0] == pytest.approx(0.6, abs=1e-9)     # p0 / v at v = 1
    assert ctx.out["REECA1.Volt_dip"][0] == 0


def test_voltage_dip_freezes_the_power_order_and_injects_reactive_current():
    s = build(Kqv=5.0, Vref0=0.0, Thld=0.0)
    res = run(s)
    t = res.t
    dip = np.asarray(res["EC.Volt_dip"]) > 0
    assert dip[(t > 1.0) & (t < 1.1)].all() and not dip[(t < 1.0) | (t > 1.2)].any()
    pord = np.asarray(res["EC.Pord"])
    assert np.ptp(pord[dip]) < 1e-12                         # s5 frozen in the dip
    iqinj = np.asarray(res["EC.Iqinj"])
    assert iqinj[dip].max() > 0.5                            # Kqv (Vref0 - s0) outside the dead band
    assert np.all(iqinj[~dip] == 0)                          # Thld = 0: only in the dip


def test_thld_negative_keeps_injecting_after_the_dip():
    res = run(build(Kqv=5.0, Vref0=0.0, Thld=-0.3, dbd1=-0.001, dbd2=0.001))
    t, iqinj = res.t, np.asarray(res["EC.Iqinj"])
    dip = np.asarray(res["EC.Volt_dip"]) > 0
    after = (~dip) & (t > 1.1)
    assert np.any(iqinj[after & (t < 1.35)] != 0)            # held "as in the dip" for |Thld|
    assert np.all(iqinj[t > 1.45] == 0)


def test_iqinj_is_clipped_to_iqh1():
    res = run(build(Kqv=5.0, Vref0=0.0, Iqh1=0.3))
    assert np.asarray(res["EC.Iqinj"]).max() == pytest.approx(0.3, abs=1e-12)


def test_current_limit_q_priority_reached():
    res = run(build(Kqv=5.0, Vref0=0.0, Imax=0.9))
    ip, iq = np.asarray(res["EC.Ipcmd"]), np.asarray(res["EC.Iqcmd"])
    assert np.max(np.hypot(ip, iq)) == pytest.approx(0.9, abs=1e-9)   # the limit is reached, not exceeded
    iqmax = np.asarray(res["EC.Iqmax"])
    assert np.any(np.abs(iq - iqmax) < 1e-12)                          # Q priority: Iq up to Imax


def test_thld2_holds_ipmax_after_the_dip():
    res = run(build(Kqv=5.0, Vref0=0.0, Imax=0.9, Thld2=0.2))
    t, ipmax = res.t, np.asarray(res["EC.Ipmax"])
    dip = np.asarray(res["EC.Volt_dip"]) > 0
    end = t[dip].max()
    held = (t > end + 1e-9) & (t < end + 0.19)
    assert np.ptp(ipmax[held]) < 1e-12                       # held for Thld2 ...
    assert ipmax[held][0] < ipmax[0] - 0.1                   # ... at its (low) value in the dip
    assert np.asarray(res["EC.fThld2"])[t > end + 0.25].max() == 0


# ----------------------------------------------------------- zero-parameter conventions
def _traj(res):
    return np.column_stack([res["SG.omega"], res["PV.Pe"], res["PV.Qe"]])


def test_zero_time_constants_are_pass_throughs():
    # (a tiny T is no reference at this step: the trapezoidal rule rings on a lag with T << h)
    res = run(build(Kqv=0.0, PFFLAG=1, Vdip=0.05, Trv=0.0, Tp=0.0, Tiq=0.0, Tpord=0.0))
    assert np.asarray(res["EC.Volt_dip"]).max() == 0
    # Tpord = 0: the power order is its input (the rate-limited reference), no lag
    assert np.max(np.abs(np.asarray(res["EC.Pord"]) - np.asarray(res["EC.pfilt"]))) < 1e-12
    # the bypassed lags' states stay put; their outputs follow the inputs (Qsel = s4_y moves)
    for st in ("s0", "S1", "s4", "s5"):
        assert np.ptp(np.asarray(res[f"EC.{st}"])) == 0
    assert np.ptp(np.asarray(res["EC.Qsel"])) > 1e-3
    s = build(Trv=0.0, Tp=0.0, Tiq=0.0, Tpord=0.0)
    F, _ = s.residual(0.0, s.z0)
    assert np.max(np.abs(F)) < 1e-9
    # in a dip, a pass-through that would be frozen holds its output (as ANDES's frozen equation)
    res = run(build(Kqv=0.0, Tiq=0.0, Tpord=0.0))
    dip = np.asarray(res["EC.Volt_dip"]) > 0
    assert dip.any()
    assert np.ptp(np.asarray(res["EC.Pord"])[dip]) == 0 and np.ptp(np.asarray(res["EC.s4_y"])[dip]) == 0


def test_imax_zero_means_no_limit():
    a = run(build(Kqv=5.0, Vref0=0.0, Imax=0.0))
    b = run(build(Kqv=5.0, Vref0=0.0, Imax=1e6))
    assert np.max(np.abs(_traj(a) - _traj(b))) < 1e-9
    assert np.asarray(a["EC.Ipmax"]).min() > 1.0


def test_vref0_zero_is_the_initial_voltage():
    s = build()
    v0 = abs(s.network.pf.V[0])
    a = run(build(Kqv=5.0, Vref0=0.0))
    b = run(build(Kqv=5.0, Vref0=v0))
    assert np.max(np.abs(_traj(a) - _traj(b))) < 1e-12


def test_non_monotone_vdl_table_is_switched_off():
    bad = dict(Iq1=5.0, Iq2=0.1, Iq3=0.1, Iq4=0.1, Ip1=5.0, Ip2=0.1, Ip3=0.1, Ip4=0.1)
    _, ctx = (s := build(Imax=3.0, **bad)).residual(0.0, s.z0)
    assert ctx.out["REECA1.Iqmax"][0] == 1e8    # table off: no Q-priority limit at all (as ANDES)
    _, ctx = (s := build(Imax=3.0)).residual(0.0, s.z0)
    assert ctx.out["REECA1.Iqmax"][0] == pytest.approx(3.0)    # (Imax below the default VDL1)
    _, ctx = (s := build(Imax=3.0, Iq4=0.7, Iq3=0.6, Iq2=0.5, Iq1=0.4)).residual(0.0, s.z0)
    assert ctx.out["REECA1.Iqmax"][0] == pytest.approx(0.7)    # a monotone table acts
    a = run(build(Kqv=1.0, Vref0=0.0, Imax=3.0, **bad))
    b = run(build(Kqv=1.0, Vref0=0.0, Imax=3.0, **{k: 1e6 for k in bad}))
    assert np.max(np.abs(_traj(a) - _traj(b))) < 1e-9


def test_p0_zero_with_pf_control_holds_q():
    s = System(two_machine_case(x_line=0.2, p=0.0))
    s.add_machine("GENROU", "SG", 1, **SG)
    s.add_component(REGCA1()).add_regca1("PV", gen=0, Sn=100, Brkpt=0.8, Lvplsw=0, Lvpnt1=0.5)
    s.add_component(REECA1()).add_reeca1("EC", "PV", **{**FLAGS, "PFFLAG": 1})
    s.setup()
    F, _ = s.residual(0.0, s.z0)
    assert np.all(np.isfinite(F)) and np.max(np.abs(F)) < 1e-9


def test_bad_link_and_start_in_a_dip_are_refused():
    s = System(two_machine_case(x_line=0.2, p=0.6))
    s.add_machine("GENROU", "SG", 1, **SG)
    s.add_component(REGCA1()).add_regca1("PV", gen=0, Sn=100, Brkpt=0.8)
    s.add_component(REECA1()).add_reeca1("EC", "nope", **FLAGS)
    with pytest.raises(DataError, match="reg"):
        s.setup()
    with pytest.raises(DataError, match="Vdip"):
        build(Vdip=1.05, Vup=1.2)
    with pytest.raises(DataError, match="PFFLAG"):
        build(PFFLAG=None)
