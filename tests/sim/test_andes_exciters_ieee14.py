"""ESST1A, ESAC1A, ESDC1A, IEEET3 against ANDES 2.0 on its ieee14 cases (one exciter each).

Each case (``ieee14/ieee14_<model>.xlsx``, as shipped) runs in both tools with the census
fault (three-phase at the first load bus, 1.00-1.05 s; the case's own events off) for 5 s at
the same fixed step h = 1/120 s; speeds and rotor angles relative to the first machine must
agree within 2e-5 pu and 0.5 deg. Then each model is driven into its limits (data edited in
ANDES's copy, which both tools read) and must still agree; and its zero-parameter conventions
(TB = TC = 0, TR = 0, TA = 0, KF = 0, TF = 0, ...) must be ANDES's (variants run 3 s).

Measured 2026-11-26 (largest speed / angle difference at h; at h/2 where given):

=====================  ==========================================  ==============================
case                   ``conventions="andes"``                     standard models
=====================  ==========================================  ==============================
ieee14_esst1a          1.22e-5 pu / 0.023 deg                      same (no departure in data)
ieee14_esac1a          1.22e-5 pu / 0.023 deg                      9.7e-4 pu / 6.4 deg
ieee14_esdc1a          1.22e-5 pu / 0.029 deg                      1.22e-5 pu / 0.078 deg
ieee14_ieeet3          1.22e-5 pu / 0.023 deg                      same (no departure)
ESST1A limits (3 s)    1.12e-5 pu / 0.021 deg (5 s, h/2: 5.5e-6)   same
ESAC1A limits (3 s)    1.34e-5 pu / 0.024 deg (5 s, h/2: 6.0e-6)   4.7e-4 pu / 3.5 deg
ESDC1A limits (3 s)    1.34e-5 pu / 0.029 deg (5 s, h/2: 6.0e-6)   1.34e-5 pu / 0.078 deg
IEEET3 limits (2 s)    1.28e-5 pu / 0.023 deg; h/2 6.4e-6 pu       same
zero parameters (3 s)  1.34-1.4e-5 pu / 0.023-0.030 deg            same
=====================  ==========================================  ==============================

1.22e-5 pu is the gap of ANDES's ieee14 family at this step (its own step error: it halves
with the step in both tools, ``test_ieee14_gap_halves_with_the_step``). The ESAC1A standard
model differs because ANDES 2.0's ESAC1A has no rate feedback at its summing junction and no
regulator limits VRMIN..VRMAX (with only ``VF_used = 0``: 6.7e-4 pu; only ``VR_limited = 0``:
8.3e-4 pu); ESDC1A's standard sensing
lag ``TR`` (ANDES ignores it) moves the angles by 0.05 deg. ANDES 2.0's ESDC1A does not
initialize at all (its regulator keeps discarded limits of value 0); the ANDES runs here point
it at its constant limits first (:func:`weakgrid.sim.peer.andes_case.fix_andes_esdc1a`).
"""

import warnings

import numpy as np
import pytest

andes = pytest.importorskip("andes")

from weakgrid.sim.peer.andes_case import (compare_named, fix_andes_esdc1a, load_case,  # noqa: E402
                                          run_andes_ss, run_weakgrid_ss)

pytestmark = [pytest.mark.andes, pytest.mark.slow]

H, TF, TF_SHORT = 1 / 120, 5.0, 3.0   # shipped cases 5 s (as the census); variants 3 s
SPEED_TOL, ANGLE_TOL = 2e-5, 0.5
MODELS = ("ESST1A", "ESAC1A", "ESDC1A", "IEEET3")


def _case(model):
    return f"ieee14/ieee14_{model.lower()}.xlsx"


def _edit(model, edits):
    def modify(ss):
        m = ss.models[model]
        for k, v in edits.items():
            getattr(m, k).v[0] = v
    return modify


def _runs(model, edits=None, h=H, tf=TF, conventions=("andes",), andes_tol=1e-8):
    mod = _edit(model, edits or {})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)      # ANDES's FEX: sqrt of a negative
        a = run_andes_ss(load_case(_case(model), fault="auto", modify=mod), tf, h, tol=andes_tol,
                         configure=fix_andes_esdc1a)
    assert a["ok"], a.get("error")
    out = {}
    for conv in conventions:
        w = run_weakgrid_ss(load_case(_case(model), fault="auto", modify=mod), tf, h, conventions=conv)
        assert w["ok"]
        dw, dd = compare_named(a, w)
        print(f"{model} {edits or ''} h=1/{round(1 / h)} {conv}: {dw:.3g} pu / {dd:.3g} deg")
        out[conv] = (dw, dd, w)
    return out


def _trace(w, model, name):
    c = w["system"].components[model]
    return np.asarray(w["res"][f"{c.names[0]}.{name}"])


#: measured gap of the standard models where ANDES 2.0 departs from them on the shipped case
STANDARD_GAP = {"ESAC1A": 9.7e-4}


@pytest.mark.parametrize("model", MODELS)
def test_shipped_case_matches(model):
    r = _runs(model, conventions=("andes", "standard"))
    dw, dd, w = r["andes"]
    assert dw < SPEED_TOL and dd < ANGLE_TOL
    dws, dds, _ = r["standard"]
    if model in STANDARD_GAP:
        assert w["system"].conventions_applied.get(model) == 1
        assert dws == pytest.approx(STANDARD_GAP[model], rel=0.05) and dds > 5.0
    else:
        assert dws < SPEED_TOL and dds < ANGLE_TOL


def test_esst1a_limits():
    """Regulator held at VAMAX = 5, input limiter VIMAX = 0.1 and the output ceiling
    ``Vt*VRMAX - KC*XadIfd`` (VRMAX = 5) active during the fault; the field-current limiter
    (ILR = KLR = 1) is active throughout. ANDES's Newton stalls above its default tolerance
    1e-8 once VA sits on VAMAX ("Time step reduced to zero" at t = 1.02 s), so ANDES runs at
    tol = 1e-5 here (weakgrid at its default)."""
    edits = dict(VAMAX=5.0, VIMAX=0.1, VRMAX=5.0)
    dw, dd, w = _runs("ESST1A", edits, tf=TF_SHORT, andes_tol=1e-5)["andes"]
    va, vi = _trace(w, "ESST1A", "VA"), _trace(w, "ESST1A", "vi")
    vas, efd = _trace(w, "ESST1A", "vas"), _trace(w, "ESST1A", "vout")
    assert va.max() == pytest.approx(5.0, abs=1e-9)                 # regulator ceiling
    assert vi.max() > 0.2                                           # input limiter cuts at 0.1
    assert (vas - efd).max() > 1.0                                  # output ceiling
    assert va[0] - vas[0] > 0.1                                     # field-current limiter
    assert dw < SPEED_TOL and dd < ANGLE_TOL


def test_esac1a_limits():
    """Regulator held at VAMAX = 10 (with ANDES's conventions); the standard model's VR also
    sits on VRMAX = 7.3, which ANDES 2.0 does not apply."""
    r = _runs("ESAC1A", dict(VAMAX=10.0), tf=TF_SHORT, conventions=("andes", "standard"))
    dw, dd, w = r["andes"]
    assert _trace(w, "ESAC1A", "VA").max() == pytest.approx(10.0, abs=1e-9)
    assert dw < SPEED_TOL and dd < ANGLE_TOL
    dws, _, ws = r["standard"]
    assert _trace(ws, "ESAC1A", "VR").max() == pytest.approx(7.3, abs=1e-9)
    assert dws > 1e-4


def test_esdc1a_limits():
    """Regulator at its ceiling VRMAX = 7.3 (as shipped: the fault is at its own bus) and at
    its floor VRMIN = -0.2 after clearing."""
    r = _runs("ESDC1A", dict(VRMIN=-0.2), tf=TF_SHORT, conventions=("andes", "standard"))
    for conv, (dw, dd, w) in r.items():
        vr = _trace(w, "ESDC1A", "VR")
        assert vr.max() == pytest.approx(7.3, abs=1e-9) and vr.min() == pytest.approx(-0.2, abs=1e-9)
        assert dw < SPEED_TOL and dd < ANGLE_TOL, conv


def _ieeet3_limits(h, tf=TF_SHORT):
    edits = dict(VRMIN=-2.6, VRMAX=-1.5, VBMAX=1.8)
    return _runs("IEEET3", edits, h=h, tf=tf)["andes"]


def test_ieeet3_limits():
    """Regulator at both limits (VRMIN = -2.6, VRMAX = -1.5) and the exciter input VR + VB
    clipped at VBMAX = 1.8 and at 0."""
    dw, dd, w = _ieeet3_limits(H)
    vr, vb = _trace(w, "IEEET3", "VR"), _trace(w, "IEEET3", "VB")
    assert vr.max() == pytest.approx(-1.5, abs=1e-9) and vr.min() == pytest.approx(-2.6, abs=1e-9)
    assert (vr + vb).max() > 1.9 and (vr + vb).min() < -0.1
    assert dw < SPEED_TOL and dd < ANGLE_TOL


def test_ieee14_gap_halves_with_the_step():
    """The 1.2-1.3e-5 pu at h is ANDES's step error: at h/2 in both tools it halves (IEEET3
    limits case, 2 s: 1.28e-5 -> 6.4e-6 pu; 5 s: 1.22e-5 -> 6.0e-6 pu)."""
    dw1 = _ieeet3_limits(H, tf=2.0)[0]
    dw2, dd2, _ = _ieeet3_limits(H / 2, tf=2.0)
    assert dw2 < 0.6 * dw1 and dd2 < ANGLE_TOL


ZERO = {
    "ESST1A": dict(TB=0.0, TC=0.0, TB1=0.0, TC1=0.0, TR=0.0, TA=0.0, TF=0.0),
    "ESAC1A": dict(TB=0.0, TC=0.0, TR=0.0, TA=0.0),
    "ESDC1A": dict(TB=0.0, TC=0.0, TR=0.0, KF=0.0),
    "IEEET3": dict(TR=0.0, TA=0.0, KF=0.0),
}


@pytest.mark.parametrize("name", list(ZERO))
def test_zero_parameters_as_andes(name):
    model = name.split()[0]
    dw, dd, _ = _runs(model, ZERO[name], tf=TF_SHORT)["andes"]
    assert dw < SPEED_TOL and dd < ANGLE_TOL
