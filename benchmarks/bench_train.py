"""Training time of both presets: weakgrid vs a plain NumPy implementation, same run.

The baseline is the algorithm of (25)–(28) (docs/theory.md) written the obvious way: every iteration
evaluates f, g, h and the basis derivatives at the mesh again, forms the regression
rows with ``einsum`` over the mesh, and solves the least-squares problem with
``numpy.linalg.lstsq`` (SVD, normal-equation-free). Both must give the same weights.

Then the constrained-input problem (beyond the paper): ``case1-paper`` with the UPQC
rating 0.15 pu as a disk bound ‖u‖ ≤ ū (and as a box), timed beside the unconstrained
``case1-paper`` in the same run.

Run:  python benchmarks/bench_train.py [--repeat N]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from weakgrid.models import load_preset


def plain_numpy_train(problem):
    """Two-loop policy iteration, straightforward NumPy (the peer)."""
    sysm, basis, cost, s = problem.system, problem.basis, problem.cost, problem.settings
    X = problem.mesh.points
    R, P, Q, g2 = cost.R, cost.P, cost.Q, cost.gamma**2
    u = problem.initial_policy(X)
    q = sysm.n_disturbances
    for i in range(s.max_outer):
        w = np.zeros((X.shape[0], q))
        for j in range(s.max_inner):
            f = sysm.open_loop_dynamics(X)
            g = sysm.control_directions(X)
            h = sysm.disturbance_directions(X)
            _, dphi, d2phi = basis.evaluate(X)
            dx = f + np.einsum("pnm,pm->pn", g, u) + np.einsum("pnq,pq->pn", h, w) - X
            A = np.einsum("pln,pn->pl", dphi, dx) + 0.5 * np.einsum("pi,plij,pj->pl", dx, d2phi, dx)
            Y = (np.einsum("pi,ij,pj->p", X, Q, X) + np.einsum("pi,ij,pj->p", u, R, u)
                 - g2 * np.einsum("pi,ij,pj->p", w, P, w))
            W = np.linalg.lstsq(A, -Y, rcond=None)[0]
            gJ = np.einsum("pln,l->pn", dphi, W)
            HJ = np.einsum("plij,l->pij", d2phi, W)
            Yw = np.einsum("pnq,pnk,pkr->pqr", h, HJ, h) - 2 * g2 * P
            rhs = np.einsum("pnq,pn->pq", h, gJ + np.einsum("pij,pj->pi", HJ, f + np.einsum(
                "pnm,pm->pn", g, u) - X))
            w_new = -np.linalg.solve(Yw, rhs[..., None])[..., 0]
            dw = np.abs(w_new - w).max()
            w = w_new
            if dw <= s.tol_w:
                break
        Yu = np.einsum("pnm,pnk,pkr->pmr", g, HJ, g) + 2 * R
        rhs = np.einsum("pnm,pn->pm", g, gJ + np.einsum("pij,pj->pi", HJ, f + np.einsum(
            "pnq,pq->pn", h, w) - X))
        u_new = -np.linalg.solve(Yu, rhs[..., None])[..., 0]
        du = np.abs(u_new - u).max()
        u = u_new
        if du <= s.tol_u:
            return W, i + 1
    raise RuntimeError("baseline did not converge")


def median_time(fn, repeat):
    fn()  # warm-up
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        ts.append(time.perf_counter() - t0)
    return statistics.median(ts)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=21)
    args = ap.parse_args()
    print(f"{'preset':14s} {'weakgrid [ms]':>14s} {'plain NumPy [ms]':>17s} {'ratio':>7s} "
          f"{'outer':>6s} {'max |ΔW|':>10s}")
    for name in ("case1-paper", "case2-paper"):
        p = load_preset(name)
        ctl = p.train()
        Wb, outer_b = plain_numpy_train(p)
        dW = np.abs(ctl.weights - Wb).max()
        t_fast = median_time(p.train, args.repeat)
        t_plain = median_time(lambda: plain_numpy_train(p), max(3, args.repeat // 4))
        print(f"{name:14s} {t_fast * 1e3:14.1f} {t_plain * 1e3:17.1f} {t_plain / t_fast:6.1f}× "
              f"{ctl.iterations['outer']:6d} {dW:10.2e}")
        assert outer_b == ctl.iterations["outer"], "baseline and weakgrid iterate differently"

    print(f"\n{'constrained':32s} {'weakgrid [ms]':>14s} {'vs unconstrained':>17s} "
          f"{'outer':>6s} {'binds on Ω':>11s}")
    p = load_preset("case1-paper")
    t_free = median_time(p.train, args.repeat)
    print(f"{'case1-paper (no bound)':32s} {t_free * 1e3:14.1f} {1.0:16.2f}× "
          f"{p.train().iterations['outer']:6d} {'':>11s}")
    for shape in ("disk", "box"):
        pb = p.with_input_bound(0.15, shape)
        ctl = pb.train()
        t_b = median_time(pb.train, args.repeat)
        act = ctl.bound_activity(pb.mesh.points)["fraction_binding"]
        label = f"case1-paper {ctl.cost.bound.describe()}"
        print(f"{label:32s} {t_b * 1e3:14.1f} {t_b / t_free:16.2f}× "
              f"{ctl.iterations['outer']:6d} {100 * act:10.1f} %")


if __name__ == "__main__":
    main()
