"""Sparse LU: KLU (kvxopt, the extra ``weakgrid[klu]``) against SciPy's SuperLU (the base install).

Not a test: prints a table, asserts nothing.

The scenario of ``bench_scale.py`` (10 s at 1/120 s, a three-phase fault from 1.0 to 1.05 s at
the bus with the most branch ends, a classical machine at every generator) on MATPOWER cases
large enough for the sparse backend; both LU libraries run in this one process, interleaved
(KLU, SuperLU, KLU, ...), so that the machine's load hits both alike. Timed: the integration
only (``Simulator.run``), median of ``--repeat`` runs each; the ratio is SuperLU / KLU of the
medians. The last column is the largest difference of any machine speed between the two runs
[pu] (the same Newton iterations on the same matrices: round-off only).

Run:  PYTHONPATH=src python benchmarks/bench_lu.py [--repeat 3] [--cases case300,case1354pegase]
"""

from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np
from bench_scale import TEMPLATE, TF, H, T_OFF, T_ON, fault_bus, load_case

CASES = ["case300", "case1354pegase", "case2869pegase"]


def run(case, lu):
    """Wall time [s] of one integration of ``case`` with the sparse LU ``lu``, and the speeds."""
    from weakgrid.sim.events import Fault
    from weakgrid.sim.integrate import Simulator
    from weakgrid.sim.templates import classical_system

    mpc = load_case(case)
    s = classical_system(mpc, **TEMPLATE)
    sim = Simulator(s, dt=H, linear_solver="sparse", sparse_lu=lu, max_angle_spread=math.inf,
                    record=[f"{n}.omega" for n in s.machine_names])
    assert sim.linsolver.lu == lu, (sim.linsolver.lu, lu)
    t0 = time.perf_counter()
    res = sim.run(TF, events=[Fault(fault_bus(mpc), T_ON, T_OFF)], on_failure="return")
    wall = time.perf_counter() - t0
    if not res.ok:
        raise SystemExit(f"{case} with {lu}: the run failed ({res.failure})")
    return wall, int(s.N), np.column_stack([res[f"{n}.omega"] for n in s.machine_names])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default=",".join(CASES))
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    try:
        import kvxopt  # noqa: F401
    except ImportError:
        raise SystemExit("KLU needs kvxopt: pip install 'weakgrid[klu]'") from None
    print("| case | DAE variables | KLU median [s] | SuperLU median [s] | SuperLU / KLU "
          "| max speed difference [pu] |\n|---|---|---|---|---|---|")
    for case in args.cases.split(","):
        walls = {"klu": [], "superlu": []}
        omega = {}
        for _ in range(args.repeat):
            for lu in walls:
                w, n, omega[lu] = run(case, lu)
                walls[lu].append(w)
        k, s = statistics.median(walls["klu"]), statistics.median(walls["superlu"])
        dev = float(np.max(np.abs(omega["klu"] - omega["superlu"])))
        print(f"| {case} | {n} | {k:.2f} | {s:.2f} | {s / k:.2f} | {dev:.1e} |", flush=True)


if __name__ == "__main__":
    main()
