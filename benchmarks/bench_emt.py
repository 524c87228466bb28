"""Benchmark of the engines on one scenario (not a test: prints medians, asserts nothing).

The SMIB of ``tests/sim/test_emt_dpsim.py`` (GENCLS, M = 6 s, xd1 = 0.25 pu, line 0.01 + j0.3 pu
to an infinite bus, 0.8 pu; bolted three-phase fault at the machine bus 0.1-0.2 s), 1 s simulated,
run by each engine at its own step(s): weakgrid's phasor engine (trapezoid, 1 ms and 0.1 ms),
DPsim DP (1 ms, 0.1 ms) and DPsim EMT (0.1 ms, 50 µs). For each: the median wall time of
``--repeats`` runs (setup and translation included; every engine's runs interleaved), the steps,
and the speed excursion ``max(omega) - 1`` (its relative difference to the phasor engine at 0.1 ms).
``--machine genrou``: the same SMIB with case 1's GENROU, EXDC2, TGOV1 and IEEEST
(``tests/sim/test_emt_machines.py``; in DPsim the controls run in Python at every step).

Run:  PYTHONPATH=src python benchmarks/bench_emt.py [--repeats 5] [--t-end 1.0] [--machine genrou]
"""

from __future__ import annotations

import argparse
import logging
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "sim"))

from sim_cases import classical_smib, machine_smib  # noqa: E402

from weakgrid.sim.emt import simulate_dpsim  # noqa: E402
from weakgrid.sim.events import Fault  # noqa: E402
from weakgrid.sim.integrate import simulate  # noqa: E402

EVENTS = [Fault(bus=1, t_on=0.1, t_off=0.2)]
RUNS = [("phasor", 1e-3), ("phasor", 1e-4), ("dpsim-dp", 1e-3), ("dpsim-dp", 1e-4),
        ("dpsim-emt", 1e-4), ("dpsim-emt", 5e-5)]


SMIBS = {"gencls": classical_smib, "genrou": machine_smib}


def one(engine, dt, t_end, smib=classical_smib):
    t0 = time.perf_counter()
    if engine == "phasor":
        r = simulate(smib(), t_end, dt=dt, events=EVENTS)
    else:
        r = simulate_dpsim(smib(), t_end, engine=engine, dt=dt, events=EVENTS)
    return time.perf_counter() - t0, r


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--t-end", type=float, default=1.0)
    ap.add_argument("--machine", choices=sorted(SMIBS), default="gencls")
    a = ap.parse_args(argv)
    logging.basicConfig(level=logging.WARNING)
    times = {k: [] for k in RUNS}
    peak = {}
    for _ in range(a.repeats):
        for eng, dt in RUNS:
            w, r = one(eng, dt, a.t_end, SMIBS[a.machine])
            times[(eng, dt)].append(w)
            peak[(eng, dt)] = float(r["G1.omega"].max() - 1.0)
    ref = peak[("phasor", 1e-4)]
    print(f"SMIB ({a.machine}) bolted fault 0.1-0.2 s, {a.t_end:g} s simulated, "
          f"median of {a.repeats} runs")
    print(f"{'engine':<10} {'dt [s]':>8} {'steps':>7} {'median [s]':>11} {'max(w)-1':>10} {'vs phasor':>10}")
    for eng, dt in RUNS:
        med = statistics.median(times[(eng, dt)])
        p = peak[(eng, dt)]
        print(f"{eng:<10} {dt:>8g} {round(a.t_end / dt):>7d} {med:>11.3f} {p:>10.5f} "
              f"{(p - ref) / ref:>+10.2%}")


if __name__ == "__main__":
    main()
