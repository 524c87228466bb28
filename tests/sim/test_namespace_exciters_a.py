"""The exciters AC8B, ESAC1A, ESAC6A, ESDC1A, ESDC2A, ESST1A, ESST3A, ESST4B, EXAC1, EXAC2 (and
their shared DC exciter) evaluated on another array namespace (issue #21).

As in :mod:`test_namespace`: the residual and every recorded output on ``array_api_strict``
equal NumPy's bit for bit, at the initial point and at points far enough out to take the
limiters, the rectifier's regimes and the saturation. Each grid has four GENROU machines on two
buses (:func:`test_shared_bus._shared_case`): one with three instances of the exciter with
different options on machines 0, 1, 3 (the machines indexed by an index array), one with the
same options on all four (a slice, and the blocks' uniform paths)."""

from __future__ import annotations

import numpy as np
import pytest
from test_namespace import _check, _no_numpy_on_strict_arrays, _points  # noqa: F401

from weakgrid.sim.namespace import namespace_models

SAT = dict(E1=3.0, SE1=0.05, E2=4.0, SE2=0.3)
ESST4B = dict(TR=0.01, KPR=3.0, KIR=2.0, VRMAX=8.0, VRMIN=0.0, TA=0.02, KPM=1.0, KIM=1.0, VMMAX=1.0,
              VMMIN=0.0, KG=1.0, KP=4.0, KI=0.1, VBMAX=18.0, KC=0.1, XL=0.01, THETAP=0.0, VGMAX=20.0)
AC8B = dict(TR=0.01, kP=3.0, kI=1.0, kD=1.0, Td=0.2, VPMAX=999.0, VPMIN=-999.0, VRMAX=7.3, VRMIN=1.0,
            VFEMAX=999.0, VEMIN=-999.0, TA=0.04, KA=40.0, TE=0.8, KE=1.0, KD=0.0, KC=0.1)
ESAC6A = dict(TR=0.0, KA=536.0, TA=0.086, TK=0.18, TB=9.0, TC=3.0, VAMAX=75.0, VAMIN=-75.0, VRMAX=44.0,
              VRMIN=-36.0, TE=1.0, VFELIM=19.0, KH=92.0, VHMAX=75.0, TH=0.08, TJ=0.02, KC=0.173, KD=1.91,
              KE=1.6, E1=7.4, SE1=0.214, E2=5.55, SE2=0.044)
EXAC2 = dict(TR=0.0, TB=0.0, TC=0.0, KA=400.0, TA=0.02, VAMAX=8.0, VAMIN=-8.0, KB=25.0, VRMAX=105.0,
             VRMIN=-95.0, TE=0.6, KL=1.0, KH=1.0, KF=0.03, TF=1.0, KC=0.28, KD=0.35, KE=1.0, VLR=4.4,
             E1=4.4, SE1=0.037, E2=3.3, SE2=0.012)

#: per model: the options of its instances (three differing ones; the first also on all four)
VARIANTS = {
    "ESDC1A": [dict(KA=80, **SAT), dict(KA=40, TR=0.0, TB=0.0, TC=0.0, TR_used=0.0),
               dict(KA=80, VRMAX=0.0, VRMIN=-2.0, TR_used=0.0, **SAT)],
    "ESDC2A": [dict(KA=80, **SAT), dict(KA=40, TR=0.0, TB=0.0, TC=0.0, TR_used=0.0),
               dict(KA=80, VRMAX=0.0, VRMIN=-2.0, TR_used=0.0, **SAT)],
    "EXAC1": [dict(KD=0.2, **SAT), dict(KD=0.2, TR_used=0.0, TB=0.0, TC=0.0, KC=0.5),
              dict(KA=200, VRMAX=4.0, VRMIN=-1.0, KF=0.0, **SAT)],
    "EXAC2": [EXAC2, dict(EXAC2, TR=0.02, TB=1.0, TC=0.5, KH=0.5, KL=2.0),
              dict(EXAC2, TA=0.0, TR=0.02, TR_used=0.0)],
    "ESAC1A": [dict(KD=0.2, **SAT), dict(KD=0.2, VRMAX=5.0, VF_used=0.0, VR_limited=0.0),
               dict(TA=0.0, TR=0.0, TB=0.0, TC=0.0, VAMAX=6.0, VAMIN=-2.0, VRMAX=5.0, KC=0.5, **SAT)],
    "ESAC6A": [ESAC6A, dict(ESAC6A, VFELIM=3.0, KH=2.0),
               dict(ESAC6A, TA=0.0, TR=0.0, TB=0.0, TC=0.0, TH=0.0, TJ=0.0)],
    "ESST1A": [dict(KA=80, ILR=1.5, KLR=2.0), dict(KA=80, VOSc=2),
               dict(KA=80, TA=0.0, KF=0.0, TB=0.0, TC=0.0, TB1=0.5, TC1=1.0, VIMAX=0.05, VIMIN=-0.05)],
    "ESST3A": [dict(KA=20, VRMAX=8, THETAP=10.0), dict(KA=20, VRMAX=8, TA=0.0, TR=0.0, TB=0.0, TC=0.0),
               dict(KA=20, VRMAX=8, KC=0.3, VGMAX=1.5, VIMAX=0.2, VIMIN=-0.05)],
    "ESST4B": [ESST4B, dict(ESST4B, PI_nonwindup=0.0),
               dict(ESST4B, TA=0.0, TR=0.0, VGMAX=1.5, THETAP=15.0, KC=0.6)],
    "AC8B": [AC8B, dict(AC8B, PID_nonwindup=0.0, VE_limited=0.0),
             dict(AC8B, TA=0.0, KD=0.2, VPMAX=2.0, VPMIN=-2.0, VFEMAX=4.0, VEMIN=0.0, KC=0.5, **SAT)],
}


def _grid(model, uniform=False):
    """Four GENROU machines; the exciter ``model`` on machines 0, 1, 3 with its three options,
    or (``uniform``) on all four with the first; set up."""
    from test_shared_bus import _shared_case

    system = _shared_case("GENROU")
    opts = VARIANTS[model]
    machines = [(k, opts[0]) for k in range(4)] if uniform else list(zip((0, 1, 3), opts))
    for k, prm in machines:
        system.add_exciter(model, f"E{k}", machine=f"G{k}", **prm)
    return system.setup()


def _far_points(system, seed):
    """:func:`test_namespace._points` and a point further out (every state and voltage scaled
    by up to 5 and shifted by up to 3: the limiters, the rectifier and the saturation)."""
    rng = np.random.default_rng(seed + 100)
    Z = _points(system, seed)
    z0 = system.z0
    far = z0 * rng.uniform(-5, 5, z0.shape) + rng.uniform(-3, 3, z0.shape)
    return np.vstack([Z, far[None]])


@pytest.mark.parametrize("uniform", [False, True], ids=["options", "uniform"])
@pytest.mark.parametrize("model", sorted(VARIANTS))
def test_the_exciter_evaluates_on_the_strict_namespace_as_on_numpy(model, uniform):
    system = _grid(model, uniform)
    assert namespace_models(system) == []
    _check(system, _far_points(system, seed=len(model) + 7 * uniform))


def test_the_guarded_branches_are_taken():
    """At the far point the rectifiers see VE <= 0 and IN beyond 1, the regulators their
    limits: the branches the checks above compare."""
    system = _grid("ESAC1A")
    Z = _far_points(system, seed=len("ESAC1A"))
    ve = Z[:, system.components["ESAC1A"].idx("VE")]
    assert np.any(ve <= 0) and np.any(ve > 0)
    _, ctx = system.device_residual(0.0, Z)
    vr = ctx.out["ESAC1A.VR"]
    assert np.any(np.abs(vr) == 5.0)          # VRMAX = 5 / VRMIN = -7.3 reached
