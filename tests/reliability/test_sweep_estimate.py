"""Long work: `weakgrid sweep` estimates the time and memory of the runs still to do before
any of them starts, refuses a sweep beyond the limits (30 min, 4 GiB or half the available
memory, ``WEAKGRID_MAX_GIB``) with the number of runs and the fix, unless ``--force``, and
counts cached runs as free.

The refused sweeps are far beyond the limits on any machine (10⁸–10⁹ integration steps),
so the verdicts do not depend on the measured speed; the one sweep that runs has two runs of
0.3 s.
"""

from __future__ import annotations

import re
from importlib import resources
from pathlib import Path

import pandas as pd
import pytest

STUDY = Path(str(resources.files("weakgrid") / "data" / "studies" / "case1-weak-grid.toml"))

AXIS = '"upqc.rating" = [0.1, 0.15, 0.3, 0.6, 1.0]'
T_END = "t_end = 2.0\ndesign_load"
RATINGS = [round(0.1 + 0.02 * k, 2) for k in range(30)]     # 30 ratings, 0.15 not among them


def _study(ws, *edits) -> str:
    """A copy of case1-weak-grid with the first occurrence of each ``old`` replaced."""
    text = STUDY.read_text()
    for old, new in edits:
        assert old in text, old
        text = text.replace(old, new, 1)
    p = ws.root / "big-study.toml"
    p.write_text(text)
    return p


def _refused(ws, cli, argv, runs):
    ws.snapshot()
    out = ws.root / "sw"
    code, stdout, err = cli(argv + ["-o", out])
    assert code == 2, stdout + err
    assert f"{runs} runs to do" in err, err
    assert "Fix: fewer points on [sweep.axes]" in err and "--force" in err, err
    assert not out.exists(), "the refused sweep wrote its output folder"
    ws.check_untouched()
    return stdout, err


def test_huge_sweep_is_refused_before_any_run(ws, cli):
    """540 runs of 6000 s (≈ 6·10⁸ steps; batched, the runs' steps cost ≈ 0.06 ms each: ≈ 10
    CPU-h — 600-s runs were close enough to the limits to run on a fast machine once batches
    were counted): refused with the count, the limits and the fix."""
    study = _study(ws, (AXIS, f'"upqc.rating" = {RATINGS}'), (T_END, "t_end = 6000.0\ndesign_load"))
    stdout, err = _refused(ws, cli, ["sweep", study], 540)
    assert re.search(r"sweep: 540 runs \(0 cached\), ≈ [\d.]+ CPU-h", stdout), stdout
    assert "limits 30 min" in err and "more workers" in err and "--quick" in err, err
    assert '"upqc.rating", has 30' in err, err


def test_sweep_too_large_to_list_is_counted_and_refused(ws, cli):
    """28 800 runs are counted from the axes (not listed one by one) and refused."""
    xf = [round(0.05 + 0.01 * k, 2) for k in range(40)]
    ratings = [round(0.1 + 0.02 * k, 2) for k in range(40)]
    study = _study(ws, (AXIS, f'"upqc.rating" = {ratings}\n"scenarios.c1-high-conv.events.0.xf"'
                              f' = {xf}'), (T_END, "t_end = 60.0\ndesign_load"))
    stdout, _ = _refused(ws, cli, ["sweep", study, "--workers", "2"], 28800)
    assert "28800 runs (too many to list" in stdout, stdout


SMALL = ('"upqc.rating" = [0.1, 0.3]',
         ('"scenarios.c1-high-conv.events.0.t_off" = [0.22, 0.25, 0.30]',
          '"scenarios.c1-high-conv.events.0.t_off" = [0.25]'),
         ('"scenarios.c1-high-conv.load" = ["high", "low"]\n\n',
          '"scenarios.c1-high-conv.load" = ["high"]\n\n'),
         ('controllers = ["hji", "nonlinear-29", "hji-bounded"]', 'controllers = ["nonlinear-29"]'),
         (T_END, "t_end = 0.3\ndesign_load"))


def test_force_runs_and_cached_runs_are_free(ws, cli, monkeypatch):
    """Under a tiny memory limit a 2-run sweep is refused; --force runs it (the estimate line
    first); the same command again finds both runs cached: nothing to run, not refused."""
    study = _study(ws, (AXIS, SMALL[0]), *SMALL[1:])
    monkeypatch.setenv("WEAKGRID_MAX_GIB", "0.001")
    argv = ["sweep", study, "--workers", "0", "--no-progress"]
    _, err = _refused(ws, cli, argv, 2)
    assert "GiB" in err and "limits" in err, err
    out = ws.root / "sw"
    code, stdout, err = cli(argv + ["-o", out, "--force"])
    assert code == 0, stdout + err
    line = stdout.splitlines()[0]
    assert re.fullmatch(r"sweep: 2 runs \(0 cached\), ≈ \d+ CPU-s, ≈ \d+ s in this process, "
                        r"≈ [\d.e+-]+ GiB \(measured on this grid: [\d.e+-]+ ms per quiet step, "
                        r"[\d.e+-]+ ms from a disturbance on; [\d.e+-]+ ms per run's quiet step "
                        r"in a batch of 2\)", line), line
    assert "2 runs, 0 failed" in stdout
    table = out / "case1-weak-grid-sweep.parquet"
    first = pd.read_parquet(table)
    code, stdout, err = cli(argv + ["-o", out])      # no --force: nothing left to cost
    assert code == 0, stdout + err
    assert stdout.splitlines()[0] == "sweep: 2 runs (2 cached), nothing to run", stdout
    assert "2 runs, 0 failed" in stdout
    pd.testing.assert_frame_equal(pd.read_parquet(table), first)


def test_estimate_counts_steps_and_cached_runs(ws, tmp_path):
    """The API: steps = Σ t_end / dt of the runs to do (dt = the study's step × dt factor),
    and a cached run is not counted."""
    from weakgrid.study.studyfile import load_study
    from weakgrid.study.sweep import run_point, sweep_points
    from weakgrid.study.sweep_estimate import estimate_sweep
    from weakgrid.sweep import ResultCache, run_key

    st = load_study(_study(ws, (AXIS, SMALL[0]), *SMALL[1:]))
    dt = st.data["design"]["T"]
    est = estimate_sweep(st, tmp_path / "cache", workers=0)
    assert (est.n_runs, est.n_cached) == (2, 0)
    assert est.steps == pytest.approx(2 * 0.3 / dt, abs=4)
    assert est.per_step_s > 0 and est.per_run_s >= 0
    # batched (the default): the two runs step together, a batched step costs batch_step_s
    assert est.batch == 2 and est.cpu_s >= est.steps / 2 * est.batch_step_s
    one = estimate_sweep(st, tmp_path / "cache", workers=0, batched=False)
    assert one.batch == 1 and one.cpu_s >= one.steps * one.per_step_s
    assert not (tmp_path / "cache").exists()
    pts = sweep_points(st)
    k = run_key(pts[0].inputs, run_point)
    ResultCache(tmp_path / "cache").put({"key": k, "status": "ok", "metrics": {}})
    est2 = estimate_sweep(st, tmp_path / "cache", workers=0)
    assert (est2.n_runs, est2.n_cached) == (2, 1)
    assert est2.steps == pytest.approx(est.steps / 2, abs=1)


def test_bounded_trainings_are_estimated_with_their_own_basis():
    """An hji-bounded training fits the problem's [basis] bounded (12 terms for case 1, the
    paper's basis 8): the estimate prices it with that basis, the unbounded HJI with its own."""
    from weakgrid.study.studyfile import load_study
    from weakgrid.study.sweep import sweep_points
    from weakgrid.study.sweep_estimate import _training, _training_key, probe

    st = load_study("case1-weak-grid")
    pts = sweep_points(st, quick=True)
    keys = {_training_key(p.inputs) for p in pts} - {None}
    assert {k.split(":")[0] for k in keys} == {"hji", "hji-bounded"}
    pr = probe(pts[0].inputs)
    assert "× 12 basis terms" in pr["train_bounded"].what and "× 8 basis terms" in pr["train"].what
    assert pr["train_bounded"].seconds > pr["train"].seconds
    for k in keys:
        want = pr["train_bounded"] if k.startswith("hji-bounded:") else pr["train"]
        assert _training(pr, k) is want


def _fake_probe(calls, transient=(1e-3, 1e-4)):
    """A probe with round numbers: a quiet step 1 ms, a batch of ``b`` runs 1 ms + 0.1 ms per
    run beyond the first; a step of the transient ``transient[0]``, in a batch
    ``transient[0] + transient[1]`` per run beyond the first; free set-up and trainings, 10⁵
    variables (their trajectories outweigh the process's own memory)."""
    from types import SimpleNamespace

    free = SimpleNamespace(seconds=0.0, bytes=0.0)

    def probe(inputs, steps=(10, 40), batch=1):
        calls.append(batch)
        return {"per_step_s": 1e-3, "transient_step_s": transient[0], "per_run_s": 0.0,
                "n_vars": 10**5, "per_process_s": 0.0, "train": free, "train_bounded": free,
                "batch": batch, "batch_step_s": 1e-3 + 1e-4 * (batch - 1),
                "batch_transient_step_s": transient[0] + transient[1] * (batch - 1)}
    return probe


@pytest.mark.parametrize("workers, sizes", [(0, [12]), (2, [6, 6])])
def test_a_batched_sweep_is_costed_by_its_batches(tmp_path, monkeypatch, workers, sizes):
    """Case 1's quick sweep (12 runs of one grid): batched, it costs its batches — those the
    sweep makes, one of 12 serially, two of 6 on 2 workers — each its steps at the probed cost
    of a batched step (linear in the batch's size); one by one, 12 runs' steps (what the
    estimate of a batched sweep said before it counted batches: 14 CPU-s for 8 s)."""
    import weakgrid.study.sweep_estimate as se
    from weakgrid.study.studyfile import load_study

    calls = []
    monkeypatch.setattr(se, "probe", _fake_probe(calls))
    st = load_study("case1-weak-grid")
    scalar = se.estimate_sweep(st, tmp_path / "c", quick=True, workers=workers, batched=False)
    batched = se.estimate_sweep(st, tmp_path / "c", quick=True, workers=workers)
    assert calls == [1, max(sizes)]
    n = scalar.steps / 12                      # every run: the same steps
    assert scalar.cpu_s == pytest.approx(12 * n * 1e-3)
    assert batched.cpu_s == pytest.approx(sum(n * (1e-3 + 1e-4 * (b - 1)) for b in sizes))
    assert batched.batch == max(sizes) and scalar.batch == 1
    # a worker holds the trajectories of its batch's runs (2 × 8 bytes × variables × steps each)
    run_bytes = 2 * 8.0 * 10**5 * n
    held = (max(sizes) - 1) * run_bytes * max(workers, 1)
    assert batched.bytes - scalar.bytes == pytest.approx(held, rel=0.01)
    assert f"in a batch of {max(sizes)}" in batched.line() and "batch" not in scalar.line()


def test_the_probe_times_a_batch_of_the_run():
    """The real probe: a batch of 4 copies of the run, its quiet step at least one run's."""
    from weakgrid.study.studyfile import load_study
    from weakgrid.study.sweep import sweep_points
    from weakgrid.study.sweep_estimate import batch_step_cost, probe

    pts = sweep_points(load_study("case1-weak-grid"), quick=True)
    pr = probe(pts[0].inputs, batch=4)
    assert pr["batch"] == 4 and pr["batch_step_s"] >= pr["per_step_s"] > 0
    assert batch_step_cost(pr, 1) == pr["per_step_s"]
    assert batch_step_cost(pr, 4) == pytest.approx(pr["batch_step_s"])


def test_the_estimate_prices_the_batches_the_sweep_makes():
    """Case 2's full sweep on 2 workers: its 90 runs of one grid are more than a worker's
    share of the sweep's cost, so the sweep splits them in two batches of 45, and the
    estimate prices those batches (one mechanism: :func:`weakgrid.sweep.batches.balanced`)."""
    from weakgrid.study.batches import STUDY_BATCHES, balance_for, batch_size_for
    from weakgrid.study.studyfile import load_study
    from weakgrid.study.sweep import run_point, sweep_points
    from weakgrid.study.sweep_estimate import _batches, run_cost
    from weakgrid.sweep.engine import _tasks

    pts = sweep_points(load_study("case2-lv-microgrid"), quick=False)
    todo = {f"k{i}": p for i, p in enumerate(pts)}
    est = _batches(todo, len(pts), 2)
    tasks = _tasks([(p, k) for k, p in todo.items()], run_point, STUDY_BATCHES,
                   batch_size_for(len(pts), 2), run_cost, balance_for(2))
    assert est == [keys for _, _, (_, keys) in tasks]
    assert sorted(len(b) for b in est) == [6, 45, 45]
    assert sorted(len(b) for b in _batches(todo, len(pts), 0)) == [6, 90]   # serially: whole
    # beside other runs as costly as the sweep (reproduce's scenario runs, and case 1's maps:
    # 192 points, at most 96 a batch), a worker's share holds the 90: one batch, in the
    # estimate as on the cluster
    other = sum(run_cost(p.inputs) for p in pts)
    est = _batches(todo, 2 * len(pts), 2, other)
    tasks = _tasks([(p, k) for k, p in todo.items()], run_point, STUDY_BATCHES,
                   batch_size_for(2 * len(pts), 2), run_cost, balance_for(2), other)
    assert est == [keys for _, _, (_, keys) in tasks]
    assert sorted(len(b) for b in est) == [6, 90]


def test_the_probe_records_what_the_sweep_records():
    """A sweep without run files records its metrics' signals alone, and the probe that
    prices its memory records the same (every signal with ``signals``)."""
    from weakgrid.study.build import build_setup
    from weakgrid.study.studyfile import load_study
    from weakgrid.study.sweep import sweep_points
    from weakgrid.study.sweep_estimate import probe

    st = load_study("case1-weak-grid")
    pts = sweep_points(st, quick=True)
    lean, every = probe(pts[0].inputs), probe(dict(pts[0].inputs, signals=True))
    assert lean["n_vars"] == len(set(build_setup(st).signals.values()))
    assert every["n_vars"] > 5 * lean["n_vars"]


FIRST_CALL_S = 0.5     # an injected one-time cost (a process loading or compiling its kernels)


def _slow_first_call(fn):
    """``fn`` whose first call first sleeps :data:`FIRST_CALL_S` (as a process's first
    simulation loads or compiles the compiled kernels, weakgrid.sim.kernels: measured 0.5–1 s)."""
    import time

    calls = []

    def wrapped(*a, **k):
        if not calls:
            time.sleep(FIRST_CALL_S)
        calls.append(1)
        return fn(*a, **k)
    return wrapped


def test_the_probe_counts_a_first_call_once_per_process_not_per_run(monkeypatch):
    """A one-time cost of a process's first simulation is its own (``per_process_s``), not a
    run's fixed cost: before the untimed first steps, it entered every run's cost (the
    case-2 sweep, 96 runs that take 129 s serially, was estimated at 7.1 CPU-h and refused
    once the kernels were compiled on first call; 2026-12-03)."""
    import weakgrid.sim.integrate as integrate
    from weakgrid.study.studyfile import load_study
    from weakgrid.study.sweep import sweep_points
    from weakgrid.study.sweep_estimate import probe

    monkeypatch.setattr(integrate, "simulate", _slow_first_call(integrate.simulate))
    pts = sweep_points(load_study("case1-weak-grid"), quick=True)
    pr = probe(pts[0].inputs)
    assert pr["per_run_s"] < FIRST_CALL_S / 2, pr
    assert pr["per_step_s"] * 30 < FIRST_CALL_S / 2, pr
    assert pr["per_process_s"] >= FIRST_CALL_S


def test_a_plain_run_estimate_pays_a_first_call_before_timing(monkeypatch):
    """The plain case's probe (weakgrid simulate): its timed steps come after untimed ones,
    so a process's one-time cost is not spread over every step of the run."""
    from weakgrid.sim.integrate import Simulator
    from weakgrid.sim.run_estimate import PROBE_STEPS, run_estimate
    from weakgrid.study.build import build_setup
    from weakgrid.study.studyfile import load_study

    st = load_study("case1-weak-grid")
    setup = build_setup(st)
    monkeypatch.setattr(Simulator, "run", _slow_first_call(Simulator.run))
    dt = st.data["design"]["T"]
    est = run_estimate(setup.system, 100 * dt, dt)
    assert est.seconds < 100 * FIRST_CALL_S / PROBE_STEPS / 2, est


def test_the_probe_times_the_transient_without_the_quiet_lead_in(monkeypatch):
    """The transient is probed with the run's disturbances moved to start after LEAD_STEPS
    quiet steps (the grid is at its operating point until then, whenever they start), alone
    and in the batch: the probe never simulates case 1's 0.2 s before its fault (247 steps,
    whose jitter drowned the transient's cost when it was the difference of two long
    timings), and the moved fault keeps its duration."""
    import weakgrid.sim.batch as batch
    import weakgrid.sim.integrate as integrate
    from weakgrid.sim.events import Fault
    from weakgrid.study.studyfile import load_study
    from weakgrid.study.sweep import sweep_points
    from weakgrid.study.sweep_estimate import LEAD_STEPS, TRANSIENT_STEPS, probe

    seen = []

    def spy(fn, t_end_at, events_of):
        def wrapped(system, *a, **k):
            seen.append((a[t_end_at], events_of(a, k)))
            return fn(system, *a, **k)
        return wrapped

    monkeypatch.setattr(integrate, "simulate", spy(integrate.simulate, 0,
                                                   lambda a, k: list(k.get("events") or [])))
    monkeypatch.setattr(batch, "simulate_batch", spy(batch.simulate_batch, 1, lambda a, k: [
        e for sc in a[0] for e in sc.get("events") or []]))
    st = load_study("case1-weak-grid")
    dt = st.data["design"]["T"]
    pts = sweep_points(st, quick=True)
    pr = probe(pts[0].inputs, batch=3)
    faults = [(t_end, e) for t_end, evs in seen for e in evs if isinstance(e, Fault)]
    assert len(faults) == 1 + 3, seen          # once alone, once in the batch of 3
    for t_end, f in faults:
        assert f.t_on == pytest.approx(LEAD_STEPS * dt)
        assert f.t_off - f.t_on == pytest.approx(0.05)
        assert t_end == pytest.approx(f.t_off + TRANSIENT_STEPS * dt)
    assert max(t for t, _ in seen) < 0.2
    assert pr["batch_transient_step_s"] >= pr["batch_step_s"] > 0


def test_the_transient_of_a_batch_is_costed_at_the_batch_s_transient_step(tmp_path, monkeypatch):
    """A batch's steps from its first disturbance on cost the probe's batched transient step,
    those before it the batched quiet step (each linear in the batch's size)."""
    import weakgrid.study.sweep_estimate as se
    from weakgrid.study.studyfile import load_study

    monkeypatch.setattr(se, "probe", _fake_probe([], transient=(3e-3, 5e-4)))
    st = load_study("case1-weak-grid")
    est = se.estimate_sweep(st, tmp_path / "c", quick=True, workers=0)
    pts = se.sweep_points(st, quick=True)
    n, q = se._steps(pts[0].inputs), se._quiet_steps(pts[0].inputs)
    assert 0 < q < n and est.batch == 12
    assert est.cpu_s == pytest.approx(q * (1e-3 + 1e-4 * 11) + (n - q) * (3e-3 + 5e-4 * 11))


def test_a_batch_at_half_the_step_starts_before_the_batches_it_outlasts():
    """``reproduce``'s maps on 2 workers: case 2's 6 runs at half the step (17.7 s measured)
    start right after case 2's 90 runs, before case 1's batches of 30 (10–11 s each); ranked
    by the sum of their runs' cost alone they started last, one worker on them while the
    other idled (2026-12-07)."""
    from weakgrid.study.batches import STUDY_BATCHES, balance_for, batch_size_for
    from weakgrid.study.studyfile import load_study
    from weakgrid.study.sweep import run_point, sweep_points
    from weakgrid.study.sweep_estimate import batch_cost, run_cost
    from weakgrid.sweep.engine import _priorities, _tasks

    pts = [p for name in ("case1-weak-grid", "case2-lv-microgrid")
           for p in sweep_points(load_study(name), quick=False)]
    # the scenario runs beside them: about 0.4 of the maps' cost in reproduce (any amount that
    # keeps case 2's 90 one batch gives this order)
    other = 0.4 * sum(run_cost(p.inputs) for p in pts)
    tasks = _tasks([(p, f"k{i}") for i, p in enumerate(pts)], run_point, STUDY_BATCHES,
                   batch_size_for(len(pts), 2), run_cost, balance_for(2), other)
    members = [m for _, _, (m, _) in tasks]

    def order(bc):
        prio = _priorities([(m[0], None) for m in members], run_cost, members, bc)
        return [(members[i][0].inputs["study"]["study"]["name"][:5], len(members[i]),
                 members[i][0].inputs["dt_factor"])
                for i in sorted(range(len(members)), key=lambda i: -prio[i])]

    assert order(batch_cost) == [("case2", 90, 1.0), ("case2", 6, 0.5)] + \
        [("case1", 30, 1.0)] * 3 + [("case1", 6, 0.5)]
    assert order(None).index(("case2", 6, 0.5)) > order(None).index(("case1", 30, 1.0))
