"""Analytic checks on a lossless single-machine / two-machine system with GENCLS."""

import numpy as np
import pytest

from weakgrid.sim.integrate import Simulator
from weakgrid.sim.system import System

from sim_cases import two_machine_case


def _build(D1=0.0, M2=6.0, x2=0.2, D2=0.0):
    sys = System(two_machine_case())
    sys.add_machine("GENCLS", "G1", 0, Sn=100, M=6.0, D=D1, ra=0.0, xd1=0.25)
    sys.add_machine("GENCLS", "G2", 1, Sn=100, M=M2, D=D2, ra=0.0, xd1=x2)
    sys.setup()
    return sys


def test_initial_point_is_equilibrium():
    sys = _build()
    F, _ = sys.residual(0.0, sys.z0)
    assert np.max(np.abs(F)) < 1e-10


def test_energy_function_conserved():
    """Lossless two-machine system, no damping: W = sum(M wb dw^2/2) - sum(Pm d) - E1 E2/X cos(d12) is constant."""
    sys = _build()
    z0 = sys.z0.copy()
    iw1 = sys.components["GENCLS"].idx("omega")[0]
    z0[iw1] += 0.005                      # speed kick on machine 1
    sys.z0 = z0
    sim = Simulator(sys, dt=1e-3, tol=1e-11)
    res = sim.run(10.0)
    c = sys.components["GENCLS"]
    M = c.p["M"]
    wb = c.wb
    E = sys.sig_defaults["vf0"]
    X = c.p["xd1"].sum() + 0.3
    Pm = sys.sig_defaults["tm0"]
    d1, d2 = res["G1.delta"], res["G2.delta"]
    w1, w2 = res["G1.omega"], res["G2.omega"]
    W = (0.5 * M[0] * wb[0] * (w1 - 1) ** 2 + 0.5 * M[1] * wb[1] * (w2 - 1) ** 2
         - Pm[0] * d1 - Pm[1] * d2 - E[0] * E[1] / X * np.cos(d1 - d2))
    kinetic0 = 0.5 * M[0] * wb[0] * 0.005 ** 2
    drift = np.max(np.abs(W - W[0]))
    assert drift / abs(W[0]) < 1e-6
    # stricter: relative to the oscillation energy itself
    assert drift / kinetic0 < 1e-4
    # it really oscillated
    assert np.ptp(d1 - d2) > 0.02


def _peaks(t, y):
    i = np.nonzero((y[1:-1] > y[:-2]) & (y[1:-1] >= y[2:]))[0] + 1
    # parabolic refinement
    tp, yp = [], []
    for k in i:
        a, b, c = y[k - 1], y[k], y[k + 1]
        den = a - 2 * b + c
        off = 0.5 * (a - c) / den if den != 0 else 0.0
        h = t[k + 1] - t[k]
        tp.append(t[k] + off * h)
        yp.append(b - 0.25 * (a - c) * off)
    return np.array(tp), np.array(yp)


@pytest.mark.parametrize("D", [0.0, 2.0])
def test_small_signal_frequency_and_damping_match_eigenvalues(D):
    """SMIB (machine 2 ~ infinite bus): oscillation frequency and damping vs the linearized eigenvalues."""
    sys = _build(D1=D, M2=1e8, x2=1e-4)
    c = sys.components["GENCLS"]
    # analytic linearization: M dw = -K dd - D dw,  dd' = wb dw
    E1, E2 = sys.sig_defaults["vf0"]
    d0 = sys.sig_defaults["delta0"]
    X = 0.25 + 0.3 + 1e-4
    K = E1 * E2 / X * np.cos(d0[0] - d0[1])
    M, wb = c.p["M"][0], c.wb[0]
    A = np.array([[0.0, wb], [-K / M, -c.p["D"][0] / M]])
    lam = np.linalg.eigvals(A)
    lam = lam[np.argmax(lam.imag)]
    z0 = sys.z0.copy()
    z0[c.idx("omega")[0]] += 1e-5
    sys.z0 = z0
    res = Simulator(sys, dt=1e-3, tol=1e-12).run(6.0)
    t, y = res.t, res["G1.omega"] - 1.0
    tp, yp = _peaks(t, y)
    assert len(tp) >= 4
    f_sim = 1.0 / np.mean(np.diff(tp))
    f_eig = lam.imag / (2 * np.pi)
    assert abs(f_sim - f_eig) / f_eig < 0.01
    if D > 0:
        sigma_sim = np.mean(np.log(yp[1:] / yp[:-1]) / np.diff(tp))
        assert abs(sigma_sim - lam.real) / abs(lam.real) < 0.01
    else:
        assert np.ptp(yp) / yp.max() < 1e-3
