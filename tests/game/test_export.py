"""Export: the generated C equals the Python saddle point; the JSON suffices to rebuild it."""

import ctypes
import json
import shutil
import subprocess

import numpy as np
import pytest

from weakgrid.cli.main import main
from weakgrid.game import (
    FunctionSystem, GameController, GameCost, GridMesh, LinearPolicy, LinearSystem,
    ParameterError, SolverSettings, dlqr, even_monomials, solve_hji,
)
from weakgrid.game.export_c import generate_c
from weakgrid.game.export_json import describe_controller

CC = shutil.which("gcc") or shutil.which("cc")
needs_cc = pytest.mark.skipif(CC is None, reason="no C compiler on this system")
DP = ctypes.POINTER(ctypes.c_double)


def compile_controller(ctl, tmp_path, name):
    src, hdr = generate_c(ctl, name, "test")
    (tmp_path / f"{name}.c").write_text(src)
    (tmp_path / f"{name}.h").write_text(hdr)
    lib = tmp_path / f"lib{name}.so"
    r = subprocess.run([CC, "-std=c99", "-O2", "-Wall", "-Wextra", "-pedantic", "-Werror",
                        "-fPIC", "-shared", "-o", str(lib), str(tmp_path / f"{name}.c"), "-lm"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return ctypes.CDLL(str(lib))


def c_saddle(lib, name, X, m, q):
    fn = getattr(lib, f"{name}_saddle")
    fv = getattr(lib, f"{name}_value")
    fv.restype = ctypes.c_double
    U, W, J = np.zeros((len(X), m)), np.zeros((len(X), q)), np.zeros(len(X))
    u, w = np.zeros(m), np.zeros(q)
    for i, x in enumerate(np.ascontiguousarray(X)):
        xp = x.ctypes.data_as(DP)
        assert fn(xp, u.ctypes.data_as(DP), w.ctypes.data_as(DP)) == 0
        U[i], W[i], J[i] = u, w, fv(xp)
    return U, W, J


def cancellation_free_magnitude(ctl, X):
    """|M⁻¹|·|B'|·(Σ_l |W_l ∇σ_l| + |∇²J|·|f − x|): the size of (u*, w*) if nothing cancelled.

    At states where the terms of ∇J + ∇²J(f − x) cancel, any two correct double-precision
    evaluations (Python's and C's) differ by ~1e-16 of this, not of |(u*, w*)|.
    """
    _, dphi, _ = ctl.basis.evaluate(X)
    gabs = np.einsum("pln,l->pn", np.abs(dphi), np.abs(ctl.weights))
    HJ = ctl.hessian(X)
    d = ctl.system.open_loop_dynamics(X) - X
    B = np.concatenate([ctl.system.control_directions(X),
                        ctl.system.disturbance_directions(X)], axis=-1)
    m = ctl.system.n_controls
    M = np.einsum("pni,pnk,pkj->pij", B, HJ, B)
    M[:, :m, :m] += 2 * ctl.cost.R
    M[:, m:, m:] -= 2 * ctl.cost.gamma**2 * ctl.cost.P
    rabs = np.einsum("pni,pn->pi", np.abs(B),
                     gabs + np.einsum("pij,pj->pi", np.abs(HJ), np.abs(d)))
    return np.einsum("pij,pj->pi", np.abs(np.linalg.inv(M)), rabs).max(1)


def assert_matches(ctl, lib, name, X):
    U, W, J = c_saddle(lib, name, X, ctl.system.n_controls, ctl.system.n_disturbances)
    u0, w0 = ctl.saddle_point(X)
    z, z0 = np.hstack([U, W]), np.hstack([u0, w0])
    err = np.abs(z - z0).max(1)
    rel = err / np.abs(z0).max(1)
    # 1e-12 relative at (nearly) every state; everywhere relative to the cancellation-free
    # magnitude (at the few states where the right-hand side cancels to 1e-5 of its terms,
    # Python and C are both only that accurate: checked against 40-digit arithmetic)
    assert np.mean(rel <= 1e-12) >= 0.999, np.sort(rel)[-20:]
    scale = np.maximum(np.abs(z0).max(1), cancellation_free_magnitude(ctl, X))
    assert (err / scale).max() <= 1e-12, (err / scale).max()
    np.testing.assert_allclose(J, ctl.value(X), rtol=1e-12, atol=0)


def linear_controller():
    rng = np.random.default_rng(5)
    A = rng.normal(size=(3, 3))
    A[0, 2] = 0.0  # a structural zero in A, and a zero row of B: emitted code skips them
    A *= 0.9 / np.max(np.abs(np.linalg.eigvals(A)))
    B = rng.normal(size=(3, 2))
    B[1] = 0.0
    E = rng.normal(size=(3, 1)) * 0.3
    sysm = LinearSystem(A, B, E)
    Q, R, P = np.eye(3), np.eye(2), np.eye(1)
    K, _, _ = dlqr(A, B, Q, R)
    cost = GameCost.for_system(sysm, Q, R, P, 5.0)
    mesh = GridMesh([-1] * 3, [1] * 3, [0.5] * 3)
    return solve_hji(sysm, even_monomials(3, 4), cost, mesh, LinearPolicy(K),
                     SolverSettings(tol_u=1e-10, tol_w=1e-10)), mesh


@needs_cc
@pytest.mark.parametrize("preset", ["case1-paper", "case2-paper"])
def test_c_equals_python_on_presets(preset, trained_presets, tmp_path):
    problem, ctl = trained_presets[preset]
    name = preset.replace("-", "_")
    lib = compile_controller(ctl, tmp_path, name)
    assert_matches(ctl, lib, name, problem.mesh.sample(10_000, seed=11))


@needs_cc
def test_c_equals_python_on_a_linear_system(tmp_path):
    ctl, mesh = linear_controller()
    lib = compile_controller(ctl, tmp_path, "lin")
    assert_matches(ctl, lib, "lin", mesh.sample(10_000, seed=12))


def _rebuild_from_json(d, X):
    """An independent NumPy implementation that reads only the exported description."""
    E = np.array(d["basis"]["exponents"])
    W = np.array(d["weights"])
    c = d["cost"]
    R, P, g = np.array(c["R"]), np.array(c["P"]), c["gamma"]
    n = E.shape[1]
    out = []
    for x in X:
        grad, hess = np.zeros(n), np.zeros((n, n))
        for w, e in zip(W, E):
            for i in range(n):
                if e[i]:
                    ei = e.copy()
                    ei[i] -= 1
                    grad[i] += w * e[i] * np.prod(x ** ei)
                for j in range(n):
                    ee = e.copy()
                    ee[i] -= 1
                    ee[j] -= 1
                    k = e[i] * (e[i] - 1) if i == j else e[i] * e[j]
                    if k and np.all(ee >= 0):
                        hess[i, j] += w * k * np.prod(x ** ee)
        rec = d["model"]["record"]
        if d["model"]["kind"] == "linear":
            A, Bm, Em = (np.array(rec[k]) for k in ("A", "B", "E"))
            f, G, H = A @ x, Bm, Em
        else:
            p = d["model"]["equations"]["parameters"]
            T, a, Vr, p0 = p["T"], p["a"], p["Vr_bar"], p["phi_s0"]
            s, co = np.sin(x[0] + p0), np.cos(x[0] + p0)
            f = np.array([x[0] + T * x[1], x[1] + T * a * Vr * (np.sin(p0) - s)])
            G = np.array([[0, 0], [T * a * co, -T * a * s]])
            H = np.array([[0], [-T * a * s]])
        Bt = np.hstack([G, H])
        m = G.shape[1]
        M = Bt.T @ hess @ Bt
        M[:m, :m] += 2 * R
        M[m:, m:] -= 2 * g**2 * P
        out.append(-np.linalg.solve(M, Bt.T @ (grad + hess @ (f - x))))
    return np.array(out)


def test_json_description_suffices(trained_presets, tmp_path):
    _, ctl = trained_presets["case1-paper"]
    lin, mesh = linear_controller()
    for c, X in ((ctl, trained_presets["case1-paper"][0].mesh.sample(50, seed=1)),
                 (lin, mesh.sample(50, seed=2))):
        d = json.loads(json.dumps(describe_controller(c, "test")))
        z = _rebuild_from_json(d, X)
        u0, w0 = c.saddle_point(X)
        np.testing.assert_allclose(z, np.hstack([u0, w0]), rtol=1e-9, atol=1e-12)
        assert "saddle_point" in d["formula"]


def test_other_model_kinds_are_refused():
    lin, _ = linear_controller()
    s = lin.system
    fs = FunctionSystem(s.open_loop_dynamics, s.control_directions, s.disturbance_directions,
                        3, 2, 1)
    ctl = GameController(fs, lin.basis, lin.weights, lin.cost)
    with pytest.raises(ParameterError, match="model.kind.*export supports"):
        generate_c(ctl, "x")
    with pytest.raises(ParameterError, match="name"):
        generate_c(lin, "1bad-name")


def test_export_cli_writes_files(trained_presets, tmp_path, capsys):
    _, ctl = trained_presets["case2-paper"]
    f = tmp_path / "case2-paper.controller.json"
    ctl.save(f)
    assert main(["export", str(f), "--format", "c-law"]) == 0
    assert (tmp_path / "case2_paper.c").exists() and (tmp_path / "case2_paper.h").exists()
    assert "case2_paper_saddle" in (tmp_path / "case2_paper.h").read_text()
    assert main(["export", str(f), "--format", "json", "-d", str(tmp_path / "o")]) == 0
    d = json.loads((tmp_path / "o" / "case2_paper.export.json").read_text())
    assert d["model"]["kind"] == "upqc-design" and d["weights"] == ctl.weights.tolist()
    assert main(["export", str(tmp_path / "missing.json")]) == 2
    assert "does not exist" in capsys.readouterr().err
