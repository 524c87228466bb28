"""Peer check of the standard control-model library against ANDES 2.0.0.

Each new model (exciters ESST3A, EXST1, IEEEX1, IEEET1, EXAC1, ESDC2A; governors
IEEEG1 (single and cross-compound), IEESGO, TG2, TGOV1N; PSS ST2CUT) runs in a
Kundur two-area case (ANDES's ``kundur_full.xlsx`` with controls swapped, same
data file read by both tools): 10 s, three-phase fault at bus 8, both tools at the
same fixed step. Requirements: speeds within 2e-5 pu and rotor angles relative
to generator 1 within 0.5 deg at all times.

Each case is run twice: with nominal data and a 50 ms fault, and with gains
raised / limits tightened and a 150 ms fault, which drives every model into
its limits (asserted on the weakgrid trajectories: each limited signal reaches
its bound).

Data notes (differences of ANDES 2.0 from the standard diagrams, documented in
the model files): ANDES's EXAC1 and ESDC2A ignore the sensing lag ``TR`` (so
``TR = 0`` here); its EXST1 output ceiling never acts (so the EXST1 ceiling
``VRMAX - KC*XadIfd`` is kept out of reach; its input limiter ``VIMAX`` is
driven); its IEEEX1 limiter keeps the constant bounds ``VRMAX``, ``VRMIN`` instead of
``VRMAX*Vt`` (so that ceiling is kept out of reach in the peer cases, and the moving
ceiling is checked on its own in ``test_voltage_dependent_ceiling``; the importer's
``conventions="andes"`` reproduces these departures, ``test_andes_conventions.py``).

IEEET1 with its regulator limit active (KA = 60, VRMAX = 3, VRMIN = 0.5, 150-ms
fault) differs from ANDES by 1.9e-4 pu of speed: ANDES integrates the regulator
output beyond VRMAX in steps it accepts while its limit flag chatters between
Newton iterations (measured in ``test_andes_limit_gaps.py``); weakgrid follows the
diagram. The IEEET1 limit is therefore not in the limit case (IEEET1 matches
without limits: nominal cases). Case A's limit case (ESST3A, EXST1, IEEEG1,
IEESGO, TG2, TGOV1N at their limits) differed by 0.8-1.1e-4 pu, not shrinking with
the step: switching its limits on one at a time, then its raised gains one at a
time, isolated it to IEEEX1 alone (KA = 60: VR reached its moving ceiling VRMAX*Vt
during the fault, which ANDES keeps at the constant VRMAX; 9.6e-5 pu at h, 1.1e-4
at h/2). With that ceiling out of reach, as in the other peer cases, case A's limit
case is 1.3e-5 pu at h and 5.1e-6 pu at h/2 (ANDES's own change 9.9e-6 pu,
weakgrid's 7.5e-6 pu).
Case B's limit case (EXAC1, IEEEG1 cross-compound, ST2CUT at their limits)
passes the step-halving check (1.1e-4 pu at h, 1.9e-5 pu at h/2; ANDES's own
change 9.0e-5 pu, weakgrid's 4.9e-6 pu).
"""

import numpy as np
import pytest

andes = pytest.importorskip("andes")

from kundur_variants import kundur_variant  # noqa: E402

from weakgrid.sim.integrate import Simulator  # noqa: E402
from weakgrid.sim.peer.andes_runs import build_weakgrid, compare, run_andes  # noqa: E402

pytestmark = [pytest.mark.andes, pytest.mark.slow]

H = 1 / 120
SPEED_TOL, ANGLE_TOL = 2e-5, 0.5


def _case_a(limits):
    """G1 ESST3A + IEEEG1, G2 EXST1 + IEESGO, G3 IEEEX1 + TG2, G4 IEEET1 + TGOV1N."""
    k = 3.0 if limits else 1.0
    exc = {
        1: ("ESST3A", dict(TR=0.01, VIMAX=0.8, VIMIN=-0.1, KM=500, TC=3, TB=15, KA=20 * k, TA=0.1,
                           VRMAX=8 if not limits else 2.5, VRMIN=0, KG=1, KP=4, KI=0.1, VBMAX=18, KC=0.1,
                           XL=0.01, VGMAX=4, THETAP=0, TM=0.1, VMMAX=1, VMMIN=0.1)),
        2: ("EXST1", dict(TR=0.02, VIMAX=0.2 if not limits else 0.02, VIMIN=0 if not limits else -0.05,
                          TC=1, TB=1, KA=50 * k, TA=0.05, VRMAX=12, VRMIN=-3, KC=0.2, KF=0.1, TF=1)),
        # IEEEX1's ceiling VRMAX*Vt is kept out of reach (ANDES applies the constant VRMAX;
        # the moving ceiling is checked in test_voltage_dependent_ceiling): with KA = 60 and
        # VRMAX = 50, VR reached 50*Vt during the fault and that alone made case A's limit gap
        3: ("IEEEX1", dict(TR=0.02, TA=0.02, TC=1, TB=1, TE=0.83, TF1=1.246, KF1=0.0754, KA=20 * k,
                           KE=1, VRMAX=50 if not limits else 500, VRMIN=-50 if not limits else -500,
                           E1=2.8, SE1=0.04, E2=3.73, SE2=0.33)),
        4: ("IEEET1", dict(TR=0.02, KA=20, TA=0.04, VRMAX=5, VRMIN=-4, KE=1, TE=0.8, KF=0.05, TF=1.0,
                           E1=2.8, SE1=0.04, E2=3.73, SE2=0.33)),
    }
    gov = {
        1: ("IEEEG1", dict(K=20 * k, T1=1, T2=2, T3=0.1, UO=0.1, UC=-0.1 if not limits else -0.02,
                           PMAX=10, PMIN=0, T4=0.4, K1=0.5, T5=10, K3=0.5)),
        2: ("IEESGO", dict(K1=20 * k, T1=0.1, T2=1, T3=2, T4=0.3, T5=8, T6=0.5, K2=0.7, K3=0.4,
                           PMAX=1.2, PMIN=0 if not limits else 0.77)),
        3: ("TG2", dict(R=0.05 / k, T1=0.2, T2=10, pmax=1.2, pmin=0 if not limits else 0.775,
                        dbl=-1e-9, dbu=1e-9)),
        4: ("TGOV1N", dict(R=0.05 / k, VMAX=33, VMIN=0.4 if not limits else 0.75, T1=0.49, T2=2.1, T3=7)),
    }
    return dict(exciters=exc, governors=gov)


def _case_b(limits):
    """G1 EXAC1 + ST2CUT, G2 ESDC2A, G3 IEEET1 + ST2CUT, G4 ESST3A; IEEEG1 drives G3 (HP) and G4 (LP)."""
    k = 3.0 if limits else 1.0
    sat = dict(E1=2.8, SE1=0.04, E2=3.73, SE2=0.33)
    exc = {
        1: ("EXAC1", dict(TR=0, TB=1, TC=1, KA=80 * k, TA=0.04, VRMAX=8 if not limits else 3.0, VRMIN=0,
                          TE=0.8, KF=0.1, TF=1, KC=0.1, KD=0.2, KE=1, **sat)),
        2: ("ESDC2A", dict(TR=0, KA=80 * k, TA=0.04, TB=1, TC=1, VRMAX=200, VRMIN=-200, KE=1, TE=0.8, KF=0.1,
                           TF1=1, Switch=0, **sat)),
        3: ("IEEET1", dict(TR=0.02, KA=20, TA=0.04, VRMAX=9, VRMIN=-9, KE=1, TE=0.8, KF=0.05, TF=1.0, **sat)),
        4: ("ESST3A", dict(TR=0.01, VIMAX=0.8, VIMIN=-0.1, KM=500, TC=3, TB=15, KA=20, TA=0.1, VRMAX=8, VRMIN=0,
                           KG=1, KP=4, KI=0.1, VBMAX=18, KC=0.1, XL=0.01, VGMAX=4, THETAP=0, TM=0.1, VMMAX=1,
                           VMMIN=0.1)),
    }
    gov = {
        3: ("IEEEG1", dict(syn2=4, K=20 * k, T1=1, T2=2, T3=0.1, UO=0.1, UC=-0.1, PMAX=10,
                           PMIN=0 if not limits else 0.77, T4=0.4, K1=0.25, K2=0.25, T5=10, K3=0.25, K4=0.25)),
        4: None,
    }
    st2 = dict(MODE=1, MODE2=3, K1=10 * k, K2=0.5, T1=0.02, T2=0.02, T3=1, T4=1, T5=0.2, T6=0.05, T7=1,
               T8=1, T9=1, T10=1, LSMAX=0.1 if not limits else 0.03, LSMIN=-0.1 if not limits else -0.03,
               VCU=0, VCL=0)
    pss = [("ST2CUT", "EXAC1_1", st2), ("ST2CUT", "IEEET1_3", dict(st2, MODE2=0, T3=0))]
    return dict(exciters=exc, governors=gov, pss=pss)


# (limited signal in weakgrid results, bound) checked in the limit cases
LIMITS_A = [("ESST3A_1.VR", "hi", 2.5), ("EXST1_2.vi", "hi", 0.02),

            ("IEEEG1_1.vs", "lo", -0.02), ("IEESGO_2.P", "lo", None),
            ("TG2_3.pout", "lo", None), ("TGOV1N_4.LAG", "lo", None)]
LIMITS_B = [("EXAC1_1.VR", "hi", 3.0),
            ("IEEEG1_3.GV", "lo", None), ("ST2CUT_EXAC1_1.vss", "both", 0.03)]

CASES = {
    "a_nominal": (_case_a, False, (8, 1.0, 1.05)),
    "a_limits": (_case_a, True, (8, 1.0, 1.15)),
    "b_nominal": (_case_b, False, (8, 1.0, 1.05)),
    "b_limits": (_case_b, True, (8, 1.0, 1.15)),
}


def _andes_tg2_deadband(ss):
    """ANDES 2.0's TG2 with its dead band disabled (the default) has no speed response (its dead-band
    flag defaults to "inside"); enable it, with a 1e-9 pu band, so that TG2 acts as its diagram."""
    if "TG2" in ss.models and ss.TG2.n:
        ss.TG2.w_db.enable = 1


def _run_pair(path, fault, h):
    a = run_andes(path, 10.0, h, fault=fault, disable_toggles=True, configure=_andes_tg2_deadband)
    system, events, names = build_weakgrid(path, fault=fault, disable_toggles=True)
    system.setup()
    res = Simulator(system, dt=h, tol=1e-8).run(10.0, events=events)
    w = {"t": res.t, "omega": np.column_stack([res[f"{n}.omega"] for n in names]),
         "delta": np.column_stack([res[f"{n}.delta"] for n in names]), "ok": res.ok}
    return a, w, res, system


@pytest.fixture(scope="module", params=list(CASES))
def runs(request, tmp_path_factory):
    builder, limits, fault = CASES[request.param]
    path = kundur_variant(tmp_path_factory.mktemp("cases") / f"{request.param}.xlsx", **builder(limits))
    a, w, res, system = _run_pair(path, fault, H)
    half = _run_pair(path, fault, H / 2)[:2] if limits else None
    return request.param, a, w, res, system, half


def test_models_match_andes(runs):
    """Nominal cases: within 2e-5 pu / 0.5 deg at the step H.

    Limit cases: limiters switch at step boundaries (a first-order effect), and
    ANDES's own step error dominates: the gap must shrink when both steps are
    halved, stay within ANDES's own change on halving, and weakgrid's own change
    must be the smaller one.
    """
    name, a, w, res, system, half = runs
    assert a["ok"] and w["ok"]
    assert a["t"][-1] == pytest.approx(10.0) and w["t"][-1] == pytest.approx(10.0)
    dw, dd = compare(a, w)
    print(f"{name}: speed {dw:.3g} pu, relative angle {dd:.3g} deg at h = 1/{round(1 / H)} s")
    if half is None:
        assert dw < SPEED_TOL, f"{name}: speed difference {dw:.3g} pu"
        assert dd < ANGLE_TOL, f"{name}: relative angle difference {dd:.3g} deg"
        return
    a2, w2 = half
    assert a2["ok"] and w2["ok"]
    dw2, dd2 = compare(a2, w2)
    self_a, self_w = compare(a, a2)[0], compare(w, w2)[0]
    print(f"{name}: speed {dw2:.3g} pu, relative angle {dd2:.3g} deg at h/2; own step change "
          f"ANDES {self_a:.3g}, weakgrid {self_w:.3g} pu")
    assert dw2 < 0.8 * dw, f"{name}: the gap does not shrink with the step ({dw:.3g} -> {dw2:.3g} pu)"
    # ANDES's own step error dominates: the remaining gap is within ANDES's change on halving its
    # step, and weakgrid's own change is smaller than ANDES's
    assert dw2 < 1.5 * self_a, f"{name}: gap {dw2:.3g} pu exceeds ANDES's own step change {self_a:.3g}"
    assert self_w < self_a, f"{name}: weakgrid's step change {self_w:.3g} >= ANDES's {self_a:.3g}"


def test_limit_cases_reach_their_limits(runs):
    """The limit cases really exercise the limits (else the peer match would not cover them)."""
    name, a, w, res, system, half = runs
    if not name.endswith("limits"):
        pytest.skip("nominal case")
    for sig, side, bound in (LIMITS_A if name.startswith("a") else LIMITS_B):
        y = res[sig]
        if bound is None:      # limit from the data: read it from the system's limit table
            comp = system.components[sig.split("_")[0]]
            st = sig.rsplit(".", 1)[1]
            hit = _state_at_limit(system, comp, st, res, sig, side)
        else:
            hit = (np.max(y) >= bound - 1e-6) if side == "hi" else (np.min(y) <= bound + 1e-6)
            if side == "both":
                hit = np.max(y) >= bound - 1e-6 and np.min(y) <= -bound + 1e-6
        assert hit, f"{name}: {sig} never reaches its {side} limit"


def _state_at_limit(system, comp, state, res, sig, side):
    p = comp.p
    i = comp.names.index(sig.split(".")[0])
    bounds = {"IEESGO": ("PMIN", "PMAX"), "TG2": ("pmin", "pmax"), "TGOV1N": ("VMIN", "VMAX"),
              "IEEEG1": ("PMIN", "PMAX")}[comp.type_name]
    b = p[bounds[0] if side == "lo" else bounds[1]][i]
    y = res[sig]
    return bool(np.min(y) <= b + 1e-6) if side == "lo" else bool(np.max(y) >= b - 1e-6)


@pytest.mark.parametrize("model", ["IEEEX1", "ESDC2A"])
def test_voltage_dependent_ceiling(model, tmp_path):
    """IEEEX1/ESDC2A regulator output is held at VRMAX*Vt (moving with the bus voltage) and never above."""
    prm = dict(IEEEX1=dict(TR=0.02, TA=0.02, TC=1, TB=1, TE=0.83, TF1=1.246, KF1=0.0754, KA=60, KE=1,
                           VRMAX=3.0, VRMIN=0.5),
               ESDC2A=dict(TR=0.02, KA=240, TA=0.04, TB=1, TC=1, VRMAX=3.0, VRMIN=0.5, KE=1, TE=0.8, KF=0.1,
                           TF1=1))[model]
    path = kundur_variant(tmp_path / "c.xlsx", exciters={3: (model, prm)})
    system, events, names = build_weakgrid(path, fault=(8, 1.0, 1.15), disable_toggles=True)
    system.setup()
    res = Simulator(system, dt=H, tol=1e-8).run(3.0, events=events)
    comp = system.components[model]
    vr = res[f"{comp.names[0]}.VR"]
    vt = res[f"bus{system.network.bus_ids[comp.bus[0]]}.v"]
    ceiling = 3.0 * vt
    at = np.abs(vr - ceiling) < 1e-6        # held at the moving ceiling (implicit in the step)
    assert at.sum() >= 10, "the ceiling is never reached"
    assert np.min(vt[at]) < 0.8, "the ceiling was not followed while the voltage was depressed"
    assert np.max(np.diff(ceiling[at])) > 0.01, "the ceiling did not move while held"
    # (at the fault instants Vt jumps while the state VR is continuous: held from the next step on)
    steps = ~np.isin(np.round(res.t, 9), [1.0, 1.15])
    excess = np.max((vr - ceiling)[steps])
    assert excess <= 1e-6, f"VR exceeds VRMAX*Vt by {excess:.3g}"
