"""A series-voltage step past a fold of the network equations is a "voltage collapse".

Before, such a step failed with cause "newton" and a residual-homotopy fraction that meant
nothing physical ("likely voltage collapse"). Now the re-solve follows the network along the
step itself and reports the fold. Oracles, independent of the continuation: the fold sits at the
same applied series voltage whatever the size of the step; a step just short of it runs; the
dense network Jacobian is singular there; beyond it Levenberg–Marquardt finds no solution.
"""

import numpy as np
import pytest
import scipy.optimize as so

from sim_cases import build_gti_upqc_sg
from weakgrid.sim.controllers import DigitalController, UPQCTarget, gti_design_states
from weakgrid.sim.integrate import simulate


def _step(vup):
    """GTI + UPQC + SG grid at rest; at t = 0.1 s the UPQC steps to Vup = ``vup`` (quadrature)."""
    s = build_gti_upqc_sg("conventional")
    s.components["UPQC"].p["Vmax"][:] = 10.0          # no rating clip: the step is exact
    u = np.array([vup, 0.0])
    c = DigitalController(lambda m: u, 1e-3, gti_design_states("PV"), UPQCTarget("U"),
                          enable=[(0.1, 10.0)], name="step")
    return s, simulate(s, 0.15, dt=1e-3, controllers=[c], on_failure="return")


def _g(s, t, z):
    nx = s.nx

    def g(y):
        zz = z.copy()
        zz[nx:] = y
        return s.residual(t, zz)[0][nx:]

    return g


def test_step_past_the_fold_is_a_voltage_collapse_at_a_fixed_series_voltage():
    folds = []
    for vup in (0.5, 1.0):
        s, r = _step(vup)
        err = r.failure
        assert err is not None and err.cause == "voltage collapse"     # was "newton"
        assert err.t == pytest.approx(0.1)
        folds.append(err.fold["s"] * vup)                  # applied Vup at the fold
        assert float(err.fold["outputs"]["UPQC.Vu"][0]) == pytest.approx(folds[-1], rel=1e-6)
    # the fold is a property of the network, not of the step: the same Vup from both steps
    assert folds[0] == pytest.approx(folds[1], rel=2e-3)
    vf = folds[1]
    assert 0.1 < vf < 0.5
    # a step to just short of the fold runs
    assert _step(0.95 * vf)[1].failure is None
    # the dense network Jacobian is singular at the reported fold (against before the step)
    nx = s.nx
    up = s.components["UPQC"]
    z0, zf = err.fold["z0"], err.fold["z"]
    up.u_p[0] = 0.0
    s0 = np.linalg.svd(s.jacobian(0.1, z0)[nx:, nx:], compute_uv=False)[-1]
    up.u_p[0] = vf
    sf = np.linalg.svd(s.jacobian(0.1, zf)[nx:, nx:], compute_uv=False)[-1]
    assert sf < 0.02 * s0
    # beyond the fold no network solution exists near the pre-step point or the fold
    up.u_p[0] = 1.2 * vf
    g = _g(s, 0.1, z0)
    for y0 in (z0[nx:], zf[nx:]):
        r = so.root(g, y0, method="lm")
        assert np.max(np.abs(g(r.x))) > 1e-4
