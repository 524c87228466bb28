"""ZIP load: equilibrium at the power-flow point, polynomial voltage dependence, bad input."""

import numpy as np
import pytest
from sim_cases import two_machine_case

from weakgrid.sim.errors import DataError
from weakgrid.sim.loads import ZIP
from weakgrid.sim.system import System

SG = dict(Sn=200, M=8.0, D=1.0, ra=0.0, xd1=0.3)


def build(P0=0.5, Q0=0.2, **k):
    case = two_machine_case(x_line=0.2, p=0.6)
    case["bus"][0, 2:4] = [60.0, 25.0]          # bus 1 load 0.6 + j0.25 pu
    s = System(case)
    s.add_machine("GENCLS", "G1", 0, **SG)
    s.add_machine("GENCLS", "G2", 1, **SG)
    z = s.add_component(ZIP())
    z.add_zip("Z", bus=0, P0=P0, Q0=Q0, **k)
    return s.setup()


K = dict(kpp=50, kpi=30, kpz=20, kqp=10, kqi=0, kqz=90)


def test_equilibrium_and_polynomial():
    s = build(**K)
    F, ctx = s.residual(0.0, s.z0)
    assert np.max(np.abs(F)) < 1e-9
    # at 0.9 of the initial voltage the ZIP share draws the polynomial power, the rest stays Z
    z = s.z0.copy()
    nx, nb = s.nx, s.nb
    z[nx:] *= 0.9
    ctx = s.evaluate(0.0, z)
    P = ctx.out["ZIP.P"][0]
    assert P == pytest.approx(0.5 * (0.5 + 0.3 * 0.9 + 0.2 * 0.81), rel=1e-12)
    V = z[nx] + 1j * z[nx + nb]
    S_dev = V * np.conj(ctx.I[0])               # device injection at bus 1 (ZIP only; GENCLS elsewhere)
    S_gen = V * np.conj(s.components["GENCLS"].network_current(
        *_stator(s, ctx), s.z0[s.components["GENCLS"].idx("delta")])[0])
    y0 = np.conj(0.5 + 0.2j) / abs(s.network.pf.V[0]) ** 2
    # ZIP injection = -(P + jQ) + (removed constant-impedance share) y0* |V|^2
    Q = 0.2 * (0.1 + 0.9 * 0.81)
    assert (S_dev - S_gen) == pytest.approx(-(P + 1j * Q) + np.conj(y0) * abs(V) ** 2, abs=1e-9)


def _stator(s, ctx):
    return ctx.out["GENCLS.Id"], ctx.out["GENCLS.Iq"]


def test_shares_must_sum_to_100():
    with pytest.raises(DataError, match="kpp"):
        build(**{**K, "kpp": 40})


def test_zip_larger_than_load_refused():
    with pytest.raises(DataError, match="exceed"):
        build(P0=0.9, **K)
