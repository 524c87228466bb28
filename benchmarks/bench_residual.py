"""The cost of one batched residual evaluation (not a test: prints medians, asserts nothing).

:meth:`weakgrid.sim.batch.BatchSimulator.residual` of ``B`` members of the GTI + UPQC + SG grid
(both UPQC structures) at their initial points, ``B`` = 6 (a batch of the case-1 quick sweep)
and 50: CPU time (``time.process_time``, what a shared machine's load inflates least) per call,
median of 5 rounds of 1000 calls after 200 warm-up calls, and each device's share (its
``compute`` and ``finish``, timed in a separate pass). A small grid's residual costs the
number of NumPy calls of its devices, nearly independent of ``B``; compare two versions of the
code by running this file with each on ``PYTHONPATH``, back to back.

Beside each grid's batches, the same grid's residual for one point as a run alone evaluates it
(``alone``: ``System.residual`` on the ``(N,)`` vector), per call and by device: what the batch
axis adds to each NumPy operation.

The device kernels (:mod:`weakgrid.sim.kernels`) are timed both ways in the same run, rounds
alternated: on NumPy (``WEAKGRID_KERNELS=numpy``) and compiled (numba, when installed).

Run:  PYTHONPATH=src python benchmarks/bench_residual.py
"""

from __future__ import annotations

import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "sim"))
sys.path.insert(0, str(ROOT / "benchmarks"))


def _device_times(bs, Z, rows, calls):
    """CPU µs per residual call in each device's ``compute`` + ``finish``."""
    spent: dict = {}
    saved = []
    for c in bs.tmpl.comps:
        for meth in ("compute", "finish"):
            f = getattr(c, meth)
            saved.append((c, meth))

            def timed(ctx, f=f, name=type(c).__name__):
                t0 = time.process_time()
                f(ctx)
                spent[name] = spent.get(name, 0.0) + time.process_time() - t0
            setattr(c, meth, timed)
    for _ in range(calls):
        bs.residual(0.0, Z, rows)
    for c, meth in saved:
        delattr(c, meth)          # the class's method again
    return {k: 1e6 * v / calls for k, v in sorted(spent.items(), key=lambda kv: -kv[1])}


class _Alone:
    """A one-point system in the shape :func:`_device_times` times (``tmpl``, ``residual``)."""

    def __init__(self, system, z):
        self.tmpl, self._z = system, z

    def residual(self, t, Z, rows):
        return self.tmpl.residual(t, self._z)


def alone(grid, modes, rounds, calls):
    """The same grid's residual for one point, as a run alone evaluates it
    (:meth:`weakgrid.sim.system.System.residual` on the ``(N,)`` vector): the reference of the
    batched residual's cost, per call and by device."""
    from sim_cases import build_gti_upqc_sg

    from weakgrid.sim.integrate import Simulator

    system = build_gti_upqc_sg(grid)
    z = Simulator(system, dt=5e-3, tol=1e-6).z.copy()
    per = {m: [] for m in modes}
    for m in modes:
        os.environ["WEAKGRID_KERNELS"] = m
        for _ in range(200):
            system.residual(0.0, z)
    for _ in range(rounds):
        for m in modes:
            os.environ["WEAKGRID_KERNELS"] = m
            c0 = time.process_time()
            for _ in range(calls):
                system.residual(0.0, z)
            per[m].append((time.process_time() - c0) / calls)
    print(f"{grid:12s} alone: residual µs CPU per call "
          + ", ".join(f"{m} {1e6 * statistics.median(v):.0f}" for m, v in per.items()))
    for m in modes:
        os.environ["WEAKGRID_KERNELS"] = m
        dev = _device_times(_Alone(system, z), None, None, calls)
        print(f"    {m:5s} by device [µs]: " + ", ".join(f"{k} {v:.0f}" for k, v in dev.items()))


def main(sizes=(6, 50), rounds=5, calls=1000):
    from bench_sim import _fault_scenarios
    from sim_cases import build_gti_upqc_sg

    from weakgrid.sim import kernels
    from weakgrid.sim.batch import BatchSimulator

    modes = ["numpy"] + (["numba"] if kernels.compiled_available() else [])
    for grid in ("conventional", "reduced"):
        alone(grid, modes, rounds, calls)
        for B in sizes:
            sc = [s for g, s in _fault_scenarios(2 * B) if g == grid][:B]
            bs = BatchSimulator(build_gti_upqc_sg(grid), sc, dt=5e-3, tol=1e-6)
            rows = list(range(B))
            bs._sync_network(rows)
            Z = np.stack([s.z for s in bs.sims])
            per = {m: [] for m in modes}
            for m in modes:
                os.environ["WEAKGRID_KERNELS"] = m
                for _ in range(200):
                    bs.residual(0.0, Z, rows)
            for _ in range(rounds):
                for m in modes:
                    os.environ["WEAKGRID_KERNELS"] = m
                    c0 = time.process_time()
                    for _ in range(calls):
                        bs.residual(0.0, Z, rows)
                    per[m].append((time.process_time() - c0) / calls)
            med = {m: 1e6 * statistics.median(v) for m, v in per.items()}
            line = ", ".join(f"{m} {med[m]:.0f}" for m in modes)
            ratio = f" ({med['numpy'] / med['numba']:.2f}x)" if "numba" in med else ""
            print(f"{grid:12s} B = {B:3d}: residual µs CPU per call {line}{ratio} "
                  f"(median of {rounds} x {calls}, alternated)")
            for m in modes:
                os.environ["WEAKGRID_KERNELS"] = m
                dev = _device_times(bs, Z, rows, calls)
                print(f"    {m:5s} by device [µs]: " + ", ".join(f"{k} {v:.0f}" for k, v in dev.items()))
    os.environ.pop("WEAKGRID_KERNELS", None)


if __name__ == "__main__":
    main()
