"""Compiled device kernels (weakgrid.sim.kernels): the same floats as NumPy.

Oracle: the elementwise core evaluated by NumPy on arrays — the model's equations as they
read, and the arithmetic of the code before the kernels (GENROU's residual, outputs and
Jacobian were checked equal to the previous commit's, bit for bit, when the core was split
out). The compiled core must give those floats exactly: ``+ - * /`` and ``sqrt`` are rounded
exactly by IEEE 754 in both, numba compiles without fast-math, and the transcendental
functions are NumPy's in both. A fused multiply-add, a re-associated sum or a libm ``sin``
inside the core would fail these tests.
"""

import copy

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from sim_cases import build_gti_upqc_sg, classical_smib, machine_smib

from weakgrid.sim import kernels
from weakgrid.sim.batch import simulate_batch
from weakgrid.sim.errors import DataError
from weakgrid.sim.events import Fault
from weakgrid.sim.machines import gencls
from weakgrid.sim.machines.genrou import _KERNEL, GENROU, quad_sat, quad_sat_scalar

numba = pytest.importorskip("numba")


@pytest.fixture(autouse=True, scope="module")
def _auto_backend():
    """These tests choose the backend themselves: not the caller's WEAKGRID_KERNELS."""
    with pytest.MonkeyPatch.context() as mp:
        mp.delenv("WEAKGRID_KERNELS", raising=False)
        yield


def _genrou(system):
    return next(c for c in system.comps if isinstance(c, GENROU))


def _signals(rng, B, n, scale):
    s = [1.0 + scale * rng.normal(size=(B, n)) for _ in range(4)]   # e1q, e1d, e2d, e2q
    delta = rng.uniform(-np.pi, np.pi, size=(B, n))
    V = (1 + 0.2 * rng.normal(size=(B, n))) * np.exp(1j * rng.uniform(-np.pi, np.pi, size=(B, n)))
    return s + [np.sin(delta), np.cos(delta), V.real, V.imag]


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), B=st.integers(1, 7), n=st.integers(1, 3),
       scale=st.sampled_from([0.0, 0.05, 1.0, 30.0]), ra0=st.booleans(), sat=st.sampled_from([0, 1]))
def test_genrou_core_compiled_equals_numpy(seed, B, n, scale, ra0, sat):
    """GENROU's core, compiled and on NumPy, bit for bit: states near and far from the
    operating point (deep saturation at scale 30), with and without ``ra`` and saturation."""
    rng = np.random.default_rng(seed)
    S = _signals(rng, B, n, scale)
    P = np.abs(rng.normal(size=(20, n))) + 0.01
    P[16] = rng.uniform(0.5, 1.0, n)                  # A: saturation starts below 1 pu flux
    if ra0:
        P[5] = P[17] = 0.0                            # cIdb, ra
    k = _KERNEL
    ref = k(S, P, (ra0, sat))                   # on NumPy
    got = k(S, P, (ra0, sat), (ra0, sat))       # compiled
    assert kernels.backend() == "numba" and k._loops[(8, (ra0, sat))] is not None
    for r, g in zip(ref, got):
        assert g.shape == r.shape
        assert np.array_equal(g, r, equal_nan=True)


def test_quad_sat_scalar_equals_genrou_sat():
    """The scalar saturation the compiled core calls gives the array form's floats, on both
    of its branches: all fluxes positive and finite (its fast path), and any zero, negative,
    infinite or NaN flux."""
    jit = numba.njit(quad_sat_scalar)
    for psi2 in (np.array([0.5, 0.8, 0.81, 1.3, 40.0]),
                 np.array([0.0, -0.2, np.nan, 0.5, 0.8, 1.3, np.inf])):
        ref = quad_sat(psi2, 0.8, 0.3)
        got = np.array([jit(float(x), 0.8, 0.3) for x in psi2])
        assert np.array_equal(got, ref, equal_nan=True), (got, ref)
        assert np.array_equal(np.array([quad_sat_scalar(float(x), 0.8, 0.3) for x in psi2]), ref)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), B=st.integers(1, 7), n=st.integers(1, 4), ra0=st.booleans())
def test_gencls_core_compiled_equals_numpy(seed, B, n, ra0):
    """GENCLS's core, compiled and on NumPy, bit for bit."""
    rng = np.random.default_rng(seed)
    S = _signals(rng, B, n, 1.0)[4:] + [1 + 0.3 * rng.normal(size=(B, n))]   # sin, cos, V, vf
    P = np.abs(rng.normal(size=(3, n))) + 0.01
    if ra0:
        P[1] = P[2] = 0.0
    ref = gencls._KERNEL(S, P, ())
    got = gencls._KERNEL(S, P, (), ())
    assert gencls._KERNEL._loops[(5, ())] is not None
    for r, g in zip(ref, got):
        assert np.array_equal(g, r)


@pytest.mark.parametrize("shapes", [((5,), (5,)), ((3, 5), (5,)), ((3, 5), (1, 5)), ((2, 3, 5), (3, 5))],
                         ids=["one point", "held signal", "one member", "three axes"])
def test_kernel_broadcasts_and_keeps_shapes(shapes):
    """Signals of one shape, or a signal held the same for every member beside per-member ones
    (broadcast as NumPy would): the compiled outputs have NumPy's shapes and values."""
    full, held = shapes
    rng = np.random.default_rng(7)
    S = [rng.normal(size=full) for _ in range(4)] + [rng.normal(size=held)]
    P = np.abs(rng.normal(size=(3, full[-1]))) + 0.01
    ref = gencls._KERNEL(S, P, ())
    got = gencls._KERNEL(S, P, (), ())
    assert None not in gencls._KERNEL._loops.values()
    for r, g in zip(ref, got):
        assert g.shape == r.shape
        assert np.array_equal(g, r)


def _runs(system, scenarios, t_end, monkeypatch):
    out = {}
    for mode in ("numpy", "numba"):
        monkeypatch.setenv("WEAKGRID_KERNELS", mode)
        out[mode] = simulate_batch(system, copy.deepcopy(scenarios), t_end, dt=5e-3, tol=1e-6)
    for k in (_KERNEL, gencls._KERNEL):       # nothing fell back to NumPy for want of compiling
        assert None not in k._loops.values()
    for a, b in zip(out["numpy"], out["numba"]):
        assert a.failure is None and b.failure is None
        assert a.names == b.names
        assert np.array_equal(a.t, b.t)
        assert np.array_equal(a.data, b.data)
        assert a.stats == b.stats
    return out


def test_batched_run_compiled_equals_numpy(monkeypatch):
    """Whole batched runs with a fault (GENROU saturated, the UPQC and GTI beside it): every
    recorded trajectory and statistic the same with the compiled kernels as on NumPy."""
    sys0 = build_gti_upqc_sg("conventional")
    assert _genrou(sys0)._compiled_flags is not None     # this grid's GENROU compiles
    scenarios = [{"events": [Fault(bus, 0.1, 0.1 + dur, xf=0.05)]}
                 for bus, dur in ((1, 0.1), (2, 0.15), (3, 0.05))]
    _runs(sys0, scenarios, 1.0, monkeypatch)


@pytest.mark.parametrize("build", [
    lambda: classical_smib(ra=0.01),                                    # GENCLS with ra
    lambda: machine_smib("GENROE", gen={"S10": 0.05, "S12": 0.3}),      # GENROE: on NumPy
], ids=["gencls", "genroe"])
def test_machine_runs_compiled_equal_numpy(build, monkeypatch):
    """A fault on each single-machine grid: the same trajectories compiled and on NumPy
    (GENROE's exponential saturation always runs on NumPy; its runs must not change)."""
    scenarios = [{"events": [Fault(1, 0.1, 0.1 + dur, xf=0.1)]} for dur in (0.05, 0.1)]
    _runs(build(), scenarios, 1.0, monkeypatch)


def test_backend_choice(monkeypatch):
    """WEAKGRID_KERNELS: a wrong value names the variable, the value and the choices;
    ``numba`` without numba says how to install it; ``auto`` falls back to NumPy."""
    monkeypatch.setenv("WEAKGRID_KERNELS", "fortran")
    with pytest.raises(DataError, match="WEAKGRID_KERNELS' = 'fortran'.*auto, numpy, numba"):
        kernels.backend()
    monkeypatch.setattr(kernels, "_numba", False)      # as if numba were not installed
    monkeypatch.setattr(kernels, "_LAST", [0, None])
    monkeypatch.setenv("WEAKGRID_KERNELS", "numba")
    with pytest.raises(DataError, match=r"weakgrid\[fast\]"):
        kernels.backend()
    monkeypatch.setenv("WEAKGRID_KERNELS", "auto")
    assert kernels.backend() == "numpy"


def test_cli_refuses_a_wrong_backend_before_any_work(tmp_path, monkeypatch, capsys):
    """The command stops at once with the input-error status and the variable's name, rather
    than failing every run of a sweep one by one."""
    from weakgrid.cli.main import main

    monkeypatch.setenv("WEAKGRID_KERNELS", "gpu")
    out = tmp_path / "c.json"
    assert main(["train", "--preset", "case1-paper", "--quiet", "--output", str(out)]) == 2
    assert "WEAKGRID_KERNELS" in capsys.readouterr().err
    assert not out.exists()


def test_unwritable_cache_compiles_in_memory(tmp_path, monkeypatch):
    """A kernel cache that cannot be written (here: a file where the directory should be)
    does not stop the compiled path: the loop is compiled in memory, with the same floats."""
    blocker = tmp_path / "cache"
    blocker.write_text("not a directory")
    monkeypatch.setenv("WEAKGRID_CACHE_DIR", str(blocker))
    k = kernels.Kernel(_KERNEL.core, _KERNEL.nout, _KERNEL.scalar_forms)   # no loop built yet
    rng = np.random.default_rng(3)
    S = _signals(rng, 4, 2, 1.0)
    P = np.abs(rng.normal(size=(20, 2))) + 0.01
    got = k(S, P, (False, 1), (False, 1))
    assert k._loops[(8, (False, 1))] is not None
    for r, g in zip(k(S, P, (False, 1)), got):
        assert np.array_equal(g, r)
