"""Invariants of the standard control models (no peer needed): steady initial point, conventions, errors."""

import numpy as np
import pytest
from sim_cases import two_machine_case

from weakgrid.sim.blocks import LagNonWindup, WashoutOrLag, rectifier_fex
from weakgrid.sim.errors import DataError
from weakgrid.sim.system import System

GENROU = dict(Sn=200, M=8.0, D=0.0, ra=0.0, xl=0.15, xd=1.8, xq=1.7, xd1=0.3, xq1=0.55, xd2=0.25, xq2=0.25,
              Td10=6.0, Td20=0.03, Tq10=0.4, Tq20=0.05, S10=0.05, S12=0.3)
SAT = dict(E1=2.8, SE1=0.04, E2=3.73, SE2=0.33)
EXCITERS = {
    "ESST3A": dict(KA=20, VRMAX=8, THETAP=10.0),
    "EXST1": dict(KA=50),
    "IEEEX1": dict(KA=20, **SAT),
    "IEEET1": dict(KA=20, **SAT),
    "EXAC1": dict(KD=0.2, **SAT),
    "ESDC2A": dict(KA=80, **SAT),
}
GOVERNORS = {
    "IEEEG1": dict(K=20, PMAX=2.0, T7=0.0),
    "IEESGO": dict(K1=20, K2=0.7, K3=0.4),
    "TG2": dict(R=0.05, pmax=2.0),
    "TGOV1N": dict(R=0.05, VMAX=2.0),
}


def _system(exciter=None, governor=None, pss=None):
    s = System(two_machine_case(p=0.8))
    s.add_generator("G", 0, machine=("GENROU", GENROU), exciter=exciter, governor=governor, pss=pss)
    s.add_generator("S", 1, machine=("GENCLS", dict(Sn=1000, M=20.0, xd1=0.1)))
    return s.setup()


@pytest.mark.parametrize("model", list(EXCITERS))
def test_exciter_starts_in_steady_state(model):
    s = _system(exciter=(model, EXCITERS[model]),
                pss=("ST2CUT", dict(MODE=1, MODE2=3, K1=5, K2=0.2, T3=1.0)))
    F, ctx = s.residual(0.0, s.z0)
    assert np.max(np.abs(F)) < 1e-9
    assert ctx.sig["vf"][0] == pytest.approx(s.sig_defaults["vf0"][0], abs=1e-12)


@pytest.mark.parametrize("model", list(GOVERNORS))
def test_governor_starts_in_steady_state(model):
    s = _system(exciter=("EXST1", {}), governor=(model, GOVERNORS[model]))
    F, ctx = s.residual(0.0, s.z0)
    assert np.max(np.abs(F)) < 1e-9
    assert ctx.sig["tm"][0] == pytest.approx(s.sig_defaults["tm0"][0], abs=1e-12)


def test_ieeeg1_cross_compound_split_warns_and_setup_refuses_the_drift():
    """A power split that does not match K1..K8 is no steady state: said twice (the governor
    warns as ANDES does; the setup check refuses the initial point, naming the machine)."""
    s = System(two_machine_case(p=0.8))
    s.add_generator("G", 0, machine=("GENROU", GENROU))
    s.add_generator("S", 1, machine=("GENROU", dict(GENROU, Sn=1000)))
    s.add_governor("IEEEG1", "G.gov", "G", machine2="S", K=20, K1=0.5, K2=0.5, K3=0.0)
    with pytest.warns(UserWarning, match="not steady"), \
            pytest.raises(DataError, match=r"G\.omega"):
        s.setup()


def test_st2cut_refuses_frequency_input():
    with pytest.raises(DataError, match="MODE"):
        _system(exciter=("EXST1", {}), pss=("ST2CUT", dict(MODE=2)))


def test_lag_nonwindup_with_zero_time_constant_is_a_limited_gain():
    """T = 0 (ANDES's ieee14 ESST3A data has TA = 0): the output is clip(K*u), not the frozen state."""
    b = LagNonWindup(np.array([2.0, 2.0, 2.0]), np.array([0.0, 0.0, 1.0]), -1.0, 1.0)
    x = np.array([0.3, 0.3, 0.3])
    assert np.all(b.output(x, np.array([0.8, 0.2, 0.8])) == [1.0, 0.4, 0.3])
    assert np.all(b.deriv(x, np.array([0.8, 0.2, 0.8]))[:2] == 0.0)


def test_esst3a_without_regulator_lag_starts_in_steady_state():
    """ESST3A with TA = 0 (as in ANDES's ieee14 cases) is accepted and starts steady; its
    regulator output then follows KA*VA at once (no frozen state)."""
    s = _system(exciter=("ESST3A", dict(EXCITERS["ESST3A"], TA=0.0)))
    F, ctx = s.residual(0.0, s.z0)
    assert np.max(np.abs(F)) < 1e-9
    c = s.components["ESST3A"]
    z = s.z0.copy()
    z[c.idx("LL")] += 0.01                       # lead-lag state up: VA up by (1 - TC/TB)*0.01
    F1, _ = s.residual(0.0, z)                   # -> VR up by KA times that, at once
    dva = (1 - c.p["TC"][0] / c.p["TB"][0]) * 0.01
    assert F1[c.idx("VM")] == pytest.approx(c.p["KM"][0] * 20 * dva / c.p["TM"][0], rel=1e-6)


def test_washout_with_zero_gain_is_a_lag():
    b = WashoutOrLag(np.array([0.0, 2.0]), np.array([2.0, 2.0]))
    x, u = np.array([0.3, 0.3]), np.array([1.0, 1.0])
    y = b.output(x, u)
    assert y[0] == 0.3                      # lag 1/(1+sT): output = state
    assert y[1] == pytest.approx(2.0 / 2.0 * (1.0 - 0.3))   # washout sK/(1+sT)
    assert np.all(b.deriv(x, u) == (u - x) / 2.0)


def test_rectifier_factor_is_continuous():
    for p in (0.0, 0.433, 0.75, 1.0):
        lo, hi = rectifier_fex(np.array([p - 1e-9, p + 1e-9]))
        assert abs(lo - hi) < 2e-3, p
