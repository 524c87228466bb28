"""Small-signal analysis of the full DAE against analytic eigenvalues."""

import math

import numpy as np
import pytest

from weakgrid.design import linearize, machine_mode, modes
from weakgrid.sim.system import System


def two_machine_case(x_line=0.3, p=0.8):
    bus = np.array([[1, 2, 0, 0, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5],
                    [2, 3, 0, 0, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5]], float)
    gen = np.array([[1, p * 100, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11,
                    [2, 0, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11], float)
    branch = np.array([[1, 2, 0.0, x_line, 0.0, 0, 0, 0, 0, 0, 1, -360, 360]], float)
    return {"baseMVA": 100.0, "bus": bus, "gen": gen, "branch": branch}


def _build(M1=6.0, D1=0.0, M2=6.0, x2=0.2):
    s = System(two_machine_case())
    s.add_machine("GENCLS", "G1", 0, Sn=100, M=M1, D=D1, ra=0.0, xd1=0.25)
    s.add_machine("GENCLS", "G2", 1, Sn=100, M=M2, D=0.0, ra=0.0, xd1=x2)
    return s.setup()


def _K(s, X):
    E1, E2 = s.sig_defaults["vf0"]
    d0 = s.sig_defaults["delta0"]
    return E1 * E2 / X * math.cos(d0[0] - d0[1])


@pytest.mark.parametrize("D", [0.0, 3.0])
def test_smib_mode_equals_the_analytic_one(D):
    """Machine 2 ≈ infinite bus: λ of [[0, ωb], [−K/M, −D/M]]."""
    s = _build(D1=D, M2=1e8, x2=1e-4)
    c = s.components["GENCLS"]
    K = _K(s, 0.25 + 0.3 + 1e-4)
    M, wb = 6.0, c.wb[0]
    lam = np.linalg.eigvals(np.array([[0.0, wb], [-K / M, -D / M]]))
    lam = lam[np.argmax(lam.imag)]
    m = modes(s)
    k, part = machine_mode(m, ["G1.delta", "G1.omega"])
    assert m.eigenvalues[k] == pytest.approx(lam, rel=1e-5)
    assert part > 0.99
    zeta = -lam.real / abs(lam)
    assert m.damping_ratio[k] == pytest.approx(zeta, abs=1e-6)
    assert m.frequency_hz[k] == pytest.approx(lam.imag / (2 * math.pi), rel=1e-5)


def test_two_machine_mode_equals_the_analytic_one():
    """Two finite machines, no damping: λ² = −ωb·K·(1/M1 + 1/M2); participation split by M."""
    s = _build(M1=6.0, M2=12.0, x2=0.2)
    wb = s.components["GENCLS"].wb[0]
    K = _K(s, 0.25 + 0.3 + 0.2)
    w = math.sqrt(wb * K * (1 / 6.0 + 1 / 12.0))
    m = modes(s)
    k, _ = machine_mode(m, "G1")
    assert m.eigenvalues[k].imag == pytest.approx(w, rel=1e-5)
    assert abs(m.eigenvalues[k].real) < 1e-6 * w
    # the lighter machine swings more: G1 (M = 6) participates twice as much as G2 (M = 12)
    p = dict(m.dominant_states(k, n=4))
    assert p["G1.omega"] == pytest.approx(2 * p["G2.omega"], rel=1e-4)
    # the rest is the rigid-body (zero) mode pair: a double zero eigenvalue (a Jordan block),
    # which moves like the square root of the finite-difference error of the Jacobian
    # (~1e-8 relative gives ~1e-4 rad/s), so "zero" is judged against that, not against 1e-10
    others = np.delete(m.eigenvalues, [k, int(np.argmin(np.abs(m.eigenvalues - np.conj(m.eigenvalues[k]))))])
    assert np.max(np.abs(others)) < 1e-3 * w


def test_linearize_eliminates_the_network():
    s = _build()
    A = linearize(s)
    assert A.shape == (s.nx, s.nx)
