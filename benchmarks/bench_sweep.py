"""Benchmark of study sweeps on dask.distributed (not a test: prints numbers, asserts nothing).

Sweep throughput (runs per second) of the same sweep — case 1, the (29) controller (no
training), the UPQC rating × the fault duration, 1.0-s runs — serially in this process
(``workers = 0``) and on a LocalCluster of 2 single-threaded worker processes, measured in one
run of this script with a fresh cache each time. Wall times include the cluster's start (the
2-worker figure is also given without it). The machine's load average is printed before and
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


def main(n_ratings=8):
    pts = points(n_ratings)
    print(f"== sweep throughput: {len(pts)} runs of case 1 ((29), 1.0 s each) ==")
    print(f"load average before: {os.getloadavg()}  (cores: {os.cpu_count()})")
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        serial = run_sweep(pts, run_point, cache_dir=f"{tmp}/serial", workers=0, progress=False)
        t_serial = time.perf_counter() - t0
        t0 = time.perf_counter()
        with open_client(None, 2) as client:
            t_up = time.perf_counter() - t0
            par = run_sweep(pts, run_point, cache_dir=f"{tmp}/par", client=client,
                            progress=False)
        t_par = time.perf_counter() - t0
    ok = (serial["status"] == "ok").sum(), (par["status"] == "ok").sum()
    n = len(pts)
    print(f"serial (workers=0):   {t_serial:7.1f} s  {n / t_serial:.3f} runs/s  ({ok[0]} ok)")
    print(f"2 workers (Dask):     {t_par:7.1f} s  {n / t_par:.3f} runs/s  ({ok[1]} ok; "
          f"cluster start {t_up:.1f} s, {n / (t_par - t_up):.3f} runs/s without it)")
    print(f"throughput ratio 2 workers / serial: {t_serial / t_par:.2f}x "
          f"({t_serial / (t_par - t_up):.2f}x without the cluster start)")
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 8)
