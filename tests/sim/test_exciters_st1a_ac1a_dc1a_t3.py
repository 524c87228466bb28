"""Invariants of the exciters ESST1A, ESAC1A, ESDC1A, IEEET3 (no peer needed).

Steady initial point (with a PSS attached), limits beyond reach at t = 0 refused with the
field named (as the other exciters: ``System.setup`` / ``check_initial_point``), the ESST1A
algebraic loop refused, and the block-diagram details a peer run cannot isolate.
"""

import numpy as np
import pytest
from sim_cases import two_machine_case

from weakgrid.sim.errors import DataError
from weakgrid.sim.system import System

GENROU = dict(Sn=200, M=8.0, D=0.0, ra=0.0, xl=0.15, xd=1.8, xq=1.7, xd1=0.3, xq1=0.55, xd2=0.25, xq2=0.25,
              Td10=6.0, Td20=0.03, Tq10=0.4, Tq20=0.05, S10=0.05, S12=0.3)
SAT = dict(E1=2.8, SE1=0.04, E2=3.73, SE2=0.33)
EXCITERS = {
    "ESST1A": dict(KA=80, ILR=1.5, KLR=2.0),
    "ESST1A VOSc=2": dict(KA=80, VOSc=2),
    "ESAC1A": dict(KD=0.2, **SAT),
    "ESDC1A": dict(KA=80, **SAT),
    "IEEET3": dict(KA=5),
}
PSS = ("ST2CUT", dict(MODE=1, MODE2=3, K1=5, K2=0.2, T3=1.0))


def _system(model, params, limits="raise"):
    s = System(two_machine_case(p=0.8))
    s.add_generator("G", 0, machine=("GENROU", GENROU), exciter=(model, params), pss=PSS)
    s.add_generator("S", 1, machine=("GENCLS", dict(Sn=1000, M=20.0, xd1=0.1)))
    return s.setup(limits=limits)


@pytest.mark.parametrize("name", list(EXCITERS))
def test_starts_in_steady_state(name):
    s = _system(name.split()[0], EXCITERS[name])
    F, ctx = s.residual(0.0, s.z0)
    assert np.max(np.abs(F)) < 1e-9
    assert ctx.sig["vf"][0] == pytest.approx(s.sig_defaults["vf0"][0], abs=1e-12)


def _x0(name, state):
    s = _system(name.split()[0], EXCITERS[name])
    c = s.components[name.split()[0]]
    return float(s.z0[c.idx(state)][0])


@pytest.mark.parametrize("model,state,field,side", [
    ("ESST1A", "VA", "VAMAX", +1), ("ESAC1A", "VA", "VAMAX", +1),
    ("ESDC1A", "VR", "VRMAX", +1), ("IEEET3", "VR", "VRMIN", -1)])
def test_initial_regulator_beyond_its_limit_is_refused(model, state, field, side):
    """The regulator state that must start beyond its limit raises DataError naming the
    exciter and the field (``limits="warn"`` warns instead), as for EXDC2, TGOV1, ..."""
    x0 = _x0(model, state)
    bad = dict(EXCITERS[model], **{field: x0 - side * 0.1})
    with pytest.raises(DataError) as e:
        _system(model, bad)
    assert f"{model} 'G.avr'" in str(e.value) and field in str(e.value)
    with pytest.warns(UserWarning, match=field):
        _system(model, bad, limits="warn")


def test_esst1a_output_ceiling_below_the_operating_point_is_refused():
    """The static output ceiling ``Vt*VRMAX - KC*XadIfd`` below ``vf0``: no steady state (the
    initial-point check refuses it)."""
    with pytest.raises(DataError):
        _system("ESST1A", dict(EXCITERS["ESST1A"], VRMAX=1.0))


def test_esst1a_without_regulator_lag_needs_no_rate_feedback():
    """TA = 0 with an active rate feedback is an algebraic loop: refused, naming TA; with
    KF = 0 it is the limited gain and starts steady."""
    with pytest.raises(DataError, match="TA"):
        _system("ESST1A", dict(EXCITERS["ESST1A"], TA=0.0))
    s = _system("ESST1A", dict(EXCITERS["ESST1A"], TA=0.0, KF=0.0))
    assert np.max(np.abs(s.residual(0.0, s.z0)[0])) < 1e-9


def test_esst1a_refuses_unknown_pss_input_code():
    with pytest.raises(DataError, match="VOSc"):
        _system("ESST1A", dict(EXCITERS["ESST1A"], VOSc=3))


def test_esst1a_pss_at_the_regulator_output_passes_without_lag():
    """VOSc = 2: a PSS signal adds to the output at once (and, ahead of the output limiter, to
    the rate feedback's input, which lowers the error); VOSc = 1: it enters the summing junction
    and reaches the output only through the regulator lag."""
    out = {}
    for code in (1, 2):
        s = _system("ESST1A", dict(EXCITERS["ESST1A"], VOSc=code))
        c = s.components["ESST1A"]
        _, ctx0 = s.residual(0.0, s.z0)
        sig = s.sig_defaults
        ctx0.sig["vs"][...] = 0.05                  # PSS output stepped: evaluate the exciter alone
        ctx0.f[...] = 0.0
        c.compute(ctx0)
        out[code] = (float(ctx0.sig["vf"][0] - sig["vf0"][0]), float(ctx0.f[c.idx("LL")][0]))
    assert out[2][0] == pytest.approx(0.05, abs=1e-12)     # straight to Efd
    assert out[1][0] == pytest.approx(0.0, abs=1e-12)      # not yet
    fb = 0.05 * EXCITERS["ESST1A"].get("KF", 0.1) / 1.0 / 1.0   # KF/TF * 0.05 through the lead-lag (TB = 1)
    assert out[1][1] == pytest.approx(0.05, rel=1e-9)             # (vi - LL)/TB
    assert out[2][1] == pytest.approx(-fb, rel=1e-9)


def test_esac1a_flags_remove_rate_feedback_and_regulator_limits():
    """ANDES 2.0's ESAC1A (``VF_used = 0``, ``VR_limited = 0``): no rate feedback at the summing
    junction; VR not clipped to VRMAX, VE not floored at 0."""
    s = _system("ESAC1A", dict(EXCITERS["ESAC1A"], VRMAX=5.0))
    a = _system("ESAC1A", dict(EXCITERS["ESAC1A"], VRMAX=5.0, VF_used=0, VR_limited=0))
    for sysm, clipped in ((s, True), (a, False)):
        c = sysm.components["ESAC1A"]
        z = sysm.z0.copy()
        z[c.idx("VA")] = 9.0                     # regulator above VRMAX = 5
        z[c.idx("VF")] -= 0.1                    # rate feedback output (KF/TF)*(VFE - VF) > 0
        _, ctx = sysm.residual(0.0, z)
        assert ctx.out["ESAC1A.VR"][0] == (5.0 if clipped else 9.0)
        vi0 = c.vref0[0] - ctx.sig["Vt"][0]
        fb = c.p["KF"][0] / c.p["TF"][0] * 0.1
        assert ctx.out["ESAC1A.vi"][0] == pytest.approx(vi0 - fb if clipped else vi0, abs=1e-9)
    lims = {tuple(np.round([lo, hi], 6)) for lo, hi in zip(s.lim_lo, s.lim_hi)}
    assert (0.0, np.inf) in lims                 # VE >= 0 in the standard model
