"""Cost and accuracy of the grid dynamic programming (``weakgrid verify``'s ground truth).

``case1-paper`` with and without the input bound ‖u‖ ≤ 0.15 pu (the UPQC rating), on
41², 61² (the default) and 81² grids, cubic residual: the median wall time of
:func:`weakgrid.game.dynamic_programming.solve_game_dp` over the repeats, its policy
iterations, and its self-consistency ``max |cost(u_dp, w_dp) − V(x₀)| / V(x₀)`` from the 8
half-Ω starts (``dp_consistency`` of ``weakgrid verify``, 4000 steps).

Run:  python benchmarks/bench_dp.py [--repeat N] [--points 41 61 81]
"""

from __future__ import annotations

import argparse
import statistics
import time

import numpy as np

from weakgrid.game.dynamic_programming import DPSettings, solve_game_dp
from weakgrid.game.optimality import default_starts
from weakgrid.game.rollout import rollout
from weakgrid.models import load_preset


def consistency(problem, dp, steps=4000):
    """``max |cost(u_dp, w_dp) − V(x₀)| / V(x₀)`` from the half-Ω starts."""
    c = problem.cost
    starts = default_starts(problem.mesh.lower, problem.mesh.upper, 0.5)
    r = rollout(problem.system, dp.control, starts, steps, Q=c.Q, R=c.R,
                disturbance=dp.disturbance, P=c.P, gamma=c.gamma,
                penalty=c.control_penalty if c.bound is not None else None)
    V0 = dp.value(starts)
    return float(np.max(np.abs(r.cost - V0) / V0))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--points", type=int, nargs="+", default=[41, 61, 81])
    args = ap.parse_args(argv)
    base = load_preset("case1-paper")
    print(f"{'problem':24s} {'grid':>6s} {'median s':>9s} {'iters':>6s} {'self-consistency':>17s}")
    for label, prob in (("case1-paper", base),
                        ("case1-paper, u_bound 0.15", base.with_input_bound(0.15))):
        for n in args.points:
            times, dp = [], None
            for _ in range(args.repeat):
                t = time.perf_counter()
                dp = solve_game_dp(prob.system, prob.cost, prob.mesh.lower, prob.mesh.upper,
                                   DPSettings(n_points=(n, n)))
                times.append(time.perf_counter() - t)
            print(f"{label:24s} {n:4d}^2 {statistics.median(times):9.2f} "
                  f"{len(dp.history):6d} {100 * consistency(prob, dp):16.3f}%", flush=True)


if __name__ == "__main__":
    main()
