"""Export of a controller with an input bound: C (gcc -Werror) equals Python; JSON suffices."""

import json

import numpy as np
import pytest
from scipy.optimize import minimize
from scipy.special import xlogy
from test_export import c_saddle, compile_controller, needs_cc

from weakgrid.game import (
    GameCost,
    GridMesh,
    LinearPolicy,
    LinearSystem,
    dlqr,
    even_monomials,
    solve_hji,
)
from weakgrid.game.controller import controller_from_dict
from weakgrid.game.export_json import describe_controller
from weakgrid.game.input_bound import InputBound


@pytest.fixture(scope="module")
def bounded_presets():
    from weakgrid.models import load_preset

    out = {}
    for shape, ub in (("disk", 0.15), ("box", 0.1)):
        p = load_preset("case1-paper").with_input_bound(ub, shape)
        out[shape] = (p, p.train())
    return out


def bounded_linear():
    """Three states, two inputs, two disturbances: the general (m, q > 1) code paths."""
    rng = np.random.default_rng(7)
    A = rng.normal(size=(3, 3))
    A *= 0.9 / np.max(np.abs(np.linalg.eigvals(A)))
    B = rng.normal(size=(3, 2))
    E = rng.normal(size=(3, 2)) * 0.2
    s = LinearSystem(A, B, E)
    K, _, _ = dlqr(A, B, np.eye(3), np.eye(2))
    cost = GameCost.for_system(s, np.eye(3), np.diag([1.0, 2.0]), np.eye(2), 6.0,
                               bound=[0.3, 0.5], bound_shape="box")
    mesh = GridMesh([-1] * 3, [1] * 3, [0.25] * 3)
    return solve_hji(s, even_monomials(3, 4), cost, mesh, LinearPolicy(K)), mesh


def assert_bounded_matches(ctl, lib, name, X):
    m, q = ctl.system.n_controls, ctl.system.n_disturbances
    U, W, J = c_saddle(lib, name, X, m, q)
    u0, w0 = ctl.saddle_point(X)
    b = ctl.cost.bound
    assert b.ratio(U).max() <= 1.0  # the generated code respects the bound too
    # u relative to the bound; w relative to the largest w of the batch (its terms cancel
    # near the origin, where both are only that accurate)
    assert np.abs(U - u0).max() <= 1e-12 * b.limit.max()
    assert np.abs(W - w0).max() <= 1e-12 * np.abs(w0).max()
    np.testing.assert_allclose(J, ctl.value(X), rtol=1e-12, atol=0)


@needs_cc
@pytest.mark.parametrize("shape", ["disk", "box"])
def test_c_equals_python_bounded_case1(shape, bounded_presets, tmp_path):
    p, ctl = bounded_presets[shape]
    name = f"case1_bounded_{shape}"
    lib = compile_controller(ctl, tmp_path, name)
    X = np.vstack([p.mesh.sample(5000, seed=13), 1.5 * p.mesh.points])  # and beyond Ω
    assert_bounded_matches(ctl, lib, name, X)
    assert f"{name}_bounded_min" in (tmp_path / f"{name}.c").read_text()


@needs_cc
def test_c_equals_python_bounded_linear_box(tmp_path):
    ctl, mesh = bounded_linear()
    assert ctl.bound_activity(mesh.points)["fraction_binding"] > 0.1
    lib = compile_controller(ctl, tmp_path, "linb")
    assert_bounded_matches(ctl, lib, "linb", mesh.sample(3000, seed=14))


def _bounded_from_json(d, X):
    """Independent: reads the description, eliminates w, minimizes over u by L-BFGS-B."""
    E, W = np.array(d["basis"]["exponents"]), np.array(d["weights"])
    c = d["cost"]
    R, P, g = np.array(c["R"]), np.array(c["P"]), c["gamma"]
    shape, lim = c["u_bound"]["shape"], np.array(c["u_bound"]["limit"])
    p = d["model"]["equations"]["parameters"]
    T, a, Vr, p0 = p["T"], p["a"], p["Vr_bar"], p["phi_s0"]
    r_ = np.diag(R)

    def Wpen(u):
        def psi(q):
            return 0.5 * (xlogy(1 + q, 1 + q) + xlogy(1 - q, 1 - q))

        if shape == "box":
            return float(np.sum(2 * r_ * lim**2 * psi(np.abs(u) / lim)))
        return float(2 * r_[0] * lim[0] ** 2 * psi(np.linalg.norm(u) / lim[0]))

    out = []
    for x in X:
        grad, hess = np.zeros(2), np.zeros((2, 2))
        for w, e in zip(W, E):
            for i in range(2):
                if e[i]:
                    ei = e.copy()
                    ei[i] -= 1
                    grad[i] += w * e[i] * np.prod(x ** ei)
                for j in range(2):
                    ee = e.copy()
                    ee[i] -= 1
                    ee[j] -= 1
                    k = e[i] * (e[i] - 1) if i == j else e[i] * e[j]
                    if k and np.all(ee >= 0):
                        hess[i, j] += w * k * np.prod(x ** ee)
        s, co = np.sin(x[0] + p0), np.cos(x[0] + p0)
        f = np.array([x[0] + T * x[1], x[1] + T * a * Vr * (np.sin(p0) - s)])
        G = np.array([[0, 0], [T * a * co, -T * a * s]])
        H = np.array([[0], [-T * a * s]])
        r = grad + hess @ (f - x)
        Yw = H.T @ hess @ H - 2 * g**2 * P
        Xg = np.linalg.solve(Yw, H.T @ hess @ G)
        Xr = np.linalg.solve(Yw, H.T @ r)
        M = G.T @ hess @ G - G.T @ hess @ H @ Xg
        b = G.T @ r - G.T @ hess @ H @ Xr
        def F(u, M=M, b=b):
            return 0.5 * u @ M @ u + b @ u + Wpen(u)

        opts = {"ftol": 1e-15, "gtol": 1e-13, "maxiter": 2000}
        if shape == "box":  # bounded quasi-Newton directly in u
            bnd = [(-v * (1 - 1e-15), v * (1 - 1e-15)) for v in lim]
            u = minimize(F, np.zeros(2), method="L-BFGS-B", options=opts, bounds=bnd).x
            # a component at the bound stops L-BFGS-B's f-test early (the barrier's slope
            # dwarfs the others): polish the free components with that one held
            hold = np.abs(u) > lim * (1 - 1e-6)
            if hold.any() and not hold.all():
                def F1(v, F=F, u=u, hold=hold):
                    return F(np.where(hold, u, v[0]))
                u = np.where(hold, u, minimize(F1, u[~hold], method="L-BFGS-B", options=opts,
                                               bounds=[b for b, h in zip(bnd, hold)
                                                       if not h]).x[0])
        else:  # polar coordinates, radius bounded
            th0 = np.arctan2(-b[1], -b[0])
            def Fp(z, F=F):
                return F(np.array([z[0] * np.cos(z[1]), z[0] * np.sin(z[1])]))

            z = minimize(Fp, [0.5 * lim[0], th0], method="L-BFGS-B",
                         options=opts, bounds=[(0, lim[0] * (1 - 1e-15)), (None, None)]).x
            u = np.array([z[0] * np.cos(z[1]), z[0] * np.sin(z[1])])
        out.append(np.concatenate([u, -(Xr + Xg @ u)]))
    return np.array(out)


@pytest.mark.parametrize("shape", ["disk", "box"])
def test_json_description_suffices_bounded(shape, bounded_presets):
    p, ctl = bounded_presets[shape]
    d = json.loads(json.dumps(describe_controller(ctl, "test")))
    assert "penalty" in d["formula"] and d["cost"]["u_bound"]["shape"] == shape
    X = p.mesh.sample(30, seed=4)
    z = _bounded_from_json(d, X)
    u0, w0 = ctl.saddle_point(X)
    np.testing.assert_allclose(z[:, :2], u0, atol=1e-6 * ctl.cost.bound.limit.max())
    np.testing.assert_allclose(z[:, 2:], w0, atol=1e-6 * np.abs(w0).max())


def test_controller_file_carries_the_bound(bounded_presets, tmp_path):
    from weakgrid.models import load_controller

    p, ctl = bounded_presets["disk"]
    f = ctl.save(tmp_path / "b.controller.json")
    d = json.loads(f.read_text())
    assert d["problem"]["cost"]["u_bound"] == {"shape": "disk", "limit": [0.15]}
    back = load_controller(f)
    assert isinstance(back.cost.bound, InputBound) and back.cost.bound.shape == "disk"
    X = p.mesh.points[::11]
    np.testing.assert_array_equal(back.control(X), ctl.control(X))
    assert controller_from_dict(d).cost.bound.limit.tolist() == [0.15]
