"""REPCA1 without ANDES: steady state, the line measurement, zero-parameter conventions (the ANDES
peer check is in ``test_repca1_peer.py``)."""

import numpy as np
import pytest
from sim_cases import two_machine_case
from test_reeca1 import FAULT, FLAGS, SG

from weakgrid.sim.errors import DataError
from weakgrid.sim.integrate import simulate
from weakgrid.sim.renewables import REECA1, REGCA1, REPCA1
from weakgrid.sim.system import System

PLANT = dict(VCFlag=1, RefFlag=1, Fflag=1, PLflag=1, dbd1=-0.01, dbd2=0.01, Kc=0.0)


def build(line=0, **plant):
    s = System(two_machine_case(x_line=0.2, p=0.6))
    s.add_machine("GENROU", "SG", 1, **SG)
    s.add_component(REGCA1()).add_regca1("PV", gen=0, Sn=100, Brkpt=0.8, Lvplsw=0, Lvpnt1=0.5)
    s.add_component(REECA1()).add_reeca1("EC", "PV", **FLAGS)
    s.add_component(REPCA1()).add_repca1("PC", "EC", line=line, **{**PLANT, **plant})
    return s.setup()


def test_equilibrium_and_line_measurement():
    s = build(Rc=0.0, Xc=0.1)
    F, ctx = s.residual(0.0, s.z0)
    assert np.max(np.abs(F)) < 1e-9
    # the converter at bus 1 = the line's from bus: Pline is the converter's export
    assert ctx.out["REPCA1.Pline"][0] == pytest.approx(0.6, abs=1e-9)
    assert ctx.out["REPCA1.f"][0] == 1.0 and ctx.out["REPCA1.Pext"][0] == 0.0


def test_plant_control_acts_in_a_fault():
    res = simulate(build(), 2.0, dt=1 / 240, events=FAULT)
    assert res.ok
    t = res.t
    assert np.ptp(np.asarray(res["PC.Qext"])) > 1e-3
    eh = np.asarray(res["PC.eHld"])
    dip = (t > 1.01) & (t < 1.09)
    assert np.ptp(eh[dip]) == 0                          # held below Vfrz


@pytest.mark.parametrize("zero", ["Tfltr", "Tfv", "Tp", "Tg"])
def test_zero_time_constants_are_pass_throughs(zero):
    s = build(**{zero: 0.0})
    F, _ = s.residual(0.0, s.z0)
    assert np.max(np.abs(F)) < 1e-9
    res = simulate(s, 2.0, dt=1 / 240, events=FAULT)
    assert res.ok
    st = {"Tfltr": "s0", "Tfv": "s3", "Tp": "s4", "Tg": "s6"}[zero]
    assert np.ptp(np.asarray(res[f"PC.{st}"])) == 0      # the bypassed state stays put


def test_without_a_line_the_line_power_is_zero():
    s = build(line=None, VCFlag=0, Kc=0.0)
    F, ctx = s.residual(0.0, s.z0)
    assert np.max(np.abs(F)) < 1e-9
    assert ctx.out["REPCA1.Pline"][0] == 0 and ctx.out["REPCA1.Qline"][0] == 0


def test_bad_links_are_refused():
    with pytest.raises(DataError, match="ree"):
        s = System(two_machine_case(x_line=0.2, p=0.6))
        s.add_machine("GENROU", "SG", 1, **SG)
        s.add_component(REGCA1()).add_regca1("PV", gen=0, Sn=100, Brkpt=0.8)
        s.add_component(REECA1()).add_reeca1("EC", "PV", **FLAGS)
        s.add_component(REPCA1()).add_repca1("PC", "nope", line=0, **PLANT)
        s.setup()
    with pytest.raises(DataError, match="line"):
        build(line=5)
