"""The point form of InputBound.minimize (one point on Python floats, m ≤ 2) writes its sums out
for m = 1 and m = 2 (issue #21: the bounded law's samples); it must give the floats of the same
iteration written with Python's ``sum`` over the components — the reference below, the form it
replaced — bit for bit, whatever the shape of the bound, the data or their degeneracies."""

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import weakgrid.game.input_bound as ib
from weakgrid.game.input_bound import InputBound


# ----------------------------------------------------------------- the reference: sums as written
def _squash(bd, v):
    if bd.shape == "box":
        return [L * math.tanh(x / L) for x, L in zip(v, bd._lim)]
    ub = bd._lim[0]
    t = math.sqrt(sum(x * x for x in v)) / ub
    fac = 1.0 - t * t / 3.0 if t < 1e-8 else math.tanh(t) / t
    u = [x * fac for x in v]
    over = math.sqrt(sum(x * x for x in u)) / ub
    if over > 1.0:
        u = [x / over * (1.0 - 2.0 ** -52) for x in u]
    return u


def _squash_jacobian(bd, v):
    m = len(v)
    if bd.shape == "box":
        return [[(1.0 / math.cosh(min(abs(v[i] / bd._lim[i]), 350.0)) ** 2) if i == j else 0.0
                 for j in range(m)] for i in range(m)]
    L = bd._lim[0]
    fac, c = ib._pt_disk_jacobian_coeffs(math.sqrt(sum(x * x for x in v)) / L)
    return [[(fac if i == j else 0.0) + c * v[i] * v[j] / (L * L) for j in range(m)]
            for i in range(m)]


def _penalty_of_v(bd, v, twoR):
    val = ib._pt_penalty_val      # the scalar formulas are shared; the sums are the subject
    if bd.shape == "box":
        return sum(0.5 * r2 * val(abs(x) / L, L * L) for x, L, r2 in zip(v, bd._lim, twoR))
    L = bd._lim[0]
    return 0.5 * twoR[0] * val(math.sqrt(sum(x * x for x in v)) / L, L * L)


def _mv(M, x):
    return [sum(Mi[j] * x[j] for j in range(len(x))) for Mi in M]


_solve = ib._pt_solve      # no sums in it


def _reference(bd, M, b, twoR, max_iter):
    m = len(b)
    L = max(bd._lim)
    scale = (max(abs(x) for x in b) + max(abs(x) for row in M for x in row) * L + max(twoR) * L)

    def F(v):
        u = _squash(bd, v)
        Mu = _mv(M, u)
        return (0.5 * sum(ui * mi for ui, mi in zip(u, Mu)) + sum(bi * ui for bi, ui in zip(b, u))
                + _penalty_of_v(bd, v, twoR))

    def G(v):
        Ms = _mv(M, _squash(bd, v))
        return [r2 * vi + bi + mi for r2, vi, bi, mi in zip(twoR, v, b, Ms)]

    A = [[M[i][j] + (twoR[i] if i == j else 0.0) for j in range(m)] for i in range(m)]
    v = _solve(A, [-x for x in b])
    it, active, f_v = 0, True, None
    for it in range(1, max_iter + 1):
        if not active:
            break
        g = G(v)
        Sj = _squash_jacobian(bd, v)
        MS = [[sum(M[i][k] * Sj[k][j] for k in range(m)) + (twoR[i] if i == j else 0.0)
               for j in range(m)] for i in range(m)]
        d = [-x for x in _solve(MS, g)]

        def slope_of(d):
            return sum(gi * si for gi, si in zip(g, _mv(Sj, d)))

        slope = slope_of(d) if all(math.isfinite(x) for x in d) else math.nan
        if not all(math.isfinite(x) for x in d) or not slope < 0:
            d = [-gi / r2 for gi, r2 in zip(g, twoR)]
            slope = slope_of(d)
        alpha = 1.0
        f0 = F(v) if f_v is None else f_v
        tol_f = 1e-15 * (abs(f0) + 1.0)
        f_v = None
        for _ in range(60):
            vn = [vi + alpha * di for vi, di in zip(v, d)]
            fn = F(vn)
            if not fn > f0 + 1e-4 * alpha * min(slope, 0.0) + tol_f:
                f_v = fn
                break
            alpha = 0.5 * alpha
        vn = [vi + alpha * di for vi, di in zip(v, d)]
        dv = max(abs(a - c) for a, c in zip(vn, v))
        v = vn
        if (max(abs(x) for x in g) <= 1e-14 * scale
                or dv <= 1e-15 * (max(abs(x) for x in vn) + L)):
            active = False
    Ms = _mv(M, _squash(bd, v))
    u = _squash(bd, [-(bi + mi) / r2 for bi, mi, r2 in zip(b, Ms, twoR)])
    res = max(abs(x) for x in G(v)) / scale
    return u, {"iterations": it, "n_unconverged": int(active), "max_residual": float(res)}


# ------------------------------------------------------------------------------------ the checks
def _bits(x):
    """The float's bits (a NaN as NaN: its sign and payload carry no meaning)."""
    return "nan" if math.isnan(x) else np.float64(x).tobytes()


def _same(a, b):
    (ua, ia), (ub, ib_) = a, b
    assert [_bits(x) for x in ua] == [_bits(x) for x in ub]
    assert ia.keys() == ib_.keys()
    for k in ia:
        assert _bits(ia[k]) == _bits(ib_[k]), k


def _problem(m, shape, seed, degenerate):
    rng = np.random.default_rng(seed)
    lim = rng.uniform(0.01, 3.0, m if shape == "box" else 1)
    bd = InputBound.for_inputs(m, lim, shape)
    A = rng.normal(size=(m, m)) * 10.0 ** rng.uniform(-3, 3)
    M = 0.5 * (A + A.T)
    r = rng.uniform(0.05, 5.0)
    ev = np.linalg.eigvalsh(M + 2 * r * np.eye(m)).min()
    M = M + max(0.0, 0.01 - ev) * np.eye(m)
    b = rng.normal(size=m) * 10.0 ** rng.uniform(-6, 4)
    if degenerate == "zero":
        b[:] = 0.0
    elif degenerate == "signed-zero":
        b[0], M[0, 0] = -0.0, -0.0 if m == 2 else M[0, 0]
    elif degenerate == "nan":
        b[0] = math.nan
    return bd, M.tolist(), b.tolist(), [2.0 * r] * m


@settings(max_examples=400, deadline=None)
@given(m=st.sampled_from([1, 2]), shape=st.sampled_from(["disk", "box"]),
       seed=st.integers(0, 2 ** 32 - 1),
       degenerate=st.sampled_from([None, None, None, "zero", "signed-zero", "nan"]))
def test_point_form_gives_the_floats_of_the_sums_as_written(m, shape, seed, degenerate):
    bd, M, b, twoR = _problem(m, shape, seed, degenerate)
    got = ib._minimize_point(bd, M, b, twoR, 100)      # sets bd._lim
    _same(got, _reference(bd, M, b, twoR, 100))
    assert ib._minimize_point(bd, M, b, twoR, 100, return_info=False)[0] == got[0] or degenerate == "nan"


def test_point_form_in_deep_saturation_and_at_the_origin():
    """The regimes the iteration branches on: ‖v‖/ū above 20 (the penalty's ln 2 form) and
    below 1e-8 and 1e-3 (the series), and a Newton direction that is not one of descent (the
    fixed-point step: taken by the box in deep saturation and with M indefinite, checked)."""
    R2 = [1.6, 1.6]
    for shape in ("disk", "box"):
        bd = InputBound.for_inputs(2, 0.15, shape)
        for M, b in (([[0.0, 0.0], [0.0, 0.0]], [1e3, -2e3]),        # saturated
                     ([[1.0, 0.2], [0.2, 2.0]], [1e-12, 3e-13]),       # at the origin
                     ([[1.0, 0.2], [0.2, 2.0]], [1e-5, -2e-5]),
                     ([[-1.5, 0.9], [0.9, -1.2]], [0.4, -0.3])):       # M indefinite
            got = ib._minimize_point(bd, M, b, R2, 100)
            _same(got, _reference(bd, M, b, R2, 100))
            assert got[1]["n_unconverged"] == 0
