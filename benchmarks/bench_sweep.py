"""Benchmark of study sweeps on dask.distributed (not a test: prints numbers, asserts nothing).

Sweep throughput (runs per second) of the same sweep — case 1, the (29) controller (no
training), the UPQC rating × the fault duration, 1.0-s runs — serially in this process
(``workers = 0``) and on a LocalCluster of 2 single-threaded worker processes, measured in one
run of this script with a fresh cache each time. Two figures: "cold" includes the cluster's
start and each worker's first imports and design-model build; "warm" runs one warm-up point
first (in this process for the serial sweep, on every worker for the cluster) and then times
the sweep alone — the steady-state throughput of a long sweep. The machine's load average is printed before and
after: on a shared machine the ratio is only as good as the load allows.

Run:  PYTHONPATH=src python benchmarks/bench_sweep.py [n_ratings]
"""

from __future__ import annotations

import os
import sys
import tempfile
import time

from weakgrid.study.studyfile import load_study
from weakgrid.study.sweep import run_point, sweep_points
from weakgrid.sweep import open_client, run_sweep


def points(n_ratings=8):
    st = load_study("case1-weak-grid")
    sw = st.data["sweep"]
    ratings = [0.05 + 0.25 * k / max(n_ratings - 1, 1) for k in range(n_ratings)]
    sw.update(controllers=["nonlinear-29"], t_end=1.0, design_load="high")
    sw["axes"] = {"upqc.rating": ratings,
                  "scenarios.c1-high-conv.events.0.t_off": [0.22, 0.25, 0.3]}
    sw.pop("dt_check", None)
    return sweep_points(st)


def _busy(n=15_000_000):
    t = time.perf_counter()
    s = 0
    for i in range(n):
        s += i
    return time.perf_counter() - t


def machine_parallelism():
    """The speed-up two processes get right now on this machine: the same pure-Python loop in
    one process, then in two at once (a shared machine gives less than 2)."""
    from concurrent.futures import ProcessPoolExecutor

    one = _busy()
    with ProcessPoolExecutor(2) as ex:
        two = list(ex.map(_busy, [15_000_000] * 2))
    return 2 * one / max(two)


def _warm(inputs):
    run_point(inputs)
    return True


def main(n_ratings=8):
    pts = points(n_ratings)
    warm = points(1)[0].inputs          # rating 0.05: not one of the timed points
    n = len(pts)
    print(f"the machine's parallel speed-up for 2 processes now: {machine_parallelism():.2f}x")
    print(f"== sweep throughput: {n} runs of case 1 ((29), 1.0 s each) ==")
    print(f"load average before: {os.getloadavg()}  (cores: {os.cpu_count()})")
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        with open_client(None, 2) as client:
            t_up = time.perf_counter() - t0
            cold = run_sweep(pts, run_point, cache_dir=f"{tmp}/cold", client=client,
                             progress=False)
            t_cold = time.perf_counter() - t0
            client.run(_warm, warm)
            t0 = time.perf_counter()
            par = run_sweep(pts, run_point, cache_dir=f"{tmp}/par", client=client,
                            progress=False)
            t_par = time.perf_counter() - t0
        t0 = time.perf_counter()
        serial_cold = run_sweep(pts, run_point, cache_dir=f"{tmp}/serial-cold", workers=0,
                                progress=False)
        t_serial_cold = time.perf_counter() - t0
        _warm(warm)
        t0 = time.perf_counter()
        serial = run_sweep(pts, run_point, cache_dir=f"{tmp}/serial", workers=0,
                           progress=False)
        t_serial = time.perf_counter() - t0
    ok = [int((t["status"] == "ok").sum()) for t in (serial, par, cold, serial_cold)]
    print(f"cold: serial {t_serial_cold:6.1f} s ({n / t_serial_cold:.3f} runs/s); 2 workers "
          f"{t_cold:6.1f} s ({n / t_cold:.3f} runs/s, cluster start {t_up:.1f} s) -> "
          f"{t_serial_cold / t_cold:.2f}x")
    print(f"warm: serial {t_serial:6.1f} s ({n / t_serial:.3f} runs/s); 2 workers "
          f"{t_par:6.1f} s ({n / t_par:.3f} runs/s) -> {t_serial / t_par:.2f}x")
    print(f"runs ok: {ok}; median wall time of one run: serial {serial['wall_s'].median():.2f} s,"
          f" on a worker {par['wall_s'].median():.2f} s (> serial: each worker got less CPU)")
    avail = machine_parallelism()
    print(f"the machine's parallel speed-up for 2 processes right now (a CPU loop): {avail:.2f}x"
          f" -> the warm sweep reaches {t_serial / t_par / avail:.0%} of what the machine gives")
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 8)
