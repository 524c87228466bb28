"""The devices' evaluation on another array namespace (issue #21: an accelerator backend).

The oracle is NumPy itself: the grid's residual and every recorded output evaluated on
``array_api_strict`` (a namespace that raises on anything outside the array API standard)
must equal NumPy's bit for bit, at points that take the models' guarded branches too."""

from __future__ import annotations

import numpy as np
import pytest

from weakgrid.sim.errors import DataError
from weakgrid.sim.namespace import add_at, namespace_models, on_namespace, put, take, to_numpy

xps = pytest.importorskip("array_api_strict")


@pytest.fixture(autouse=True)
def _no_numpy_on_strict_arrays(monkeypatch):
    """A NumPy function called on a strict array raises (it would convert it silently)."""
    def refuse(self, *args, **kw):
        raise TypeError("a NumPy function called on an array_api_strict array")

    monkeypatch.setattr(type(xps.asarray(0.0)), "__array__", refuse)

STUDIES = ("case1-weak-grid", "case2-lv-microgrid", "case14-pv-gti", "cigre-mv-two-gti",
           "cigre-mv-wind-gti", pytest.param("ieee39-g3-upqc", marks=pytest.mark.andes),
           "ieee9-sg-upqc")     # ieee39: ANDES's case file, read by ANDES


def _system(study, **kw):
    import warnings

    from weakgrid.study.build import build_setup
    from weakgrid.study.studyfile import load_study

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return build_setup(load_study(study), **kw).system


def _points(system, seed=0):
    """The initial point and two perturbed points: states and voltages moved by up to ±0.2,
    and one far off (machines out of step, the UPQC beyond its rating)."""
    rng = np.random.default_rng(seed)
    z0 = system.z0
    Z = np.stack([z0, z0 + rng.uniform(-0.2, 0.2, z0.shape), z0 + rng.uniform(-2, 2, z0.shape)])
    return Z


def _strict_squares_as_numpy() -> bool:
    """Whether ``x ** 2`` on array_api_strict gives NumPy's floats: it computes
    ``numpy.power(x, array(2.0))``, which NumPy 2.0 evaluates by the general power function
    (5 % of random squares differ in the last bit, measured with NumPy 2.0.2) and later NumPy
    as the square ``x ** 2`` is."""
    x = np.random.default_rng(0).uniform(0.0, 3.0, 10_000)
    return np.array_equal(x ** 2, np.power(x, np.asarray(2.0)))


#: bit for bit where the namespaces' arithmetic agrees; else to the last bits of a square
EXACT = _strict_squares_as_numpy()


def _same(a, b, what):
    assert isinstance(b, type(xps.asarray(0.0))), f"{what}: {type(b).__name__}, not a strict array"
    a, b = np.asarray(a), to_numpy(b)
    assert a.shape == b.shape, what
    if EXACT:
        assert np.array_equal(a, b, equal_nan=True), f"{what}: {np.max(np.abs(a - b))}"
    else:
        np.testing.assert_allclose(b, a, rtol=1e-13, atol=1e-14, equal_nan=True, err_msg=what)


def _check(system, Z):
    other = on_namespace(system, xps)
    for z in (Z, Z[1]):        # a batch of points and one point
        F, ctx = system.device_residual(0.0, z)
        Fs, ctxs = other.device_residual(0.0, xps.asarray(z))
        _same(F, Fs, "residual")
        assert set(ctx.out) == set(ctxs.out)
        for k in ctx.out:
            _same(np.broadcast_to(ctx.out[k], np.shape(to_numpy(ctxs.out[k]))), ctxs.out[k], k)


@pytest.mark.parametrize("study", STUDIES)
def test_the_shipped_grids_evaluate_on_the_strict_namespace_as_on_numpy(study):
    system = _system(study)
    assert namespace_models(system) == []
    _check(system, _points(system))


def test_the_upqc_limits_and_dc_link_evaluate_on_the_strict_namespace_as_on_numpy():
    """The UPQC's series voltage beyond its rating and beyond what its dc link carries, and a
    dc link below its set point: the guarded branches."""
    system = _system("case1-weak-grid")
    up = system.components["UPQC"]
    up.u_q = np.full(up.n, 0.9)
    up.u_p = np.full(up.n, -0.4)
    Z = _points(system, seed=1)
    Z[:, up.sl(0)] = 0.6       # the dc link sagged (conventional structure)
    _check(system, Z)
    # the branches were taken: |Vu| held at the dc link's share of the rating, below |u|
    _, ctx = system.device_residual(0.0, Z)
    assert np.all(ctx.out["UPQC.Vu"] < np.hypot(0.9, 0.4) - 1e-3)


@pytest.mark.parametrize("structure, upqc", [
    ("conventional", dict(Imax=0.05, Rsh=0.01, chi=0.02)),   # the shunt converter's current limit
    ("reduced", dict(chi=0.02)),                              # the GTI's dc link feeds the series
])
def test_the_gti_in_pq_mode_and_both_upqc_structures_evaluate_on_the_strict_namespace(structure, upqc):
    """GTI + UPQC + SG (GENROU, SEXS, HYGOV, IEEEST): the GTI's PQ control (its PID blocks),
    the UPQC's loss factor, current limit and reduced structure."""
    from sim_cases import build_gti_upqc_sg

    system = build_gti_upqc_sg(structure=structure, mode="pq", upqc=upqc)
    _check(system, _points(system, seed=2))


def test_shared_buses_psse_shafts_and_the_stabilizers_filters_evaluate_on_the_strict_namespace():
    """Two machines on each of two buses (the currents added at repeated indices), PSS/E's
    shaft on two of them, and IEEEST stabilizers with both filters, the voltage cut and two
    input modes (numpy.select's per-instance path)."""
    from test_shared_bus import _shared_case

    system = _shared_case("GENROU")
    gr = system.components["GENROU"]
    for k in range(4):
        system.add_exciter("SEXS", f"E{k}", machine=f"G{k}", TATB=0.1, TB=10.0, K=100.0, TE=0.1,
                           EMIN=-5.0, EMAX=5.0)
        system.add_pss("IEEEST", f"P{k}", machine=f"G{k}", MODE=(1, 3)[k % 2], A1=0.1, A2=0.01,
                       A3=0.2, A4=0.02, A5=0.05, A6=0.01, T1=0.15, T2=0.05, T3=0.15, T4=0.05,
                       T5=2.0, T6=2.0, KS=5.0, LSMAX=0.1, LSMIN=-0.1, VCU=1.5, VCL=0.5)
    for v in gr._values[:2]:
        v["psse_shaft"] = 1.0
    system.setup()
    assert not gr._uniq and gr._psse_shaft is not None
    assert system.components["IEEEST"]._mode is None
    _check(system, _points(system, seed=4))


def test_a_grid_with_a_model_written_for_numpy_only_is_refused_by_name():
    from weakgrid.sim.system import System

    system = _system("case1-weak-grid")
    assert isinstance(system, System)
    type(system.components["TGOV1"]).array_api = False
    try:
        with pytest.raises(DataError, match="TGOV1"):
            on_namespace(system, xps)
    finally:
        type(system.components["TGOV1"]).array_api = True


@pytest.mark.parametrize("unique", [True, False])
def test_the_index_helpers_equal_numpys_indexing(unique):
    rng = np.random.default_rng(3)
    idx = np.array([4, 1, 3]) if unique else np.array([2, 0, 2, 5, 2, 0])
    a = rng.normal(size=(3, 6))
    v = rng.normal(size=(3, len(idx)))
    want = a.copy()
    np.add.at(want, (Ellipsis, idx), v)
    got = xps.asarray(a.copy())
    add_at(xps, got, xps.asarray(idx), xps.asarray(v), unique)
    _same(want, got, "add_at")
    _same(a[..., idx], take(xps, xps.asarray(a), xps.asarray(idx)), "take")
    if unique:
        want = a.copy()
        want[..., idx] = v
        got = xps.asarray(a.copy())
        put(xps, got, xps.asarray(idx), xps.asarray(v))
        _same(want, got, "put")
