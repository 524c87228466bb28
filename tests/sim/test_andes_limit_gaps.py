"""Where weakgrid and ANDES 2.0.0 differ at non-windup limits, and why (measured causes).

IEEET1 with its regulator limit active (Kundur, machine 3: KA = 60, VRMAX = 3, VRMIN = 0.5,
150-ms fault at bus 8) differs from ANDES by 1.9e-4 pu of speed and 1.0 deg. The cause is in
ANDES's solution, not in the model: in the steps where its anti-windup lag ``LA`` reaches
``VRMAX`` (after the fault and after the clearing), ANDES's exciter integrator ``INT``
(``TE dINT/dt = LA - VFE``) advances by 2-3.5 times the trapezoidal increment of its own
recorded ``LA`` and ``VFE`` — it integrates the regulator output beyond the limit. ANDES
accepts those steps as converged although the limit flag toggles between Newton iterations
(its "chattering" exit, ``TDS.config.chatter_iter``), and its iteration-count heuristic then
shortens its "fixed" step (1/120 s becomes 0.0061-0.0079 s). weakgrid's exciter voltage obeys
its trapezoidal equation to Newton tolerance with the regulator output held at ``VRMAX``.
"""

import warnings

import numpy as np
import pytest

andes = pytest.importorskip("andes")

from kundur_variants import kundur_variant  # noqa: E402

from weakgrid.sim.peer.andes_case import compare_named, load_case, run_andes_ss, run_weakgrid_ss  # noqa: E402

pytestmark = [pytest.mark.andes, pytest.mark.slow]

H = 1 / 120
IEEET1 = dict(TR=0.02, KA=60, TA=0.04, VRMAX=3.0, VRMIN=0.5, KE=1, TE=0.8, KF=0.05, TF=1.0,
              E1=2.8, SE1=0.04, E2=3.73, SE2=0.33)


def _trapezoid_excess(t, x, f):
    """Per step: increment of ``x`` minus the trapezoidal increment ``h/2 (f0 + f1)``."""
    keep = np.r_[np.diff(t) > 0, True]            # one sample per event time
    t, x, f = t[keep], x[keep], f[keep]
    return np.diff(x) - np.diff(t) / 2 * (f[1:] + f[:-1])


def test_ieeet1_limit_gap_is_andes_integrating_beyond_the_limit(tmp_path):
    path = kundur_variant(tmp_path / "ieeet1.xlsx", exciters={3: ("IEEET1", IEEET1)})
    fault = (8, 1.0, 1.15)
    a = run_andes_ss(load_case(path, fault=fault), 3.0, H)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        w = run_weakgrid_ss(load_case(path, fault=fault), 3.0, H)
    assert a["ok"] and w["ok"]
    dw, dd = compare_named(a, w)
    print(f"IEEET1 at its limit: {dw:.3g} pu, {dd:.3g} deg")
    assert dw > 5e-5, "the gap is gone: did ANDES change? (then put IEEET1's limit back in the peer case)"

    ss, TE = a["ss"], 0.8
    E, ts = ss.IEEET1, ss.dae.ts
    t = np.asarray(ts.t)
    LA, INT, VFE = ts.x[:, E.LA_y.a[0]], ts.x[:, E.INT_y.a[0]], ts.y[:, E.VFE.a[0]]
    assert np.max(LA) == pytest.approx(3.0, abs=1e-9)          # ANDES records LA held at VRMAX ...
    excess_a = _trapezoid_excess(t, INT, (LA - VFE) / TE)
    assert np.max(excess_a) > 5e-3                              # ... but INT integrates beyond it
    steps = np.diff(t[t > 1.05])
    assert np.min(steps[steps > 1e-3]) < 0.9 * H                # and its "fixed" step shrank

    res, name = w["res"], "IEEET1_3"
    VR, EFD = res[f"{name}.VR"], res[f"{name}.Efd"]
    assert np.max(VR) == pytest.approx(3.0, abs=1e-9)
    exciter = w["system"].components["IEEET1"].EX           # TE dEfd/dt = VR - VFE(Efd)
    excess_w = _trapezoid_excess(np.asarray(res.t), EFD, exciter.deriv(EFD, VR))
    assert np.max(np.abs(excess_w)) < 1e-6                      # weakgrid: its equation holds
