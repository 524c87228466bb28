"""Benchmark of the engines on a GTI scenario (not a test: prints medians, asserts nothing).

The GTI grid of ``tests/sim/test_emt_gti.py`` (a GTI with its dc link, energy control, behind a
reduced UPQC to its reference bus and a line to an infinite bus) with the UPQC's series voltage
stepped to (0.05, 0.05) pu at 0.1 s by a sampled controller (T = 1 ms), 0.8 s simulated: the
phasor engine (1 ms, 0.1 ms) and DPsim DP and EMT (0.1 ms) — the GTI co-simulated in DPsim's
step loop (weakgrid.sim.emt.gti). For each: the median wall time of ``--repeats`` runs (setup
and translation included, runs interleaved) and the dc-link excursion ``max |Vc - 1|``.

Run:  PYTHONPATH=src python benchmarks/bench_emt_gti.py [--repeats 3]
"""

from __future__ import annotations

import argparse
import logging
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "sim"))

from test_emt_gti import _controller, _system  # noqa: E402

from weakgrid.sim.emt import simulate_dpsim  # noqa: E402
from weakgrid.sim.integrate import simulate  # noqa: E402

RUNS = [("phasor", 1e-3), ("phasor", 1e-4), ("dpsim-dp", 1e-4), ("dpsim-emt", 1e-4)]
T_END = 0.8


def one(engine, dt):
    t0 = time.perf_counter()
    if engine == "phasor":
        r = simulate(_system(upqc="reduced"), T_END, dt=dt, controllers=[_controller()])
    else:
        r = simulate_dpsim(_system(upqc="reduced"), T_END, engine=engine, dt=dt,
                           controllers=[_controller()])
    return time.perf_counter() - t0, r


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=3)
    a = ap.parse_args(argv)
    logging.basicConfig(level=logging.WARNING)
    times = {k: [] for k in RUNS}
    dev = {}
    for _ in range(a.repeats):
        for eng, dt in RUNS:
            w, r = one(eng, dt)
            times[(eng, dt)].append(w)
            dev[(eng, dt)] = float(np.max(np.abs(r["PV.Vc"] - 1.0)))
    print(f"GTI + reduced UPQC, series-voltage step, {T_END:g} s, median of {a.repeats} runs")
    print(f"{'engine':<10} {'dt [s]':>8} {'steps':>7} {'median [s]':>11} {'max|Vc-1|':>10}")
    for eng, dt in RUNS:
        print(f"{eng:<10} {dt:>8g} {round(T_END / dt):>7d} "
              f"{statistics.median(times[(eng, dt)]):>11.3f} {dev[(eng, dt)]:>10.5f}")


if __name__ == "__main__":
    main()
