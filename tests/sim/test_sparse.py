"""The sparse path of the simulator: pattern, colouring, assembly, solvers, templates, recording.

Oracles: the dense path (same trajectories to 1e-10), the dense first-fit colouring it replaced,
the dense Ybus, and the power-flow equilibrium of a freshly initialized system.
"""

import sys

import numpy as np
import pytest
import scipy.sparse as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from sim_cases import build_gti_upqc_sg, two_machine_case

from weakgrid.sim.errors import DataError
from weakgrid.sim.events import Fault, LineTrip
from weakgrid.sim.integrate import Simulator
from weakgrid.sim.linsolve import DenseSolver, SparseSolver, make_solver, sparse_lu
from weakgrid.sim.system import System, colour_columns


def _dense_first_fit(P):
    """The O(N^2) dense colouring the simulator used before (reference)."""
    N = P.shape[1]
    colour = -np.ones(N, dtype=int)
    used = []
    for j in range(N):
        rows = P[:, j]
        if not rows.any():
            continue
        for k, u in enumerate(used):
            if not (u & rows).any():
                colour[j] = k
                u |= rows
                break
        else:
            colour[j] = len(used)
            used.append(rows.copy())
    return colour, len(used)


@settings(max_examples=40, deadline=None)
@given(st.integers(1, 40), st.floats(0.0, 0.3), st.integers(0, 2**31 - 1))
def test_colouring_equals_dense_first_fit_and_is_valid(n, density, seed):
    rng = np.random.default_rng(seed)
    P = rng.random((n, n)) < density
    colour, nc = colour_columns(sp.csc_matrix(P))
    ref, nref = _dense_first_fit(P)
    assert nc == nref
    np.testing.assert_array_equal(colour, ref)
    for k in range(nc):   # no two columns of one colour share a row
        assert (P[:, colour == k].sum(axis=1) <= 1).all()


def test_sparse_ybus_equals_dense():
    from weakgrid.sim.network import Network

    net = Network(two_machine_case())
    st_ = np.array([True])
    sh = np.array([0.1 + 0.2j, -0.3j])
    np.testing.assert_allclose(net.ybus_sparse(st_, sh).toarray(), net.ybus(st_, sh), rtol=0, atol=1e-14)
    np.testing.assert_allclose(net.ybus_sparse(~st_, sh).toarray(), net.ybus(~st_, sh), rtol=0, atol=1e-14)


@pytest.fixture(scope="module")
def gus():
    return build_gti_upqc_sg("reduced")


def test_sparse_jacobian_equals_dense(gus):
    z = gus.z0 + 1e-3 * np.random.default_rng(0).standard_normal(gus.N)
    np.testing.assert_allclose(gus.jacobian_sparse(0.0, z).toarray(), gus.jacobian(0.0, z), rtol=0, atol=1e-12)


def _lu_available(lu):
    if lu == "klu":
        pytest.importorskip("kvxopt", reason="KLU needs the extra weakgrid[klu]")


@pytest.mark.parametrize("lu", ["klu", "superlu"])
def test_sparse_factorizations_solve_like_dense(gus, lu):
    _lu_available(lu)
    z = gus.z0
    d, s = DenseSolver(gus), SparseSolver(gus, lu=lu)
    vals = gus.device_jacobian_values(0.0, z)
    d.set_device_jacobian(vals)
    s.set_device_jacobian(vals)
    b = np.random.default_rng(1).standard_normal(gus.N)
    fr = gus.lim_idx[:2]
    for _ in range(2):     # second round: refactorization with the reused analysis
        np.testing.assert_allclose(s.factor_iteration(0.01, fr).solve(b), d.factor_iteration(0.01, fr).solve(b),
                                   rtol=1e-9, atol=1e-11)
        np.testing.assert_allclose(s.factor_algebraic().solve(b[gus.nx:]), d.factor_algebraic().solve(b[gus.nx:]),
                                   rtol=1e-9, atol=1e-11)


def test_sparse_lu_without_kvxopt(gus, monkeypatch):
    """Without kvxopt (the base install) "auto" is SuperLU and an explicit "klu" is an error
    naming the extra (it used to switch to SuperLU silently, so a benchmark's "--lu klu" could
    time SuperLU)."""
    monkeypatch.setitem(sys.modules, "kvxopt", None)      # import kvxopt -> ImportError
    assert sparse_lu() == "superlu"
    assert SparseSolver(gus).lu == "superlu"
    with pytest.raises(DataError, match=r"weakgrid\[klu\]"):
        SparseSolver(gus, lu="klu")
    with pytest.raises(DataError, match="'lu'"):
        sparse_lu("umfpack")


def test_sparse_lu_auto_is_klu_with_kvxopt(gus):
    pytest.importorskip("kvxopt", reason="KLU needs the extra weakgrid[klu]")
    assert sparse_lu("auto") == "klu" and SparseSolver(gus).lu == "klu"
    assert SparseSolver(gus, lu="superlu").lu == "superlu"


def test_make_solver_choice_and_bad_kind(gus):
    assert make_solver(gus, "dense").name == "dense"
    assert make_solver(gus, "sparse").name == "sparse"
    with pytest.raises(DataError, match="linear_solver"):
        make_solver(gus, "cholesky")


def _run(build, kind, events, tf, dt):
    s = build()
    return Simulator(s, dt=dt, linear_solver=kind, record="all").run(tf, events=events)


def _same(a, b, tol=1e-10, names=None):
    """Same time points; every variable within ``tol`` (relative to its size when above 1 pu)."""
    assert a.names == b.names
    np.testing.assert_array_equal(a.t, b.t)
    cols = [a.names.index(n) for n in names] if names is not None else slice(None)
    da, db = a.data[:, cols], b.data[:, cols]
    scale = np.maximum(1.0, np.max(np.abs(da), axis=0))
    assert np.max(np.abs(da - db) / scale) < tol


def test_sparse_and_dense_same_trajectory_gti_upqc_sg():
    ev = [Fault(3, 0.2, 0.25, xf=0.05)]
    a = _run(lambda: build_gti_upqc_sg("reduced"), "dense", ev, 2.0, 5e-3)
    b = _run(lambda: build_gti_upqc_sg("reduced"), "sparse", [Fault(3, 0.2, 0.25, xf=0.05)], 2.0, 5e-3)
    _same(a, b)


@pytest.mark.andes
@pytest.mark.parametrize("case,fault", [("kundur/kundur_full.xlsx", (8, 1.0, 1.05))])
def test_sparse_and_dense_same_trajectory_peer_case(case, fault):
    """States agree to 1e-10 at the default Newton tolerance; with a tight tolerance every
    recorded variable does too (at the default one, the algebraic re-solve after the fault
    clearing stops anywhere within its tolerance of the solution, so algebraic outputs there
    may differ by round-off amplified up to ~1e-9)."""
    pytest.importorskip("andes")
    from weakgrid.sim.peer.andes_runs import build_weakgrid

    for tol, states_only in ((1e-7, True), (1e-11, False)):
        out = []
        for kind in ("dense", "sparse"):
            s, events, _ = build_weakgrid(case, fault=fault, disable_toggles=True)
            s.setup()
            out.append(Simulator(s, dt=1 / 120, tol=tol, linear_solver=kind, record="all").run(5.0, events=events))
        names = s.state_names() if states_only else None
        _same(*out, names=names)


def test_template_classical_case39_is_an_equilibrium_and_sparse_equals_dense():
    from weakgrid.sim.templates import (
        classical_parameters,
        classical_system,
        matpower_case,
    )

    mpc = matpower_case("case39")
    s = classical_system(mpc, H=4.0, xd1=0.3)
    assert len(s.machine_names) == len(classical_parameters(mpc)) == int((mpc["gen"][:, 7] > 0).sum())
    F, _ = s.residual(0.0, s.z0)
    assert np.max(np.abs(F)) < 1e-8
    runs = []
    for kind in ("dense", "sparse"):
        s = classical_system(mpc)
        runs.append(Simulator(s, dt=1 / 120, linear_solver=kind, record="all")
                    .run(2.0, events=[Fault(16, 0.5, 0.55), LineTrip(3, 1.0)]))
    _same(*runs, names=s.state_names())   # states (see the peer-case test for the algebraic ones)


def test_template_bad_input():
    from weakgrid.sim.templates import classical_system, matpower_case

    with pytest.raises(DataError, match="pandapower.networks"):
        matpower_case("case_does_not_exist")
    with pytest.raises(DataError, match="H"):
        classical_system(two_machine_case(), H=-1.0)


def test_record_selection():
    def build():
        s = System(two_machine_case())
        s.add_machine("GENCLS", "G0", 0, M=6.0, xd1=0.3)
        s.add_machine("GENCLS", "G1", 1, M=6.0, xd1=0.3)
        return s.setup()

    full = Simulator(build(), dt=0.01, record="all").run(0.5, events=[Fault(1, 0.1, 0.15)])
    mach = Simulator(build(), dt=0.01, record="machines").run(0.5, events=[Fault(1, 0.1, 0.15)])
    assert sorted(mach.names) == ["G0.delta", "G0.omega", "G1.delta", "G1.omega"]
    for n in mach.names:
        np.testing.assert_array_equal(mach[n], full[n])
    pat = Simulator(build(), dt=0.01, record=["*.omega", "bus1.v"]).run(0.2)
    assert sorted(pat.names) == ["G0.omega", "G1.omega", "bus1.v"]
    with pytest.raises(DataError, match="record"):
        Simulator(build(), dt=0.01, record=["G7.omega"]).run(0.1)


def _plain_fd(s, z, t=0.0):
    """Device Jacobian by one forward difference per column (no pattern, no colouring)."""
    F0 = s.device_residual(t, z)[0]
    J = np.zeros((s.N, s.N))
    for j in range(s.N):
        h = 1e-7 * max(1.0, abs(z[j]))
        zp = z.copy()
        zp[j] += h
        J[:, j] = (s.device_residual(t, zp)[0] - F0) / h
    return J


@pytest.mark.parametrize("which", ["gti_upqc_sg", "case39_classical"])
def test_sparse_pattern_is_complete_and_colouring_exact(which, gus):
    """Every device derivative lies inside the sparse pattern, and the coloured differences
    equal the plain column-by-column ones (columns of one colour really share no row)."""
    if which == "gti_upqc_sg":
        s = gus
    else:
        from weakgrid.sim.templates import classical_system

        s = classical_system("case39")
    z = s.z0 + 1e-3 * np.random.default_rng(2).standard_normal(s.N)
    ref = _plain_fd(s, z)
    inside = s.pattern.toarray()
    assert np.max(np.abs(ref[~inside])) < 1e-6
    J = np.zeros((s.N, s.N))
    J[s._pr, s._pc] = s.device_jacobian_values(0.0, z)
    np.testing.assert_allclose(J, np.where(inside, ref, 0.0), rtol=0, atol=1e-12)


@pytest.mark.parametrize("lu", ["klu", "superlu"])
def test_singular_matrix_gives_nan_not_a_traceback(gus, lu):
    """A singular matrix (no device derivatives, network switched to all zeros) is reported as
    NaN solutions, which the integrator handles as a failed iteration."""
    _lu_available(lu)
    nx = gus.nx
    saved = gus.Yr_coo
    try:
        gus.Yr_coo = (saved[0], saved[1], np.zeros_like(saved[2]))
        s = SparseSolver(gus, lu=lu)
        s.set_device_jacobian(np.zeros(len(gus._pr)))
        x = s.factor_algebraic().solve(np.ones(gus.N - nx))
    finally:
        gus.update_network()
    assert np.all(np.isnan(x))
