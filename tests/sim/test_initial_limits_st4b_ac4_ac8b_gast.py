"""ESST4B, EXAC4, AC8B, GAST: an operating point beyond a limit is refused at setup.

As for the other models (``test_initial_limits.py``): a non-windup state (ESST4B's PI
integrators, AC8B's regulator) or a static limit / gate (EXAC4's input and output limiters,
GAST's temperature low-value gate) that the initial operating point would violate raises
``DataError`` naming device, field, value and limit; ``setup(limits="warn")`` warns instead.
Within the limits each model starts at rest (the initial point solves the DAE).
"""

import warnings

import numpy as np
import pytest

from weakgrid.sim.errors import DataError
from weakgrid.sim.integrate import simulate
from weakgrid.sim.system import System

from sim_cases import two_machine_case

GENROU = dict(Sn=100, M=7.0, D=0.0, ra=0.002, xl=0.15, xd=1.8, xq=1.7, xd1=0.3, xq1=0.55,
              xd2=0.25, xq2=0.25, Td10=6.0, Td20=0.03, Tq10=0.4, Tq20=0.05, S10=0.05, S12=0.3)
ESST4B = dict(TR=0.01, KPR=3.0, KIR=2.0, VRMAX=8.0, VRMIN=0.0, TA=0.02, KPM=1.0, KIM=1.0, VMMAX=1.0,
              VMMIN=0.0, KG=1.0, KP=4.0, KI=0.1, VBMAX=18.0, KC=0.1, XL=0.01, THETAP=0.0, VGMAX=20.0)
EXAC4 = dict(TR=0.01, VIMAX=5.0, VIMIN=-0.1, TC=1.0, TB=1.0, KA=80.0, TA=0.04, VRMAX=8.0, VRMIN=0.0, KC=0.05)
AC8B = dict(TR=0.01, kP=3.0, kI=1.0, kD=1.0, Td=0.2, VPMAX=999.0, VPMIN=-999.0, VRMAX=7.3, VRMIN=1.0,
            VFEMAX=999.0, VEMIN=-999.0, TA=0.04, KA=40.0, TE=0.8, E1=0.0, SE1=0.0, E2=1.0, SE2=1.0,
            KE=1.0, KD=0.0, KC=0.1)
GAST = dict(R=0.05, VMAX=1.05, VMIN=0.3, KT=5.0, AT=1.0, T1=0.1, T2=0.2, T3=10.0, Dt=1.0)
TGOV1 = dict(R=0.05, VMAX=1.2, VMIN=0.0, T1=0.1, T2=0.2, T3=10.0)


def _smib(exciter=("ESST4B", ESST4B), governor=("TGOV1", TGOV1)):
    s = System(two_machine_case(x_line=0.3, p=0.8))
    s.add_generator("G", 0, machine=("GENROU", GENROU), exciter=exciter, governor=governor)
    s.add_machine("GENCLS", "inf", gen=1, Sn=100, M=1e4, xd1=0.01)
    return s


@pytest.mark.parametrize("exciter, governor", [
    (("ESST4B", ESST4B), ("GAST", GAST)),
    (("EXAC4", EXAC4), ("GAST", GAST)),
    (("AC8B", AC8B), ("TGOV1", TGOV1)),
    (("ESST4B", dict(ESST4B, PI_nonwindup=0.0)), ("TGOV1", TGOV1)),
    (("AC8B", dict(AC8B, PID_nonwindup=0.0, VE_limited=0.0)), ("TGOV1", TGOV1)),
], ids=["ESST4B+GAST", "EXAC4+GAST", "AC8B", "ESST4B-andes", "AC8B-andes"])
def test_within_limits_starts_at_rest(exciter, governor):
    s = _smib(exciter, governor).setup()
    res = simulate(s, 1.0, dt=1 / 120)
    assert np.max(np.abs(res["G.omega"] - 1)) < 1e-8
    assert np.ptp(res["G.vf"]) < 1e-7


@pytest.mark.parametrize("exciter, governor, who, field", [
    (("ESST4B", dict(ESST4B, VRMAX=1.0)), ("TGOV1", TGOV1), "ESST4B 'G.avr'", "VRMAX"),   # VR0 = KG*vf0 > 1
    (("ESST4B", dict(ESST4B, VRMAX=1.0, PI_nonwindup=0.0)), ("TGOV1", TGOV1), "ESST4B 'G.avr'", "VRMAX"),
    (("ESST4B", dict(ESST4B, VMMAX=0.1)), ("TGOV1", TGOV1), "ESST4B 'G.avr'", "VMMAX"),
    (("EXAC4", dict(EXAC4, VRMAX=1.0)), ("TGOV1", TGOV1), "EXAC4 'G.avr'", "VRMAX - KC*XadIfd"),
    (("EXAC4", dict(EXAC4, KA=5.0, VIMAX=0.1)), ("TGOV1", TGOV1), "EXAC4 'G.avr'", "VIMAX"),
    (("AC8B", dict(AC8B, VRMAX=1.2)), ("TGOV1", TGOV1), "AC8B 'G.avr'", "VRMAX"),
    (("AC8B", dict(AC8B, VFEMAX=1.2)), ("TGOV1", TGOV1), "AC8B 'G.avr'", "VFEMAX"),
    (("EXAC4", EXAC4), ("GAST", dict(GAST, AT=0.7)), "GAST 'G.gov'", "AT + KT*(AT - tm0)"),   # Pg = 0.8
    (("EXAC4", EXAC4), ("GAST", dict(GAST, VMAX=0.7)), "GAST 'G.gov'", "VMAX"),
], ids=["ESST4B-VRMAX", "ESST4B-VRMAX-tracking", "ESST4B-VMMAX", "EXAC4-VRMAX", "EXAC4-VIMAX",
        "AC8B-VRMAX", "AC8B-VFEMAX", "GAST-AT", "GAST-VMAX"])
def test_beyond_limit_is_refused_or_warned(exciter, governor, who, field):
    with pytest.raises(DataError) as e:
        _smib(exciter, governor).setup()
    msg = str(e.value)
    assert who in msg and field in msg, msg
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        s = _smib(exciter, governor)
        try:
            s.setup(limits="warn")
        except DataError as e2:    # the clamped point may then fail the residual check: still named
            assert "initial point" in str(e2)
    assert any(who in str(x.message) and field in str(x.message) for x in w)
