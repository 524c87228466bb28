"""The sweep engine: axes, cache keys, failures as rows, resume, Dask clusters."""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import textwrap
import time

import cloudpickle
import pandas as pd
import pytest

from weakgrid.game.errors import ParameterError
from weakgrid.sweep import Axis, expand, get_path, run_key, run_sweep, set_path


def _sigint_default():
    """In the child: Ctrl-C acts, even when this test runs in a background job (which starts
    its children with SIGINT ignored, so that Python would install no KeyboardInterrupt)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)

cloudpickle.register_pickle_by_value(sys.modules[__name__])

BASE = {"upqc": {"rating": 0.15, "structure": "conventional"},
        "scenarios": [{"fault": {"duration": 0.05, "x": 0.1}}], "load": "high"}


def toy_run(inputs):
    """A deterministic 'simulation': fails for a negative rating."""
    r = inputs["upqc"]["rating"]
    d = inputs["scenarios"][0]["fault"]["duration"]
    if r < 0:
        raise ValueError(f"rating {r} < 0")
    if r == 0:
        return {"status": "failed", "failure": "loss of synchronism at t = 1.2 s", "peak": math.nan}
    return {"peak": r * d, "cost": math.sin(r) / (1 + d), "label": inputs["load"]}


def _tab(df):
    return df.drop(columns=["wall_s"]).reset_index(drop=True)


def test_expand_product_and_points():
    pts = expand(BASE, {"upqc.rating": [0.1, 0.3], "scenarios.0.fault.duration": [0.05, 0.1, 0.2]})
    assert len(pts) == 6
    assert pts[0].params == {"upqc.rating": 0.1, "scenarios.0.fault.duration": 0.05}
    assert pts[-1].inputs["scenarios"][0]["fault"]["duration"] == 0.2
    assert BASE["upqc"]["rating"] == 0.15  # the base is not modified
    pts = expand(BASE, [Axis("upqc.rating", [0.1, 0.3]), Axis("load", ["high", "low"])],
                 mode="points")
    assert [p.params for p in pts] == [{"upqc.rating": 0.1, "load": "high"},
                                       {"upqc.rating": 0.3, "load": "low"}]


@pytest.mark.parametrize("axes, mode, word", [
    ({"upqc.ratng": [0.1]}, "product", "ratng"),
    ({"upqc.rating": []}, "product", "non-empty"),
    ({"upqc.rating": [float("nan")]}, "product", "finite"),
    ({"upqc.rating": [0.1], "load": ["a", "b"]}, "points", "same number"),
    ({"upqc.rating": [0.1]}, "zip", "product"),
    ({"scenarios.3.fault": [1]}, "product", "indices 0..0"),
])
def test_bad_axes_name_the_field(axes, mode, word):
    with pytest.raises(ParameterError) as ei:
        expand(BASE, axes, mode=mode)
    assert word in str(ei.value)


def test_paths():
    d = {"a": {"b": [1, {"c": 2}]}}
    assert get_path(d, "a.b.1.c") == 2
    set_path(d, "a.b.0", 5)
    assert d["a"]["b"][0] == 5


def test_key_depends_on_input_and_function():
    a = run_key({"x": 1.0, "y": [1, 2]}, toy_run)
    assert a == run_key({"y": [1, 2], "x": 1.0}, toy_run)  # key order does not matter
    assert a != run_key({"x": 1.0 + 1e-12, "y": [1, 2]}, toy_run)
    assert a != run_key({"x": 1.0, "y": [1, 2]}, _tab)


def test_serial_sweep_failures_are_rows_and_cache_is_reused(tmp_path):
    pts = expand(BASE, {"upqc.rating": [-0.1, 0.0, 0.1, 0.3]})
    t1 = run_sweep(pts, toy_run, cache_dir=tmp_path / "c", workers=0, progress=False,
                   table_path=tmp_path / "t.parquet")
    assert list(t1["status"]) == ["failed", "failed", "ok", "ok"]
    assert "ValueError: rating -0.1 < 0" in t1["failure"][0]
    assert "loss of synchronism" in t1["failure"][1]
    assert t1["peak"][2] == pytest.approx(0.1 * 0.05)
    assert math.isnan(t1["peak"][1])
    pd.testing.assert_frame_equal(_tab(pd.read_parquet(tmp_path / "t.parquet")), _tab(t1))
    # a repeated sweep runs nothing: the cached records (and their wall times) come back
    mtimes = {p: p.stat().st_mtime_ns for p in (tmp_path / "c").glob("*.json")}
    t2 = run_sweep(pts, toy_run, cache_dir=tmp_path / "c", workers=0, progress=False)
    pd.testing.assert_frame_equal(t1, t2)
    assert mtimes == {p: p.stat().st_mtime_ns for p in (tmp_path / "c").glob("*.json")}


def test_local_cluster_and_scheduler_address_give_the_default_table(tmp_path):
    from distributed import LocalCluster

    pts = expand(BASE, {"upqc.rating": [-0.1, 0.1, 0.2], "scenarios.0.fault.duration": [0.05, 0.1]})
    serial = run_sweep(pts, toy_run, cache_dir=tmp_path / "s", workers=0, progress=False)
    local = run_sweep(pts, toy_run, cache_dir=tmp_path / "l", workers=2, progress=False)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster:
        remote = run_sweep(pts, toy_run, cache_dir=tmp_path / "r", scheduler=cluster.scheduler_address,
                           progress=False)
    for t in (local, remote):
        pd.testing.assert_frame_equal(_tab(t), _tab(serial))


def stamped_run(inputs):
    """A run that says when it started (one worker: runs start in the order it takes them)."""
    t = time.perf_counter()
    time.sleep(0.05)
    return {"started": t, "cpu_busy": sum(i * i for i in range(200_000))}


def test_costliest_runs_start_first_on_a_cluster(tmp_path):
    from weakgrid.sweep import open_client

    ratings = [0.3, 0.1, 0.5, 0.2, 0.4, 0.05]
    pts = expand(BASE, {"upqc.rating": ratings})
    with open_client(None, 1) as client:
        t = run_sweep(pts, stamped_run, cache_dir=tmp_path / "c", client=client,
                      progress=False, cost=lambda inp: inp["upqc"]["rating"])
    assert list(t["upqc.rating"]) == ratings       # the table keeps the sweep's order
    started = t.sort_values("started")["upqc.rating"].tolist()
    assert started == sorted(ratings, reverse=True)


def test_local_cluster_workers_take_one_run_at_a_time_without_the_profiler(tmp_path):
    """Dask's settings for CPU-bound runs reach the scheduler and the worker processes."""
    import dask

    from weakgrid.sweep import open_client

    def worker_config():
        return [dask.config.get("distributed.worker.profile.enabled"),
                dask.config.get("distributed.admin.tick.interval")]

    with open_client(None, 2) as client:
        assert client.run_on_scheduler(lambda dask_scheduler: dask_scheduler.WORKER_SATURATION) \
            == 1.0
        assert list(client.run(worker_config).values()) == [[False, "1s"]] * 2
        # the worker's other threads: the event loop and its periodic callbacks only
        assert all(client.run(lambda dask_worker: "profile" not in
                              dask_worker.periodic_callbacks).values())
    assert dask.config.get("distributed.worker.profile.enabled") is True  # not left set here


def test_record_keeps_the_cpu_time_of_the_run(tmp_path):
    from weakgrid.sweep import ResultCache

    pts = expand(BASE, {"upqc.rating": [0.1]})
    t = run_sweep(pts, stamped_run, cache_dir=tmp_path / "c", workers=0, progress=False)
    rec = ResultCache(tmp_path / "c").get(t["key"][0])
    assert 0 < rec["cpu_s"] < rec["wall_s"]        # the sleep counts in the wall time only
    assert rec["wall_s"] >= 0.05


SCRIPT = textwrap.dedent('''
    import sys, time, os
    from weakgrid.sweep import expand, run_sweep, SweepInterrupted

    LOG = sys.argv[2]
    N = 16

    def slow(inputs):
        time.sleep(1.0)
        with open(LOG, "a") as fh:
            fh.write(f"{inputs['i']}\\n")
        return {"sq": inputs["i"] ** 2}

    if __name__ == "__main__":
        pts = expand({"i": 0}, {"i": list(range(N))})
        try:
            t = run_sweep(pts, slow, cache_dir=sys.argv[1], workers=2, progress=False,
                          table_path=os.path.join(sys.argv[1], "table.parquet"), log=print)
        except SweepInterrupted as exc:
            print("STOPPED", exc.done, flush=True)
            sys.exit(130)
        print("DONE", len(t), flush=True)
''')


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM])
def test_interrupted_sweep_resumes_without_rerunning(tmp_path, sig):
    script = tmp_path / "s.py"
    script.write_text(SCRIPT)
    cache, log = tmp_path / "cache", tmp_path / "log.txt"
    env = dict(os.environ, PYTHONUNBUFFERED="1")
    p = subprocess.Popen([sys.executable, str(script), str(cache), str(log)],
                         preexec_fn=_sigint_default, env=env,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    t0 = time.time()
    while len(list(cache.glob("*.json"))) < 2 and time.time() - t0 < 120:
        time.sleep(0.05)
    done_before = {p.stem for p in cache.glob("*.json")}
    p.send_signal(sig)
    out, err = p.communicate(timeout=120)
    assert p.returncode == 130, (out, err)
    assert "STOPPED" in out and "Traceback" not in err
    done_at_stop = {p.stem for p in cache.glob("*.json")}
    assert done_before <= done_at_stop and len(done_at_stop) < 16
    ran_first = log.read_text().split()
    p2 = subprocess.run([sys.executable, str(script), str(cache), str(log)], env=env,
                        capture_output=True, text=True, timeout=180)
    assert p2.returncode == 0, p2.stderr
    assert "DONE 16" in p2.stdout
    assert f"{len(done_at_stop)} already done" in p2.stdout
    ran = log.read_text().split()
    # each run finished before the stop ran once; only the others ran in the second sweep
    ran_second = ran[len(ran_first):]
    assert len(ran_second) == 16 - len(done_at_stop)
    table = pd.read_parquet(cache / "table.parquet")
    assert list(table["sq"]) == [i * i for i in range(16)]
    assert (table["status"] == "ok").all()


def test_submitted_sweep_yields_to_the_callers_tasks_and_keeps_what_finished(tmp_path):
    """``submit_sweep`` returns at once with the runs queued on the cluster's feed at
    priorities below the caller's own tasks (``weakgrid run``/``reproduce``: the scenario
    runs first, the maps' runs filling the workers as they end); the runs finished before an
    interruption are kept (``store_finished``), and the table is the one ``run_sweep``
    gives."""
    from weakgrid.sweep import ResultCache, TaskFeed, open_client, submit_sweep

    ratings = [0.3, 0.1, 0.5, 0.2]
    pts = expand(BASE, {"upqc.rating": ratings})
    serial = run_sweep(pts, stamped_run, cache_dir=tmp_path / "s", workers=0, progress=False)
    said = []
    with open_client(None, 1) as client:
        feed = TaskFeed(client)
        feed.add("mine", "first", stamped_run, {}, priority=0)     # the worker's first
        pending = submit_sweep(pts, stamped_run, cache_dir=tmp_path / "c", feed=feed,
                               progress=False, log=said.append,
                               cost=lambda inp: inp["upqc"]["rating"])
        feed.add("mine", "mine", stamped_run, {"x": 1}, priority=0)
        assert said == ["sweep: 4 runs, 0 already done, 4 to run on the cluster, beside other "
                        "tasks"]
        mine = dict(feed.take("mine"))            # the sweep's first run starts after these
        kept, t0 = 0, time.monotonic()
        while kept == 0 and time.monotonic() - t0 < 30:
            time.sleep(0.05)
            kept = pending.store_finished()       # kept without collect (an interrupt)
        # at least the first (two, if the poll came late: the suite runs beside this cluster)
        assert kept >= 1
        assert len(list(ResultCache(tmp_path / "c").folder.glob("*.json"))) == kept
        table = pending.collect()
    assert mine["mine"]["started"] < table["started"].min()   # the caller's task first
    assert table.sort_values("started")["upqc.rating"].tolist() == sorted(ratings, reverse=True)
    assert len(list(ResultCache(tmp_path / "c").folder.glob("*.json"))) == 4
    pd.testing.assert_frame_equal(_tab(table).drop(columns=["started", "cpu_busy"]),
                                  _tab(serial).drop(columns=["started", "cpu_busy"]))
    again = []
    run_sweep(pts, stamped_run, cache_dir=tmp_path / "c", workers=0, progress=False,
              log=again.append)
    assert again[0] == "sweep: 4 runs, 4 already done, 0 to run"


def slept(seconds):
    """A task that sleeps ``seconds`` and says when it started."""
    t = time.time()
    time.sleep(seconds)
    return t


def test_free_workers_take_the_highest_priority_task_left(tmp_path):
    """A cluster fed from the client (``TaskFeed``) starts its tasks in the order of their
    priorities whatever their lengths: on 2 workers, a long first task and short others, the
    short ones start one after the other in the order of their priorities, all while the long
    one runs. Dask alone gives the first tasks of a small group to a worker at submission, so
    a short task of high priority waited there behind the long one while the other worker ran
    the rest.

    Only the order of the short ones is checked against each other: the long one and the first
    short one start together on the two free threads, and a worker slow to start its task (CI
    runs the suite beside this cluster) let the second short one start before the long one
    (measured: the order 1, 2, 0, ...)."""
    from weakgrid.sweep import TaskFeed, open_client

    long = 2.0
    lengths = [long, 0.1, 0.1, 0.1, 0.1, 0.1]
    with open_client(None, 2) as client:
        client.run(slept, 0.0)      # each worker has the function before the timed tasks
        feed = TaskFeed(client)
        for i, s in enumerate(lengths):
            feed.add("g", i, slept, s, priority=len(lengths) - i, key=f"slept-{i}")
        started = dict(feed.take("g"))
    shorts = sorted(range(1, len(lengths)), key=started.get)
    assert shorts == list(range(1, len(lengths)))     # one after the other, by priority
    assert max(started[i] for i in shorts) < started[0] + long   # beside the long one


def test_sweep_on_a_client_that_is_not_the_default(tmp_path):
    """A sweep runs on the client it is given, also when that client is not Dask's default
    one (the feed waits on the given client's event loop)."""
    from distributed import Client, LocalCluster

    pts = expand(BASE, {"upqc.rating": [0.1, 0.2]})
    serial = run_sweep(pts, toy_run, cache_dir=tmp_path / "s", workers=0, progress=False)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                      dashboard_address=None) as cluster, \
            Client(cluster, set_as_default=False) as client:
        t = run_sweep(pts, toy_run, cache_dir=tmp_path / "c", client=client, progress=False)
    pd.testing.assert_frame_equal(_tab(t), _tab(serial))
