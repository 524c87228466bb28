"""Run the points of a sweep on ``dask.distributed`` with a result cache.

Every point is one task. Tasks run on a :class:`distributed.LocalCluster` (one
single-threaded worker process per core by default) or on an existing cluster
given by its scheduler address. Given an estimate of each run's cost, the
costliest runs start first (a long run started last keeps one worker busy while
the others idle); a LocalCluster holds one run per worker at a time (the next
waits on the scheduler, not behind a running one) and keeps Dask's own
monitoring, which shares the workers' cores, to a minimum
(:data:`LOCAL_CLUSTER_CONFIG`). A finished run is written to the cache as soon
as it arrives, so an interrupted sweep (Ctrl-C, SIGTERM) loses nothing and a
repeated one runs nothing. A run that raises is a row with ``status = "failed"``
and its cause, never the end of the sweep.
"""

from __future__ import annotations

import contextlib
import logging
import math
import os
import signal
import time
import traceback
from pathlib import Path

import pandas as pd

from .. import __version__
from ..fileio import replace_atomic
from ..game.errors import ParameterError, WeakgridError
from .cache import ResultCache, run_key
from .feed import TaskFeed

_log = logging.getLogger(__name__)

__all__ = ["run_sweep", "submit_sweep", "PendingSweep", "execute", "execute_batch",
           "SweepInterrupted", "results_table",
           "open_client",
           "LOCAL_CLUSTER_CONFIG"]

#: Dask settings of the LocalCluster that :func:`open_client` starts. Each worker runs one
#: CPU-bound run at a time on its own core, and each of Dask's periodic callbacks wakes a
#: thread that takes the GIL from that run; the scheduler and the nannies live in this
#: process, which shares the same cores. Measured on case-1 runs of ≈ 1 s (2026-11-26, on the
#: shared 2-core machine): with Dask's defaults the workers' other threads took 6 % (1 worker)
#: to 9-10 % (2 workers, benchmarks/bench_sweep.py) of the CPU time of their runs and this
#: process 2.7-4.3 % of a core; with these, 0.5 % (1 worker) and 0.7-1.5 % (2 workers; ≈ 2 ms
#: of a worker's CPU per task), and 0.5-1.3 % of a core.
LOCAL_CLUSTER_CONFIG = {
    # one run per worker: with the default 1.1, a worker of one thread holds a second run
    # in its queue, which can end a sweep with that worker busy and the other idle
    "distributed.scheduler.worker-saturation": 1.0,
    # the statistical profiler samples the running task every 10 ms, for the dashboard
    # (which is off): ≈ 3 % of the worker's CPU
    "distributed.worker.profile.enabled": False,
    # the event loops' latency check (a log line beyond 3 s), default every 20 ms in the
    # scheduler, each nanny and each worker
    "distributed.admin.tick.interval": "1s",
    # CPU/memory/network series for the dashboard (default 0.5 s)
    "distributed.admin.system-monitor.interval": "2s",
    # the memory limits (pause, spill, restart) checked every 0.5 s, not 0.1 s
    "distributed.worker.memory.monitor-interval": "500ms",
    # no HTTP endpoints: the scheduler and the workers start an HTTP server even without the
    # dashboard (health, JSON state, Prometheus metrics), which nobody here reads and which
    # needs no credentials; with no routes it answers nothing
    "distributed.scheduler.http.routes": [],
    "distributed.worker.http.routes": [],
}


class SweepInterrupted(WeakgridError, KeyboardInterrupt):
    """The sweep was stopped (SIGINT/SIGTERM); finished runs are cached.

    Attributes
    ----------
    done, total : int
        Runs finished (cached) and runs in the sweep.
    cache_dir : Path
    """

    def __init__(self, done, total, cache_dir):
        self.done, self.total, self.cache_dir = done, total, Path(cache_dir)
        super().__init__(f"interrupted: {done} of {total} runs finished and kept in "
                         f"{cache_dir}; run the same command again to continue")


def execute(run, inputs: dict, key: str) -> dict:
    """Run one point (on a worker) and return its record; never raises for a failed run.

    ``run(inputs)`` returns a dict of metrics, or ``(metrics, signals)`` with signals a
    DataFrame or a pyarrow Table (a study's run file). Metrics may carry ``status`` ("ok"/"failed") and ``failure`` (its cause)
    when the run failed without raising (e.g. a simulation that lost synchronism).
    The record keeps the run's wall time ``wall_s`` and the CPU time of the thread that ran
    it, ``cpu_s`` [s] (``wall_s`` above ``cpu_s``: the run waited for a core).
    """
    t0, c0 = time.perf_counter(), time.thread_time()
    try:
        out = run(inputs)
    except Exception as exc:  # a failing run is a row, whatever it raised
        out = exc
    return _record(key, out, time.perf_counter() - t0, time.thread_time() - c0)


def execute_batch(run_many, inputs: list, keys: list) -> list:
    """Run a batch of points (on a worker) and return one record each (as :func:`execute`).

    ``run_many(inputs)`` returns one result per input, in order: what ``run`` of
    :func:`execute` returns, or the exception that run raised (it becomes that run's failed
    row alone). If ``run_many`` itself raises, every run of the batch fails with its cause.
    Each record's ``wall_s`` and ``cpu_s`` are the batch's divided by its size [s].
    """
    t0, c0 = time.perf_counter(), time.thread_time()
    try:
        outs = list(run_many(list(inputs)))
        if len(outs) != len(keys):
            raise RuntimeError(f"{getattr(run_many, '__name__', run_many)} returned "
                               f"{len(outs)} results for a batch of {len(keys)} runs")
    except Exception as exc:  # the whole batch failed: each run is a failed row
        outs = [exc] * len(keys)
    n = max(len(keys), 1)
    wall, cpu = (time.perf_counter() - t0) / n, (time.thread_time() - c0) / n
    return [_record(k, o, wall, cpu) for k, o in zip(keys, outs)]


def _record(key, out, wall, cpu) -> dict:
    """The record of one run from what it returned (or the exception it raised)."""
    signals = None
    if not isinstance(out, BaseException):
        try:
            if isinstance(out, tuple):
                out, signals = out
            metrics = dict(out)
            status = str(metrics.pop("status", "ok"))
            failure = str(metrics.pop("failure", "") or "")
            kind = str(metrics.pop("failure_kind", "") or "")
        except Exception as exc:  # not metrics: the run's failure too
            out, signals = exc, None
    if isinstance(out, BaseException):
        metrics, status = {}, "failed"
        failure = f"{type(out).__name__}: {out}"
        kind = type(out).__name__
        tb = "".join(traceback.format_exception(out, limit=-3))
        metrics["traceback_tail"] = tb[-2000:]
    rec = {"key": key, "status": status, "failure": failure, "failure_kind": kind,
           "wall_s": wall, "cpu_s": cpu, "metrics": metrics, "weakgrid_version": __version__}
    return {"record": rec, "signals": signals}


def _store(cache, res):
    rec = res["record"]
    sig = res.get("signals")
    cache.put(rec, signals=sig)
    return cache.get(rec["key"])


@contextlib.contextmanager
def _sigterm_as_interrupt():
    """Inside the block, SIGTERM raises KeyboardInterrupt (main thread only)."""
    def handler(signum, frame):
        raise KeyboardInterrupt

    try:
        old = signal.signal(signal.SIGTERM, handler)
    except ValueError:  # not the main thread
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, old)


@contextlib.contextmanager
def open_client(scheduler=None, workers=None):
    """A ``distributed.Client`` for the block: of the cluster at ``scheduler``
    (``tcp://host:port``), else of a new LocalCluster with ``workers`` single-threaded
    worker processes (default: one per core) and :data:`LOCAL_CLUSTER_CONFIG`, closed at
    the end. One cluster can serve several sweeps (pass the client to :func:`run_sweep`).

    The local cluster is private: it listens on 127.0.0.1 only, speaks TLS with mutual
    authentication by a key pair made for it in memory (``distributed.Security.temporary``),
    so that no other process of the machine — another user's included — can connect to it
    and run code in its workers; the dashboard and every HTTP endpoint are off. A cluster
    given by ``scheduler`` is the user's: its security is its own (for a TLS cluster, set
    the client's certificates in Dask's configuration, ``distributed.comm.tls.*``, which
    ``Client`` reads).
    """
    import dask
    from distributed import Client, LocalCluster
    from distributed.security import Security

    if scheduler:
        client = Client(scheduler, timeout="20s")
        try:
            yield client
        finally:
            client.close()
        return
    n = workers or os.cpu_count() or 1
    # the workers' own logs stay quiet: a run's failure is a row of the table, and an interrupt
    # (SIGINT/SIGTERM) must not print the workers' shutdown tracebacks (heartbeats to a closing
    # scheduler); a lost worker still reaches the client as an exception
    security = Security.temporary()   # TLS, both ends authenticated; the key never touches disk
    with dask.config.set(LOCAL_CLUSTER_CONFIG):  # the workers get this config at their start
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                               host="127.0.0.1", dashboard_address=None,
                               silence_logs=logging.CRITICAL, security=security)
    client = Client(cluster, security=security)
    try:
        yield client
    finally:
        client.close()
        cluster.close()



def _progress(total, initial, enabled, desc):
    from tqdm.auto import tqdm

    return tqdm(total=total, initial=initial, disable=not enabled, desc=desc, unit="run",
                dynamic_ncols=True, mininterval=0.5)


def results_table(points, records) -> pd.DataFrame:
    """One row per point, in the sweep's order: run number, key, the swept fields,
    status, failure cause, wall time, then every metric."""
    rows = []
    for i, (pt, rec) in enumerate(zip(points, records)):
        row = {"run": i, "key": rec["key"]}
        for k, v in pt.params.items():
            row[k] = v if isinstance(v, (int, float, str, bool)) or v is None else str(v)
        row["status"] = rec["status"]
        row["failure"] = rec.get("failure", "")
        row["wall_s"] = rec.get("wall_s", math.nan)
        for k, v in (rec.get("metrics") or {}).items():
            if k in row:
                k = f"metric.{k}"
            row[k] = math.nan if v is None else v
        rows.append(row)
    df = pd.DataFrame(rows)
    for c in df.columns:  # text columns: missing is None (as Parquet reads it back)
        if df[c].dtype == object:
            df[c] = df[c].astype(object).where(df[c].notna(), None)
    return df


def _tasks(todo, run, batch, batch_size, cost=None, balance=None, other_cost=0.0):
    """``(function, arguments, (points, keys))`` of every task: one point each, or with
    ``batch = (key, run_many)`` one batch each (:func:`weakgrid.sweep.batches.balanced`;
    ``other_cost``: the cost of the workers' other tasks)."""
    if batch is None:
        return [(execute, (run, p.inputs, k), ([p], [k])) for p, k in todo]
    from .batches import balanced

    key, run_many = batch
    out = []
    for b in balanced(todo, lambda pk: key(pk[0].inputs), batch_size,
                      None if cost is None else (lambda pk: cost(pk[0].inputs)), balance,
                      other_cost):
        pts = [todo[i][0] for i in b.rows]
        keys = [todo[i][1] for i in b.rows]
        out.append((execute_batch, (run_many, [p.inputs for p in pts], keys), (pts, keys)))
    return out


def _results(res):
    """The records a task returned (a batch returns a list of them)."""
    return res if isinstance(res, list) else [res]


def _priorities(todo, cost, members=None, batch_cost=None):
    """Dask priorities (higher runs first): by decreasing ``cost`` (of a batch:
    ``batch_cost`` of its ``members``' inputs, by default the sum of their ``cost``), ties in
    the given order."""
    n = len(todo)
    if cost is None:
        return [n - i for i in range(n)]
    if members is None:
        est = [float(cost(p.inputs)) for p, _ in todo]
    elif batch_cost is not None:
        est = [float(batch_cost([p.inputs for p in m])) for m in members]
    else:
        est = [sum(float(cost(p.inputs)) for p in m) for m in members]
    order = sorted(range(n), key=lambda i: -est[i] if math.isfinite(est[i]) else 0.0)
    prio = [0] * n
    for rank, i in enumerate(order):
        prio[i] = n - rank
    return prio


def run_sweep(points, run, *, cache_dir, scheduler: str | None = None,
              workers: int | None = None, progress: bool = True, table_path=None,
              desc: str = "sweep", log=None, client=None, cost=None, batch=None,
              batch_size: int | None = None, balance: int | None = None,
              batch_cost=None) -> pd.DataFrame:
    """Run every point (skipping those already cached) and return the result table.

    Parameters
    ----------
    points : list of weakgrid.sweep.axes.Point
        What to run (``point.inputs`` is passed to ``run``).
    run : callable
        ``run(inputs) -> metrics`` or ``(metrics, signals)``; must be picklable (a
        module-level function or a :func:`functools.partial` of one).
    cache_dir : str or Path
        Where finished runs are kept (created if missing).
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:port``). Default: a
        LocalCluster.
    workers : int, optional
        Worker processes of the LocalCluster (default: one per core). ``0`` runs the
        points serially in this process (no Dask).
    progress : bool
        Show a progress bar (tqdm) on stderr.
    table_path : str or Path, optional
        Write the table as Parquet there (atomically).
    log : callable, optional
        Receives one-line messages (start, interruption).
    client : distributed.Client, optional
        An open client to run on (the caller's cluster; ``scheduler``/``workers`` ignored).
    cost : callable, optional
        ``cost(inputs) -> float``, an estimate of a run's cost (any unit): on a cluster the
        costliest runs start first, so that the sweep does not end with one worker on a long
        run and the others idle. Default: the points' order.
    batch : (key, run_many), optional
        Run the points in batches instead of one task each: the points still to run whose
        ``key(inputs)`` is equal form a batch (:func:`weakgrid.sweep.batches.group`: in the
        points' order), and ``run_many(list of inputs)`` runs a batch as one task
        (:func:`execute_batch`; for a study, :data:`weakgrid.study.batches.STUDY_BATCHES`).
        ``run`` still names the runs in the cache: a batched and a one-by-one sweep share
        their finished runs. Default: one task per point (the scalar path).
    batch_size : int, optional
        Largest batch (larger groups are split, so that batches spread over the workers).
    balance : int, optional
        With ``batch`` and ``cost``: the number of workers the batches are spread over; a
        batch costs at most ``1/balance`` of the runs still to run (a costlier group is
        split), so that no worker is left with one long batch while the others idle (the
        maps of ``weakgrid reproduce``: case 2's 90 runs of 6 s were one batch, half the
        sweep's cost, on one of 2 workers). Default: no limit by cost.
    batch_cost : callable, optional
        With ``batch`` and ``cost``: ``batch_cost(list of inputs) -> float``, a batch's cost
        in ``cost``'s unit, for the order in which the batches start (a batch also costs per
        step, whatever its size: :func:`weakgrid.study.sweep_estimate.batch_cost`). Default:
        the sum of its runs' ``cost``.

    Returns
    -------
    pandas.DataFrame
        See :func:`results_table`. Columns ``status``/``failure`` tell failed runs.

    Raises
    ------
    SweepInterrupted
        On SIGINT/SIGTERM, after every finished run is cached.
    """
    if workers is not None and (not isinstance(workers, int) or workers < 0):
        raise ParameterError("workers", workers, "give a whole number ≥ 0 (0 = serial)")
    log = log or _log.info
    cache, keys, records, todo = _plan(points, run, cache_dir, log)
    total = len(set(keys))
    log(f"{desc}: {total} runs, {total - len(todo)} already done, {len(todo)} to run"
        + ("" if not todo else (" serially" if workers == 0 and client is None else
                                f" on {scheduler or 'a local cluster'}")))
    tasks = _tasks(todo, run, batch, batch_size, cost, balance)
    if tasks and (workers != 0 or client is not None):
        ctx = contextlib.nullcontext(client) if client is not None else \
            open_client(scheduler, workers)
        try:
            with _sigterm_as_interrupt(), ctx as cl:
                return _submit(TaskFeed(cl), tasks, cost, points, keys, records, cache, desc,
                               progress, log=log, batch_cost=batch_cost).collect(table_path)
        except SweepInterrupted:
            raise
        except KeyboardInterrupt:   # before the runs were submitted (the cluster's start)
            exc = SweepInterrupted(len(records), total, cache.folder)
            log(str(exc))
            raise exc from None
    bar = _progress(total, total - len(todo), progress, desc)
    try:
        with _sigterm_as_interrupt():
            for fn, args, _ in tasks:
                for res in _results(fn(*args)):
                    records[res["record"]["key"]] = _store(cache, res)
                    bar.update(1)
    except KeyboardInterrupt:
        bar.close()
        exc = SweepInterrupted(len(records), total, cache.folder)
        log(str(exc))
        raise exc from None
    bar.close()
    return _table(points, keys, records, table_path)


def _plan(points, run, cache_dir, log):
    """``(cache, keys, records, todo)``: the result cache, every point's key, the records
    already cached and the ``(point, key)`` still to run (each key once)."""
    cache = ResultCache(cache_dir)
    keys = [run_key(p.inputs, run) for p in points]
    if len(set(keys)) != len(keys):
        log(f"note: {len(keys) - len(set(keys))} point(s) have the same input as another and "
            "run once")
    records = {k: rec for k in keys if (rec := cache.get(k)) is not None}
    todo = list({k: (p, k) for p, k in zip(points, keys) if k not in records}.values())
    return cache, keys, records, todo


def _table(points, keys, records, table_path):
    table = results_table(points, [records[k] for k in keys])
    if table_path is not None:
        replace_atomic(table_path, lambda tmp: table.to_parquet(tmp, index=False))
    return table


def submit_sweep(points, run, *, cache_dir, feed, desc: str = "sweep", progress: bool = True,
                 log=None, cost=None, batch=None, batch_size: int | None = None,
                 balance: int | None = None, other_cost: float = 0.0,
                 batch_cost=None) -> "PendingSweep":
    """Queue the runs of a sweep on ``feed`` (a :class:`weakgrid.sweep.feed.TaskFeed` of the
    caller's cluster) and return at once: the :class:`PendingSweep` collects them
    (:meth:`PendingSweep.collect`), so that the caller can keep the workers busy with other
    tasks beside it (``weakgrid run`` and ``reproduce``: the maps' runs fill the workers as
    the scenario runs end). The other arguments are :func:`run_sweep`'s; the runs get
    priorities below 0, so that tasks the caller queues with priorities ≥ 0 start first.
    ``other_cost``: the summed ``cost`` of those tasks of the caller, counted in the workers'
    shares that ``balance`` caps a batch at (:func:`weakgrid.sweep.batches.balanced`)."""
    log = log or _log.info
    cache, keys, records, todo = _plan(points, run, cache_dir, log)
    total = len(set(keys))
    log(f"{desc}: {total} runs, {total - len(todo)} already done, {len(todo)} to run"
        + (" on the cluster, beside other tasks" if todo else ""))
    tasks = _tasks(todo, run, batch, batch_size, cost, balance, other_cost)
    return _submit(feed, tasks, cost, points, keys, records, cache, desc, progress,
                   log=log, below=True, batch_cost=batch_cost)


def _submit(feed, tasks, cost, points, keys, records, cache, desc, progress, log=None,
            below=False, batch_cost=None):
    """Queue ``tasks`` on ``feed``, each with its priority, the costliest highest
    (``below``: priorities below 0)."""
    prio = _priorities([(pts[0], keys_[0]) for _, _, (pts, keys_) in tasks],
                       cost, [pts for _, _, (pts, _) in tasks], batch_cost)
    shift = -(len(tasks) + 1) if below else 0
    group = object()          # this sweep's tasks on the feed
    for pr, (fn, args, (_, keys_)) in sorted(zip(prio, tasks), key=lambda x: -x[0]):
        feed.add(group, None, fn, *args, priority=pr + shift,
                 key=f"weakgrid-run-{keys_[0]}" + (f"-{len(keys_)}" if len(keys_) > 1 else ""))
    return PendingSweep(points, keys, records, cache, feed, group, desc, progress,
                        log or _log.info)


class PendingSweep:
    """The runs of a sweep queued on a cluster's :class:`~weakgrid.sweep.feed.TaskFeed`
    (:func:`submit_sweep`): the records already cached, and the feed's group of the others."""

    def __init__(self, points, keys, records, cache, feed, group, desc, progress, log):
        self.points, self.keys, self.records, self.cache = points, keys, records, cache
        self.feed, self.group, self.desc, self.progress, self.log = feed, group, desc, \
            progress, log

    def _keep(self, res) -> bool:
        key = res["record"]["key"]
        if key in self.records:
            return False
        self.records[key] = _store(self.cache, res)
        return True

    def store_finished(self) -> int:
        """Store the runs already finished into the cache without waiting for the others
        (a caller interrupted before :meth:`collect` loses no finished run); returns how
        many were stored."""
        return sum(self._keep(res) for _, out in self.feed.ended(self.group)
                   for res in _results(out))

    def collect(self, table_path=None) -> pd.DataFrame:
        """Wait for every run, store each in the cache as it arrives and return the
        sweep's table (written to ``table_path`` as Parquet, atomically); raises
        :class:`SweepInterrupted` on SIGINT/SIGTERM, after the finished runs are cached."""
        total = len(set(self.keys))
        bar = _progress(total, len(self.records), self.progress, self.desc)
        try:
            with _sigterm_as_interrupt():
                try:
                    for _, out in self.feed.take(self.group):
                        bar.update(sum(self._keep(res) for res in _results(out)))
                except BaseException:
                    self.store_finished()
                    self.feed.cancel()
                    raise
        except KeyboardInterrupt:
            bar.close()
            exc = SweepInterrupted(len(self.records), total, self.cache.folder)
            self.log(str(exc))
            raise exc from None
        bar.close()
        return _table(self.points, self.keys, self.records, table_path)
