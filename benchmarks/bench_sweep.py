"""Benchmark of study sweeps on dask.distributed (not a test: prints numbers, asserts nothing).

What it measures
----------------
Sweep throughput (runs per second) of the same sweep — case 1, the (29) controller (no
training), the UPQC rating × the fault duration, 1.0-s runs — serially in this process
(``workers = 0``: the plain loop over the runs, with the same result cache) and on the
LocalCluster that ``weakgrid sweep`` starts (``open_client``: 2 single-threaded worker
processes, the scheduler in this process), measured in one run of this script with a fresh
cache each time. The same runs, in the same process, one after the other.

* **cold**: includes the cluster's start and each worker's first imports and design-model
  build (the serial loop's first run includes them too);
* **warm**: one warm-up point first (in this process for the serial loop, on every worker
  for the cluster; not one of the timed points), then the sweep alone — the steady-state
  throughput of a long sweep.

The ratio is only as good as the machine's load allows (a shared machine gives two processes
less than 2×; the same CPU loop in one and in two processes is timed beside it, and the load
average printed before and after). So the components of the parallel sweep's time are
measured too, each of them independent of the ratio:

* the runs' own CPU time (``cpu_s`` of each record: the CPU time of the thread that ran it)
  serially and on the workers — the per-run slowdown of running two at once (caches, memory
  bandwidth, the workers' Dask threads taking the GIL); and their wall time over CPU time —
  runs waiting for a core (other load);
* the CPU time of the workers' other threads (Dask's event loop and its periodic callbacks:
  process CPU − the runs' CPU) and of this process while the sweep runs (scheduler, nannies,
  client, cache writes), which shares the same 2 cores;
* from Dask's task stream, on each worker: runs, busy time, the idle gaps between its runs
  (a scheduler round trip each), the time from the sweep's start to its first run and from
  its last run to the end of the last run on any worker (the tail, where one worker idles
  while the other finishes); and the sweep's time outside the task stream (submission,
  collecting the results, the table);
* the pickled size of one task (function and input), and Dask's cost of one task (submit,
  run, result, cache write: 200 no-op runs through the same engine on the same cluster);
* the peer of the Dask sweep: the same runs in a plain pool of 2 processes
  (``concurrent.futures``, no Dask, no cache, warm) — its runs' CPU time against the serial
  runs' is the cost of running two simulations at once on this machine (shared caches and
  memory), which no engine removes;
* CPU accounting: the core-seconds of the serial loop against those of the parallel sweep
  (the runs, Dask's threads, this process, the workers' idle time from the task stream;
  cold: the cluster's start on both cores):
  the ratio they project on 2 otherwise idle cores (time waiting for a core not counted).

Measured 2026-11-26 on the shared machine (other sessions' load 2-5 on the 2 cores, so the
ratios themselves are noisy: 0.75x-1.72x), the engine before (``--dask-defaults``) → after
(``weakgrid.sweep.engine.LOCAL_CLUSTER_CONFIG``, ``run_sweep(cost=...)``), warm:

* the workers' Dask threads: 5.4-9.7 % of the runs' CPU time → 0.7-1.5 % (the statistical
  profiler, 20-ms event-loop ticks, the 0.1-s memory and 0.5-s system monitors);
* this process (scheduler, nannies, client, cache): 2.9-4.3 % of a core → 0.9-1.3 %;
* the tail: up to 1.9 s of a 23-s sweep with a worker holding two runs → a worker holds one
  run at a time, the costliest first (0-0.6 s in 8 sweeps, 1.5 s once at load 3: under load
  a run's wall time varies and so does the tail); the gaps between runs: 1-2 ms → 2-10 ms each (a
  scheduler round trip per run now);
* the runs' CPU time on the workers against the serial runs': x1.06-1.12 (median x1.11 of 4
  measurements) → x1.00-1.18 (median x1.06 of 10; the x1.18 at load 5), as in the plain pool
  measured beside it (x0.99-1.15, median x1.07 of 7): what is left is two simulations at
  once on this machine, not Dask (in a 1-worker cluster a run takes the serial CPU time);
* Dask's cost per task: 1.5-2.3 ms of a worker's CPU and 2.5-3.4 ms of this process's (with
  the cache write), against ≈ 1 s runs: no batching needed;
* CPU accounting: 1.75x → 1.81-1.83x warm; cold 1.61x → 1.95x without the cluster's start,
  1.60x with it (it now counts on both cores: 1.1-3.1 s; a 24-run sweep does not amortize
  it). The one warm ratio measured while the machine was quiet, before: 1.72x (plain pool
  1.96x); after, on the idle machine (load average ~1): 24 runs 2.01x warm, 1.74x cold; 96 runs
  (``bench_sweep.py 32``) 1.96x warm, 1.89x cold; the plain pool 2.02-2.03x.

Run:  PYTHONPATH=src python benchmarks/bench_sweep.py [n_ratings] [--dask-defaults]
      PYTHONPATH=src python benchmarks/bench_sweep.py --study [--repeats N] [--workers W]
          [--only sweep|reproduce|breakdown|scaling]

``--study``: the commands users wait for, batched against the scalar path (issue #21), each
pair measured in one run of this script, a fresh output folder and cache each time, each in a
fresh process (its own imports and per-process caches, as a command runs), the order
alternated between repeats, medians of ``--repeats`` (default 1):

* the case-1 quick sweep (``weakgrid sweep case1-weak-grid --quick``: 12 runs) on ``W``
  workers (default 2; 0 = serially in this process);
* ``weakgrid reproduce --quick`` (its runs, trainings, figures, report and the maps' sweeps);
* ``--only breakdown``: where a batch's time goes, in this process (prepare, simulate one by
  one and together, finish; the batched step's parts);
* ``--only scaling``: how a map batch's cost grows with its size (:func:`batch_scaling`).

The scalar path is one task per run (:func:`weakgrid.sweep.execute`); the batched path groups
a sweep's runs by grid (:func:`weakgrid.study.batches.batch_key`) and hands each batch to
:func:`weakgrid.study.batches.simulate_many`, a task per batch, which simulates the batch's
runs in one :func:`weakgrid.sim.batch.simulate_batch` pass (the ratings as per-member
parameters). The tables of both paths are checked equal (times aside).

``--dask-defaults``: the cluster with Dask's default settings and the runs in the sweep's
order (the engine before the changes above), for a comparison on the same machine.
"""

from __future__ import annotations

import itertools
import os
import statistics
import sys
import tempfile
import time

from weakgrid.study.studyfile import load_study
from weakgrid.study.sweep import run_point, sweep_points
from weakgrid.study.sweep_estimate import run_cost
from weakgrid.sweep import ResultCache, execute, open_client, run_sweep


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


def _cpu_of(pids):
    import psutil

    out = 0.0
    for p in pids:
        t = psutil.Process(p).cpu_times()
        out += t.user + t.system
    return out


def _runs_cpu(table, cache_dir):
    """The CPU time of each run (its record's ``cpu_s``), in the table's order [s]."""
    cache = ResultCache(cache_dir)
    return [cache.get(k).get("cpu_s", float("nan")) for k in table["key"]]


def _stream(tasks, t_start, t_end):
    """Per worker: runs, busy, gaps, lead-in and tail from Dask's task stream [s]."""
    by = {}
    for t in tasks:
        for s in t["startstops"]:
            if s["action"] == "compute":
                by.setdefault(t["worker"], []).append((s["start"], s["stop"]))
    last = max(e for v in by.values() for _, e in v)
    first = min(s for v in by.values() for s, _ in v)
    out = []
    for w, v in sorted(by.items()):
        v.sort()
        gaps = [b[0] - a[1] for a, b in itertools.pairwise(v)]
        out.append({"worker": w, "runs": len(v), "busy": sum(e - s for s, e in v),
                    "gaps": sum(gaps), "gap_max": max(gaps, default=0.0),
                    "lead": v[0][0] - t_start, "tail": last - v[-1][1]})
    return out, first - t_start, t_end - last


def components(client, pts, cache_dir, cost):
    """Run the sweep on ``client`` and measure where its time goes (see the module's text)."""
    import cloudpickle
    from distributed import get_task_stream

    wpids = list(client.run(os.getpid).values())
    w0, m0 = _cpu_of(wpids), time.process_time()
    t0, wall0 = time.perf_counter(), time.time()
    with get_task_stream(client) as ts:
        table = run_sweep(pts, run_point, cache_dir=cache_dir, client=client, progress=False,
                          cost=cost)
    t = time.perf_counter() - t0
    wall1 = time.time()
    w_cpu, m_cpu = _cpu_of(wpids) - w0, time.process_time() - m0
    runs_cpu = _runs_cpu(table, cache_dir)
    per_worker, lead, end = _stream(ts.data, wall0, wall1)
    task = len(cloudpickle.dumps((execute, run_point, pts[0].inputs, "k" * 24)))
    return {"t": t, "table": table, "runs_cpu": runs_cpu, "workers_cpu": w_cpu,
            "main_cpu": m_cpu, "per_worker": per_worker, "lead": lead, "end": end,
            "task_bytes": task}


def _noop(inputs):
    return {"i": inputs["i"]}


def per_task(client, cache_dir, n=200):
    """Dask's (and the cache's) cost of one task: ``n`` no-op runs through :func:`run_sweep`
    on ``client``. Returns (wall, CPU of the workers, CPU of this process) per task [s]."""
    from weakgrid.sweep import Point

    pts = [Point({"i": i}, {"i": i}) for i in range(n)]
    wpids = list(client.run(os.getpid).values())
    w0, m0, t0 = _cpu_of(wpids), time.process_time(), time.perf_counter()
    run_sweep(pts, _noop, cache_dir=cache_dir, client=client, progress=False)
    return ((time.perf_counter() - t0) / n, (_cpu_of(wpids) - w0) / n,
            (time.process_time() - m0) / n)


def _serial(pts, cache_dir):
    m0, t0 = time.process_time(), time.perf_counter()
    table = run_sweep(pts, run_point, cache_dir=cache_dir, workers=0, progress=False)
    return {"t": time.perf_counter() - t0, "table": table, "main_cpu": time.process_time() - m0,
            "runs_cpu": _runs_cpu(table, cache_dir)}


def _pool_run(inputs):
    c0 = time.thread_time()
    run_point(inputs)
    return time.thread_time() - c0


def _pool_warm(inputs):
    _pool_run(inputs)
    time.sleep(0.5)      # the other process takes the other warm-up point
    return os.getpid()


def plain_pool(pts, warm):
    """The same runs in a plain pool of 2 processes (no Dask, no cache), warm: the cost of two
    runs at once on this machine, without Dask. Returns (wall time [s], the runs' CPU [s])."""
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(2, mp_context=mp.get_context("spawn")) as ex:
        list(ex.map(_pool_warm, [warm, warm]))
        t0 = time.perf_counter()
        cpu = list(ex.map(_pool_run, [p.inputs for p in pts]))
        return time.perf_counter() - t0, cpu


def _report(label, ser, par, start=0.0):
    s_cpu, p_cpu = sum(ser["runs_cpu"]), sum(par["runs_cpu"])
    s_wall, p_wall = ser["table"]["wall_s"].sum(), par["table"]["wall_s"].sum()
    ratio = [p / s for p, s in zip(par["runs_cpu"], ser["runs_cpu"])]
    print(f"-- {label}: components")
    print(f"  runs' CPU time: serial {s_cpu:.2f} s, on the workers {p_cpu:.2f} s "
          f"(x{p_cpu / s_cpu:.3f}; per run median x{statistics.median(ratio):.3f})")
    print(f"  runs' wall / CPU time (> 1: waiting for a core): serial {s_wall / s_cpu:.3f}, "
          f"workers {p_wall / p_cpu:.3f}")
    print(f"  the workers' Dask threads: {par['workers_cpu'] - p_cpu:.2f} s of CPU "
          f"({(par['workers_cpu'] - p_cpu) / p_cpu:.1%} of the runs'); this process "
          f"(scheduler, nannies, client, cache): {par['main_cpu']:.2f} s "
          f"({par['main_cpu'] / par['t']:.1%} of a core; serial loop outside the runs: "
          f"{ser['main_cpu'] - s_cpu:.2f} s)")
    idle = sum(w["gaps"] + w["tail"] + w["lead"] for w in par["per_worker"])
    core_s = p_cpu + (par["workers_cpu"] - p_cpu) + par["main_cpu"] + idle + 2 * start
    print(f"  CPU accounting: the serial loop used {ser['main_cpu']:.2f} core-s, the sweep on 2 "
          f"workers {core_s:.2f} (runs, Dask threads, this process, idle workers {idle:.2f}"
          + (f", the cluster's start on both cores {2 * start:.2f}" if start else "") + ") "
          f"-> {2 * ser['main_cpu'] / core_s:.2f}x on 2 otherwise idle cores (a projection: "
          f"waiting for a core not counted, idle time as measured now)")
    for w in par["per_worker"]:
        print(f"  {w['worker']}: {w['runs']} runs, busy {w['busy']:.2f} s, gaps between runs "
              f"{w['gaps']:.3f} s (max {w['gap_max'] * 1e3:.0f} ms), first run after "
              f"{w['lead']:.2f} s, idle at the end {w['tail']:.2f} s")
    print(f"  sweep {par['t']:.2f} s: before the first run {par['lead']:.2f} s, after the last "
          f"{par['end']:.2f} s; one task pickled {par['task_bytes'] / 1024:.1f} KiB")


def main(n_ratings=8, dask_defaults=False):
    cost = run_cost
    if dask_defaults:
        from weakgrid.sweep import engine

        engine.LOCAL_CLUSTER_CONFIG = {}
        cost = None
        print("Dask's default settings, runs in the sweep's order")
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
            cold = components(client, pts, f"{tmp}/cold", cost)
            t_cold = time.perf_counter() - t0
            client.run(_warm, warm)
            par = components(client, pts, f"{tmp}/par", cost)
            task_wall, task_wcpu, task_mcpu = per_task(client, f"{tmp}/noop")
        t_pool, pool_cpu = plain_pool(pts, warm)
        serial_cold = _serial(pts, f"{tmp}/serial-cold")
        _warm(warm)
        serial = _serial(pts, f"{tmp}/serial")
    ok = [int((r["table"]["status"] == "ok").sum()) for r in (serial, par, cold, serial_cold)]
    print(f"cold: serial {serial_cold['t']:6.1f} s ({n / serial_cold['t']:.3f} runs/s); 2 workers "
          f"{t_cold:6.1f} s ({n / t_cold:.3f} runs/s, cluster start {t_up:.1f} s) -> "
          f"{serial_cold['t'] / t_cold:.2f}x")
    print(f"warm: serial {serial['t']:6.1f} s ({n / serial['t']:.3f} runs/s); 2 workers "
          f"{par['t']:6.1f} s ({n / par['t']:.3f} runs/s) -> {serial['t'] / par['t']:.2f}x")
    print(f"runs ok: {ok}; median wall time of one run: serial "
          f"{serial['table']['wall_s'].median():.2f} s, on a worker "
          f"{par['table']['wall_s'].median():.2f} s")
    s_cpu = sum(serial["runs_cpu"])
    print(f"peer: a plain pool of 2 processes (no Dask, no cache, warm) {t_pool:6.1f} s "
          f"({n / t_pool:.3f} runs/s) -> {serial['t'] / t_pool:.2f}x; its runs' CPU time "
          f"{sum(pool_cpu):.2f} s (x{sum(pool_cpu) / s_cpu:.3f} the serial runs': two runs at "
          f"once on this machine); the warm Dask sweep reaches {t_pool / par['t']:.0%} of its "
          f"throughput")
    print(f"Dask's cost of a task (200 no-op runs on the same cluster: submit, run, result, "
          f"cache write): {task_wall * 1e3:.1f} ms wall, {task_wcpu * 1e3:.1f} ms of the "
          f"workers' CPU, {task_mcpu * 1e3:.1f} ms of this process's CPU")
    _report("warm", serial, par)
    _report("cold", serial_cold, cold, start=t_up)
    avail = machine_parallelism()
    print(f"the machine's parallel speed-up for 2 processes right now (a CPU loop): {avail:.2f}x"
          f" -> the warm sweep reaches {serial['t'] / par['t'] / avail:.0%} of what the machine "
          f"gives")
    print(f"load average after: {os.getloadavg()}")


def _fresh(fn, *args):
    """``(wall time [s], fn(*args))`` in a fresh process (as a command runs: its own imports
    and per-process caches, none left warm by the measurement before)."""
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(1, mp_context=mp.get_context("spawn")) as ex:
        return ex.submit(_timed, fn, *args).result()


def _timed(fn, *args):
    import logging

    logging.disable(logging.INFO)
    t0 = time.perf_counter()
    out = fn(*args)
    return time.perf_counter() - t0, out


def _case1_quick_sweep(out, workers, batched):
    from weakgrid.study.sweep import run_study_sweep

    return run_study_sweep(load_study("case1-weak-grid"), out, quick=True, workers=workers,
                           progress=False, batched=batched)


def _reproduce_quick(out, workers, batched):
    from weakgrid.study.reproduce import reproduce

    return reproduce(out, quick=True, workers=workers, progress=False, batched=batched)["sweep"]


def _same_table(a, b):
    times = [c for c in ("wall_s", "sim_wall_s", "traceback_tail") if c in a.columns]
    try:
        import pandas as pd

        pd.testing.assert_frame_equal(a.drop(columns=times), b.drop(columns=times))
        return True
    except AssertionError:
        return False


def study_commands(repeats=1, workers=2, only=None):
    """The case-1 quick sweep and ``reproduce --quick``, scalar against batched (see the
    module's text); prints the medians and ratios."""
    print(f"== study commands, scalar vs batched, {workers} workers, medians of {repeats} ==")
    print(f"load average before: {os.getloadavg()}  (cores: {os.cpu_count()})")
    for label, fn in (("case-1 quick sweep (12 runs)", _case1_quick_sweep),
                      ("reproduce --quick", _reproduce_quick)):
        if only and only not in label:
            continue
        times = {"scalar": [], "batched": []}
        same = True
        for k in range(repeats):
            tables = {}
            for path in ("scalar", "batched")[::1 if k % 2 == 0 else -1]:   # order alternated
                with tempfile.TemporaryDirectory() as tmp:
                    t, tables[path] = _fresh(fn, f"{tmp}/out", workers, path == "batched")
                times[path].append(t)
            same = same and _same_table(tables["scalar"], tables["batched"])
        s, b = (statistics.median(times[k]) for k in ("scalar", "batched"))
        print(f"{label}: scalar {s:7.1f} s, batched {b:7.1f} s -> {s / b:.2f}x "
              f"(tables equal: {same}; all: scalar {[round(x, 1) for x in times['scalar']]}, "
              f"batched {[round(x, 1) for x in times['batched']]})")
    print(f"load average after: {os.getloadavg()}")


def batch_breakdown(repeats=3):
    """Where a batch's time goes, in this process: the high-load half of the case-1 quick
    sweep (6 runs: 2 ratings × 3 controllers, one batch of the batched sweep) prepared (grid,
    events, controller; the trained controllers are built once before), simulated one by one
    and together, finished (metrics); medians of ``repeats`` (wall and CPU time of the
    simulations), and the batched step's parts."""
    from weakgrid.study.runner import simulate_prepared
    from weakgrid.study.sweep import finish_point, prepare_point

    pts = [p.inputs for p in sweep_points(load_study("case1-weak-grid"), quick=True)
           if p.params["scenarios.c1-high-conv.load"] == "high"]
    [prepare_point(i) for i in pts]            # the trainings and design models, once
    out = {"prepare": [], "scalar": [], "batched": [], "finish": []}
    cpu = {"scalar": [], "batched": []}     # CPU time of this process: what the load inflates less
    stats = {}
    for k in range(repeats):
        for path in ("scalar", "batched")[::1 if k % 2 == 0 else -1]:
            t0 = time.perf_counter()
            preps = [prepare_point(i) for i in pts]
            t1, c1 = time.perf_counter(), time.process_time()
            sims = simulate_prepared(preps, batched=path == "batched",
                                     stats=stats if path == "batched" else None)
            t2 = time.perf_counter()
            cpu[path].append(time.process_time() - c1)
            [finish_point(i, p, *s) for i, p, s in zip(pts, preps, sims)]
            t3 = time.perf_counter()
            out["prepare"].append(t1 - t0)
            out[path].append(t2 - t1)
            out["finish"].append(t3 - t2)
    med = {k: statistics.median(v) for k, v in out.items()}
    print(f"== one batch of the case-1 quick sweep ({len(pts)} runs), in one process, medians "
          f"of {repeats} ==")
    print(f"prepare {med['prepare']:.2f} s, simulate one by one {med['scalar']:.2f} s, "
          f"together {med['batched']:.2f} s ({med['scalar'] / med['batched']:.2f}x), finish "
          f"{med['finish']:.2f} s")
    cs, cb = statistics.median(cpu["scalar"]), statistics.median(cpu["batched"])
    print(f"CPU time: simulate one by one {cs:.2f} s, together {cb:.2f} s ({cs / cb:.2f}x)")
    tim = stats.get("timing", {})
    tot = sum(tim.values()) or 1.0
    print("batched step, share of its timed parts: " + ", ".join(
        f"{k} {v / repeats:.2f} s ({100 * v / tot:.0f} %)" for k, v in tim.items()))


def batch_scaling(sizes=(6, 15, 30), repeats=1, n_alone=6):
    """How a map batch's cost grows with its size, in this process: the first ``B`` runs of
    one batch of the full case-1 sweep (one fault clearing time, 2-s runs at the controller's
    period T; ratings, loads and the three controllers mixed as the sweep mixes them),
    simulated together for each ``B`` (and the first ``n_alone`` one by one: the cost of a run
    alone is their mean), after one warm-up batch
    (trainings and design models built). Per batched step: the wall time, the time per
    member, the timed parts (:attr:`weakgrid.sim.batch.BatchSimulator.timing`; ``events``
    holds the controllers' samples, ``other`` is the rest: the members' bookkeeping between
    the parts), and the residual evaluations per step, split into those of every member
    still iterating and those of a few stragglers (at most a fifth of the batch): a
    residual's cost hardly depends on how many members it evaluates. Medians of
    ``repeats``."""
    import collections

    from weakgrid.sim import batch as batch_mod
    from weakgrid.study.batches import batch_key, simulate_many

    groups = collections.defaultdict(list)
    for p in sweep_points(load_study("case1-weak-grid"), quick=False):
        groups[batch_key(p.inputs)].append(p.inputs)
    key = max(groups, key=lambda k: (k[4] == 1.0, len(groups[k])))
    runs = groups[key]
    seen = []
    calls = collections.Counter()
    run0, res0 = batch_mod.BatchSimulator.run, batch_mod.BatchSimulator.residual

    def run(self, t_end):
        t0 = time.perf_counter()
        try:
            return run0(self, t_end)
        finally:
            seen.append((self.B, self.steps, time.perf_counter() - t0, dict(self.timing)))

    def residual(self, t, Z, rows):
        calls["all" if 5 * len(rows) > self.B else "few"] += 1
        return res0(self, t, Z, rows)

    batch_mod.BatchSimulator.run, batch_mod.BatchSimulator.residual = run, residual
    try:
        simulate_many(runs[:2])                    # warm-up: trainings, design models
        singles = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            for r in runs[:n_alone]:
                simulate_many([r])
            singles.append((time.perf_counter() - t0) / n_alone)
        alone = statistics.median(singles)
        ctl = collections.Counter(r["controller"] for r in runs[:n_alone])
        print(f"== one map batch of the case-1 sweep ({len(runs)} runs, clearing at "
              f"{key[5][-1]} s), the first B runs together, in this process ==")
        print(f"a run alone: {alone:.2f} s (the mean of the first {n_alone}: "
              + ", ".join(f"{n} {c}" for c, n in ctl.items()) + ")")
        for B in sizes:
            rows = []
            for _ in range(repeats):
                seen.clear()
                calls.clear()
                simulate_many(runs[:B])
                (b, steps, wall, tim), = seen
                rows.append((wall, steps, tim, dict(calls)))
            wall, steps, tim, cnt = sorted(rows, key=lambda r: r[0])[len(rows) // 2]
            ms = {k: 1e3 * v / steps for k, v in tim.items()}
            ms["other"] = 1e3 * wall / steps - sum(ms.values())
            print(f"B = {B:3d}: {wall:6.2f} s, {steps} steps: {1e3 * wall / steps:.2f} ms per "
                  f"step, {1e3 * wall / steps / B:.3f} ms per member-step "
                  f"({alone / (wall / B):.1f}x less than alone); per step: "
                  + ", ".join(f"{k} {v:.2f}" for k, v in ms.items())
                  + f" ms; residuals per step: {cnt.get('all', 0) / steps:.2f} of the members "
                  f"iterating, {cnt.get('few', 0) / steps:.2f} of at most a fifth")
    finally:
        batch_mod.BatchSimulator.run, batch_mod.BatchSimulator.residual = run0, res0


def _option(name, default):
    if name in sys.argv:
        return int(sys.argv[sys.argv.index(name) + 1])
    return default


if __name__ == "__main__":
    if "--study" in sys.argv:
        only = sys.argv[sys.argv.index("--only") + 1] if "--only" in sys.argv else None
        if only == "breakdown":
            batch_breakdown(_option("--repeats", 3))
        elif only == "scaling":
            batch_scaling(repeats=_option("--repeats", 1))
        else:
            study_commands(_option("--repeats", 1), _option("--workers", 2), only)
        sys.exit(0)
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    main(int(args[0]) if args else 8, dask_defaults="--dask-defaults" in sys.argv)
