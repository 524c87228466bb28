"""The cost of one batched residual evaluation (not a test: prints medians, asserts nothing).

:meth:`weakgrid.sim.batch.BatchSimulator.residual` of ``B`` members of the GTI + UPQC + SG grid
(both UPQC structures) at their initial points, ``B`` = 6 (a batch of the case-1 quick sweep)
and 50: CPU time (``time.process_time``, what a shared machine's load inflates least) per call,
median of 5 rounds of 1000 calls after 200 warm-up calls. A small grid's residual costs the
number of NumPy calls of its devices, nearly independent of ``B``; compare two versions of the
code by running this file with each on ``PYTHONPATH``, back to back.

Run:  PYTHONPATH=src python benchmarks/bench_residual.py
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "sim"))
sys.path.insert(0, str(ROOT / "benchmarks"))


def main(sizes=(6, 50), rounds=5, calls=1000):
    from bench_sim import _fault_scenarios
    from sim_cases import build_gti_upqc_sg

    from weakgrid.sim.batch import BatchSimulator

    for grid in ("conventional", "reduced"):
        for B in sizes:
            sc = [s for g, s in _fault_scenarios(2 * B) if g == grid][:B]
            bs = BatchSimulator(build_gti_upqc_sg(grid), sc, dt=5e-3, tol=1e-6)
            rows = list(range(B))
            bs._sync_network(rows)
            Z = np.stack([s.z for s in bs.sims])
            for _ in range(200):
                bs.residual(0.0, Z, rows)
            per = []
            for _ in range(rounds):
                c0 = time.process_time()
                for _ in range(calls):
                    bs.residual(0.0, Z, rows)
                per.append((time.process_time() - c0) / calls)
            print(f"{grid:12s} B = {B:3d}: residual {1e6 * statistics.median(per):.0f} µs CPU per call "
                  f"(median of {rounds} x {calls})")


if __name__ == "__main__":
    main()
