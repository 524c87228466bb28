"""How well a sweep's estimate predicts its cost (not a test: prints numbers, asserts nothing).

Before a sweep, ``weakgrid sweep`` prints and checks an estimate of its CPU time
(:func:`weakgrid.study.sweep_estimate.estimate_sweep`, from a timed probe of the study's grid).
This file calls that estimate ``--repeat`` times in one process (its spread: the probe's
timings are milliseconds long, as long as this machine's jitter), then runs the same sweep
serially in this process (``workers = 0``, batched as the command does, a fresh cache) and
prints the estimated against the measured CPU time (``time.process_time``) and their ratio.

Measured 2026-12-03 on the idle 2-core machine, from the source tree:

* the code before the probe's untimed first steps and repeated timings: case 2's sweep (96
  runs, 129 s serially) estimated at anywhere from 5 CPU-min to 7.1 CPU-h between calls (and
  refused, beyond 30 min): a process's first call of a compiled kernel (0.5–1 s,
  :mod:`weakgrid.sim.kernels`) fell in the timed quiet steps, and the transient, timed from
  0 s through 3 000 quiet steps, was the difference of two long timings;
* after, this file: case 2's sweep (``case2-lv-microgrid --full``) 79.9–83.0 CPU-s estimated
  (3 calls; the first, which also builds the grid and loads the kernels, 4.7 s, the others
  1.4 s), 143.0 CPU-s measured (1.72–1.79×); case 1's quick sweep (the default) 6.4–6.9 CPU-s
  estimated, 8.1 CPU-s measured (1.18–1.27×). Case 1's full sweep on 2 workers (``weakgrid
  sweep case1-weak-grid``): 49–61 CPU-s estimated (3 calls), 89 CPU-s measured. Low, by up to 2×: the
  probe's controller holds zero, so a trained policy's evaluation and the network's re-solve
  after each of its samples are not in it.

Run:  PYTHONPATH=src python benchmarks/bench_estimate.py [STUDY] [--full] [--repeat N]
      (default: case1-weak-grid, its quick sweep, 3 estimates)
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time


def main(study="case1-weak-grid", quick=True, repeat=3):
    from weakgrid.study.studyfile import load_study
    from weakgrid.study.sweep import run_study_sweep
    from weakgrid.study.sweep_estimate import estimate_sweep

    st = load_study(study)
    print(f"{study}{' --quick' if quick else ''}, load {os.getloadavg()[0]:.2f}")
    with tempfile.TemporaryDirectory() as tmp:
        cpu = []
        for k in range(repeat):
            t0 = time.perf_counter()
            est = estimate_sweep(st, os.path.join(tmp, "cache"), quick=quick, workers=0)
            cpu.append(est.cpu_s)
            print(f"  estimate {k + 1}: {est.cpu_s:8.1f} CPU-s (the probe and the estimate took "
                  f"{time.perf_counter() - t0:.2f} s)  {est.line()}")
        c0, t0 = time.process_time(), time.perf_counter()
        run_study_sweep(st, os.path.join(tmp, "out"), quick=quick, workers=0, progress=False)
        used, wall = time.process_time() - c0, time.perf_counter() - t0
    print(f"  the sweep serially: {used:.1f} CPU-s, {wall:.1f} s; measured / estimated: "
          + ", ".join(f"{used / c:.2f}" for c in cpu)
          + f"; estimates from {min(cpu):.1f} to {max(cpu):.1f} CPU-s, "
          f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("study", nargs="?", default="case1-weak-grid")
    ap.add_argument("--full", action="store_true", help="the sweep's full axes (default: "
                    "its quick ones)")
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    main(a.study, quick=not a.full, repeat=a.repeat)
