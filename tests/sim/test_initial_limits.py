"""Initial values beyond limits are refused at setup (issue 8, item 6).

A TGOV1 valve that must open above VMAX, or an exciter whose regulator output must
exceed VRMAX, used to be clamped at t = 0+ so the grid drifted before any event.
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
EXDC2 = dict(TR=0.01, TA=0.02, TC=1.0, TB=1.0, TE=0.8, TF1=1.0, KF1=0.03, KA=40.0, KE=1.0,
             VRMAX=7.3, VRMIN=-7.3, E1=0.0, SE1=0.0, E2=1.0, SE2=1.0)


def _smib(vmax=1.2, vrmax=7.3):
    s = System(two_machine_case(x_line=0.3, p=0.8))
    s.add_generator("G", 0, machine=("GENROU", GENROU), exciter=("EXDC2", dict(EXDC2, VRMAX=vrmax)),
                    governor=("TGOV1", dict(R=0.05, VMAX=vmax, VMIN=0.0, T1=0.1, T2=0.2, T3=10.0)))
    s.add_machine("GENCLS", "inf", gen=1, Sn=100, M=1e4, xd1=0.01)
    return s


def test_within_limits_is_accepted_and_flat():
    s = _smib().setup()
    res = simulate(s, 2.0, dt=1 / 120)
    assert np.max(np.abs(res["G.omega"] - 1)) < 1e-8


def test_valve_above_vmax_is_refused():
    with pytest.raises(DataError) as e:
        _smib(vmax=0.5).setup()          # Pg = 0.8 pu needs the valve at 0.8 > VMAX = 0.5
    msg = str(e.value)
    assert "TGOV1 'G.gov'" in msg and "VMAX" in msg and "0.8" in msg and "0.5" in msg


def test_exciter_output_above_vrmax_is_refused():
    with pytest.raises(DataError) as e:
        _smib(vrmax=1.0).setup()         # the field voltage of this operating point is > 1 pu
    msg = str(e.value)
    assert "EXDC2 'G.avr'" in msg and "VRMAX" in msg


def test_warn_option_reports_and_continues():
    s = _smib(vmax=0.5)
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        s.setup(limits="warn")
    assert any("VMAX" in str(x.message) and "TGOV1 'G.gov'" in str(x.message) for x in w)
    assert s.is_setup
