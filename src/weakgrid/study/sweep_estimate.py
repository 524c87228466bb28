"""What a study's sweep will cost, before it starts: runs, CPU and wall time, memory.

The time is measured, not assumed: a short probe of the study's own grid (the first run
still to do, with its integration step and tolerance, the controller idle) is timed in this
process. First, untimed, what a process pays once (``per_process_s``): its first build of the
grid (imports, caches) and its first steps (the compiled kernels loaded or compiled,
:mod:`weakgrid.sim.kernels`: 0.5–1 s). Then, each the least of :data:`PROBE_REPEAT` timings
(this machine's jitter is milliseconds, as long as these), two simulations of 10 and 40 steps
at the operating point (their difference gives the cost of a quiet step, the rest with the
grid's second build the fixed cost of a run), and one through the run's disturbances, moved
to start after :data:`LEAD_STEPS` quiet steps, and 60 steps beyond (the cost of a step of the
transient: more Newton iterations and Jacobians). Every remaining run then costs ``fixed +
quiet steps × quiet cost + steps from its first disturbance on × transient cost``. A batched
sweep (the default: the runs of one grid advance together, :mod:`weakgrid.study.batches`) is
costed by its batches, grouped as the sweep will group them: the probe also times the quiet
steps and the transient of its largest batch (up to :data:`PROBE_BATCH` copies of the probed
run, :func:`weakgrid.sim.batch.simulate_batch`), and a batch of ``B`` runs costs each run's
fixed cost plus its quiet steps and its transient at the costs of a batched step, each
interpolated linearly in ``B`` between the probe's one run and its batch (a batched step of
``B`` runs costs far less than ``B`` steps); each worker process pays its ``per_process_s``
once; the HJI trainings (once per design point and worker process) come from
:func:`weakgrid.game.estimate.training_estimate`. Rough (±2×, low: the probe's controller is
idle, a trained policy's evaluation at every sample is not in it): on the development
machine (2026-12-03, ``benchmarks/bench_estimate.py``) case 2's sweep, 96 runs serially,
estimated at 80–83 CPU-s took 143 CPU-s; case 1's, 96 runs on 2 workers, estimated at 27–32 s
(49–61 CPU-s) took 54 s (89 CPU-s). Before the untimed first steps and the repeated timings,
the same case-2 sweep was estimated anywhere from 5 CPU-min to 7.1 CPU-h from one call to the
next (and refused): a process's first call of a compiled kernel fell in the timed quiet
steps, and a transient timed from 0 s drowned in the jitter of 3 000 quiet steps. Runs
already in the cache cost nothing. The wall time divides the CPU time by the workers, at
most one per core; other work on the machine slows it down.

The memory: one worker process holds what this process holds after the probe (the
package, the grid; its resident size is measured), plus the trajectories of its longest
run (steps × recorded variables × 8 bytes, twice: while they grow and as the final array;
the signals its metrics read, every signal with ``signals``) times the runs of its largest
batch, plus a
training's working memory; this process holds the table (a row per run) and, with
``signals``, one run's signals in transit.
"""

from __future__ import annotations

import math
import os
import time
from dataclasses import dataclass, replace
from types import SimpleNamespace

import numpy as np

from ..game.errors import ParameterError
from ..game.estimate import GiB, available_memory, format_duration, proc_kib, training_estimate
from ..sweep import canonical_json, run_key
from ..sweep.cache import ResultCache
from .studyfile import event_end, get_path, study_from_dict
from .sweep import _NOT_DESIGN, _axes, run_point, sweep_points

__all__ = ["SweepEstimate", "batch_cost", "check_sweep", "estimate_sweep", "planned_runs",
           "probe", "run_cost"]

MAX_SECONDS = 1800.0          # the limits of a training (weakgrid.game.estimate.Estimate.check)
PROBE_STEPS = (10, 40)
TRANSIENT_STEPS = 60          # steps probed after the last disturbance
CLUSTER_START_S = 2.0         # a local Dask cluster of 2 workers up and importing weakgrid
PROBE_BATCH = 32              # the largest batch the probe times (larger ones: extrapolated)
PROBE_REPEAT = 2              # each timing the least of this many (the machine's jitter)
WARM_STEPS = 2                # untimed steps first (a process's first steps load its kernels)
LEAD_STEPS = 5                # quiet steps before the probed disturbance
MAX_LISTED = 20000            # runs listed (and looked up in the cache) one by one


@dataclass(frozen=True)
class SweepEstimate:
    """The cost of a sweep's remaining runs.

    Attributes
    ----------
    n_runs, n_cached : int
        Distinct runs of the sweep, and those already in the cache.
    steps : float
        Integration steps of the remaining runs.
    per_step_s, per_run_s : float
        Measured cost of one step and fixed cost of one run [s] (0 if nothing to run).
    n_trainings : int
        HJI trainings at most (once per design point and worker process).
    cpu_s : float
        CPU time of the remaining runs and trainings [s].
    workers : int or None
        Processes working in parallel (None: an existing cluster of unknown size).
    wall_s : float or None
        Wall time on ``workers`` (None for an existing cluster).
    bytes : float
        Memory of this process and its workers together [B].
    note : str
        Why the time is unknown (the probe failed; the runs will report it), else "".
    unlisted : str
        Set when the sweep was too large to list (runs counted, cache not consulted).
    transient_step_s : float
        Measured cost of a step from the first disturbance on [s].
    batch : int
        The largest batch of the sweep (1: the runs one by one).
    batch_step_s : float
        Cost of one quiet step of a batch of ``batch`` runs [s] (all of them; measured up to
        :data:`PROBE_BATCH` runs, extrapolated beyond).
    """

    n_runs: int
    n_cached: int
    steps: float
    per_step_s: float
    per_run_s: float
    n_trainings: int
    cpu_s: float
    workers: int | None
    wall_s: float | None
    bytes: float
    note: str = ""
    unlisted: str = ""
    transient_step_s: float = math.nan
    batch: int = 1
    batch_step_s: float = math.nan

    @property
    def n_todo(self) -> int:
        return self.n_runs - self.n_cached

    def line(self, label: str = "sweep") -> str:
        """One line, e.g. ``sweep: 192 runs (24 cached), ≈ 14 CPU-min, ≈ 7 min on 2 workers,
        ≈ 0.3 GiB (…)``."""
        head = f"{label}: {self.n_runs} runs " + (f"({self.unlisted})" if self.unlisted
                                                 else f"({self.n_cached} cached)")
        if not self.n_todo:
            return f"{head}, nothing to run"
        if self.note:
            return f"{head}, time unknown ({self.note})"
        if self.workers is None:
            where = "on the given cluster"
        else:
            on = "in this process" if self.workers == 0 else \
                f"on {self.workers} worker{'s' if self.workers != 1 else ''}"
            where = f"≈ {_duration(self.wall_s)} {on}"
        batched = "" if self.batch <= 1 else \
            (f"; {self.batch_step_s / self.batch * 1e3:.2g} ms per run's quiet step in a "
             f"batch of {self.batch}")
        return (f"{head}, ≈ {_cpu(self.cpu_s)}, {where}, ≈ {self.bytes / GiB:.2g} GiB "
                f"(measured on this grid: {self.per_step_s * 1e3:.2g} ms per quiet step, "
                f"{self.transient_step_s * 1e3:.2g} ms from a disturbance on{batched})")


def _duration(s: float) -> str:
    return format_duration(s)


def _cpu(s: float) -> str:
    return format_duration(s, cpu=True)


def _rss() -> float:
    """Resident memory of this process [B] (0 where unknown)."""
    return proc_kib("/proc/self/status", "VmRSS", 0.0)


def _scenario(d: dict, sid: str) -> dict:
    return get_path(d, f"scenarios.{sid}")


def _steps(inputs: dict) -> float:
    """Integration steps of one run: simulated time / step (as :func:`sim_settings`)."""
    d = inputs["study"]
    t_end = inputs.get("t_end") or _scenario(d, inputs["scenario"])["t_end"]
    sim = d.get("simulation") or {}
    dt = float(sim.get("dt") or d["design"]["T"]) * float(inputs.get("dt_factor") or 1.0)
    return math.ceil(float(t_end) / dt)


def _event_window(events):
    """(start of the first, end of the last) disturbance [s], or (None, None)."""
    starts = [float(e.get("t_on", e.get("t", 0.0))) for e in events]
    ends = [s if event_end(e) is None else event_end(e) for s, e in zip(starts, events)]
    return (min(starts), max(ends)) if starts else (None, None)


def _quiet_steps(inputs: dict) -> int:
    """Steps of a run before its first disturbance (at the operating point)."""
    d = inputs["study"]
    first, _ = _event_window(_scenario(d, inputs["scenario"]).get("events") or [])
    if first is None:
        return _steps(inputs)
    sim = d.get("simulation") or {}
    dt = float(sim.get("dt") or d["design"]["T"]) * float(inputs.get("dt_factor") or 1.0)
    return min(math.floor(first / dt), _steps(inputs))


FAULT_STEP_WEIGHT = 10.0      # a step with a disturbance on, in quiet steps (see run_cost)
BATCH_STEP_WEIGHT = 30.0      # a batched step's own cost, in quiet steps (see batch_cost)


def run_cost(inputs: dict) -> float:
    """A run's cost before it runs, in quiet steps: to start a sweep's costliest runs first
    (:func:`weakgrid.sweep.run_sweep`'s ``cost``), not to predict a time.

    Its steps (those before the first disturbance count 1, those from it on 3: the transient,
    as :func:`probe` measures), those while a disturbance is on counting
    :data:`FAULT_STEP_WEIGHT` in all. Measured on case 1 ((29), 1.0-s runs, eight UPQC
    ratings): 0.97, 1.04 and 1.16 s of CPU for faults of 20, 50 and 100 ms, i.e. ≈ 2.4 ms
    more per ms of fault, ≈ 6.5 quiet steps more per step of fault beyond a transient step's 3
    (the fault also lengthens the swing after it). A halved step doubles the steps.
    """
    d = inputs["study"]
    n, quiet = _steps(inputs), _quiet_steps(inputs)
    sim = d.get("simulation") or {}
    dt = float(sim.get("dt") or d["design"]["T"]) * float(inputs.get("dt_factor") or 1.0)
    t_end = n * dt
    on = 0.0
    for e in _scenario(d, inputs["scenario"]).get("events") or []:
        if event_end(e) is not None:
            t_on = float(e.get("t_on", e.get("t", 0.0)))
            on += max(min(event_end(e), t_end) - min(t_on, t_end), 0.0)
    return quiet + 3.0 * (n - quiet) + (FAULT_STEP_WEIGHT - 3.0) * on / dt


def batch_cost(runs: list) -> float:
    """A batch's cost before it runs, in :func:`run_cost`'s unit: to start a sweep's costliest
    batches first (:func:`weakgrid.sweep.run_sweep`'s ``batch_cost``).

    Its runs' :func:`run_cost`, and :data:`BATCH_STEP_WEIGHT` per step of the batch (its
    longest run's): what a batched step costs whatever its members (the controllers'
    sampling, the network's re-solve, the bookkeeping of the Newton iteration). Fitted on the
    map batches of ``reproduce`` (2026-12-07, 2 workers): case 2's 90 runs of 6 s took 47.5 s
    and its 6 at half the step 17.7 s, case 1's 30 runs of 2 s 10.3–11.0 s and its 6 at half
    the step 8.9 s — about 0.036 s per 1 000 units, and 28–30 units per batched step. By the
    sum of its runs alone, a batch of few runs at half the step ranked below batches of 30
    and started last, one worker on it while the other idled.
    """
    runs = list(runs)
    return sum(run_cost(r) for r in runs) + BATCH_STEP_WEIGHT * max(
        (_steps(r) for r in runs), default=0)


def _training_key(inputs: dict):
    """What one HJI training of this run depends on, ``"<kind>:<json>"`` (kind ``hji`` or
    ``hji-bounded``; None: the run trains nothing)."""
    from .controllers import controller_kind

    d = inputs["study"]
    kind = controller_kind(SimpleNamespace(data=d), inputs["controller"])
    if kind not in ("hji", "hji-bounded"):
        return None
    sc = _scenario(d, inputs["scenario"])
    dload = inputs.get("design_load") or sc.get("design_load") or sc["load"]
    design = {k: v for k, v in d.items() if k not in _NOT_DESIGN}
    design["upqc"] = {k: v for k, v in design["upqc"].items() if k != "rating"}
    extra = None
    if kind == "hji-bounded":
        opts = d["controllers"].get(inputs["controller"], {})
        extra = (opts if isinstance(opts, dict) else {}).get("u_bound", d["upqc"]["rating"])
    return f"{kind}:" + canonical_json([design, dload, sc["upqc"], extra])


def _training(pr: dict, key: str):
    """The probe's estimate of the training ``key`` (:func:`_training_key`): the bounded
    basis's for an ``hji-bounded`` controller, the problem's own otherwise."""
    return pr["train_bounded"] if key.startswith("hji-bounded:") else pr["train"]


def probe(inputs: dict, steps=PROBE_STEPS, batch: int = 1) -> dict:
    """Time the study's grid of the run ``inputs`` (see the module's text).

    Returns ``per_step_s`` and ``transient_step_s`` (one run's quiet step and step of the
    transient), ``per_run_s`` (a run's fixed cost: its grid built as a worker builds it again,
    its start), ``per_process_s`` (what a process pays once: its first build of the grid, the
    simulator's first steps — compiled kernels loaded or compiled, :mod:`weakgrid.sim.kernels`),
    ``n_vars`` (variables recorded per step, as the sweep records them) and ``train`` and
    ``train_bounded`` (the :class:`~weakgrid.game.estimate.Estimate` of one HJI training,
    unbounded and rating-bounded: their bases differ); with ``batch`` > 1 also ``batch`` (at most :data:`PROBE_BATCH`),
    ``batch_step_s`` and ``batch_transient_step_s``, the cost of one quiet step and of one step
    of the transient of that many copies of the run advanced together [s].
    """
    from ..sim.batch import simulate_batch
    from ..sim.controllers import DigitalController, UPQCTarget
    from ..sim.integrate import simulate
    from .build import build_setup
    from .controllers import controller_variant, design_problem
    from .runner import (Run, _MeasureOnly, enable_windows, make_events, metric_signals,
                         sim_settings)

    st = study_from_dict(inputs["study"], source=f"sweep:{inputs['study']['study']['name']}")
    sc = next(s for s in st.scenarios() if s["id"] == inputs["scenario"])
    run = Run.of(st, sc, inputs["controller"])
    dt, tol = sim_settings(st, float(inputs.get("dt_factor") or 1.0))
    t_once = time.perf_counter()
    variant = controller_variant(st, run.controller)
    build_setup(st, run.load, run.upqc, variant)      # a process's first build: imports, caches
    t0 = time.perf_counter()
    setup = build_setup(st, run.load, run.upqc, variant)
    t_setup = time.perf_counter() - t0
    # what the sweep records: every signal with ``signals`` (its run files), else what the
    # metrics read (weakgrid.study.sweep.prepare_point)
    record = None if inputs.get("signals") else metric_signals(setup)

    def idle(**kw):     # the run's digital controller, measuring and holding zero
        return DigitalController(lambda m: np.zeros(2), T=setup.design.T, measure=setup.measure,
                                 target=UPQCTarget(setup.upqc_name) if setup.upqc_name
                                 else _MeasureOnly(), name="probe", **kw)

    batch = max(1, min(int(batch), PROBE_BATCH))

    def timed(t_end, b=1, events=None, enable=None, repeat=PROBE_REPEAT):
        """The least wall time of ``repeat`` simulations of ``b`` copies of the run [s] and
        the steps and recorded variables of one."""
        best = math.inf
        for _ in range(repeat):
            kw = {} if enable is None else {"enable": enable}
            scen = [{"controllers": [idle(**kw)], "events": events() if events else []}
                    for _ in range(b)]
            t0 = time.perf_counter()
            if b == 1:
                res = simulate(setup.system, t_end, dt=dt, tol=tol, on_failure="return",
                               record=record, **scen[0])
            else:
                res = simulate_batch(setup.system, scen, t_end, batch_size=b, dt=dt, tol=tol,
                                     record=record)[0]
            best = min(best, time.perf_counter() - t0)
        return best, int(res.stats.get("steps") or round(t_end / dt)), len(res.names)

    # a process's first steps load (or compile) what the simulator caches: not a run's cost
    timed(WARM_STEPS * dt, repeat=1)
    if batch > 1:
        timed(WARM_STEPS * dt, batch, repeat=1)
    per_process = time.perf_counter() - t_once - t_setup
    # at the operating point: the fixed cost of a run and the cost of a quiet step
    (t1, s1, _), (t2, s2, n_vars) = (timed(n * dt) for n in steps)
    per_step = (t2 - t1) / (s2 - s1) if s2 > s1 and t2 > t1 else t2 / max(s2, 1)
    fixed_sim = max(t1 - s1 * per_step, 0.0)
    per_run = t_setup + fixed_sim
    batch_step = per_step
    if batch > 1:     # the same quiet steps, ``batch`` copies of the run together
        (u1, _, _), (u2, _, _) = (timed(n * dt, batch) for n in steps)
        batch_step = max((u2 - u1) / (s2 - s1) if s2 > s1 else u2 / max(s2, 1), per_step)
        batch_fixed = max(u1 - s1 * batch_step, 0.0)
    # through the run's disturbances and TRANSIENT_STEPS beyond the last, the disturbances
    # moved to start after LEAD_STEPS quiet steps (the grid is at its operating point until
    # then whenever they start): the cost of a step of the transient (more Newton iterations
    # and Jacobians), most of a run after a fault
    transient, batch_transient = per_step, batch_step
    first, last = _event_window(run.events)
    if first is not None:
        shift = max(first - LEAD_STEPS * dt, 0.0)
        moved = replace(run, events=tuple(_shifted(e, shift) for e in run.events),
                        bypass=tuple((a - shift, b - shift) for a, b in run.bypass))
        t_probe = min(run.t_end, last + TRANSIENT_STEPS * dt) - shift
        n_quiet = math.floor((first - shift) / dt)
        enable = enable_windows(moved.bypass, t_probe)

        def moved_events():
            return make_events(setup, moved)

        # long enough to be timed once (repeated, they agreed to 1 %)
        t3, s3, _ = timed(t_probe, 1, moved_events, enable, repeat=1)
        if s3 > n_quiet:
            transient = max((t3 - fixed_sim - n_quiet * per_step) / (s3 - n_quiet), per_step)
        if batch > 1:
            u3, _, _ = timed(t_probe, batch, moved_events, enable, repeat=1)
            if s3 > n_quiet:
                batch_transient = max((u3 - batch_fixed - n_quiet * batch_step)
                                      / (s3 - n_quiet), batch_step)
    prob = design_problem(st, setup.design)
    # a rating-bounded training (hji-bounded) fits its own basis (the problem's [basis] bounded)
    bounded = prob.with_rating(float(st.data["upqc"]["rating"]))
    train, train_bounded = (training_estimate(int(p.mesh.points.shape[0]), p.basis.size,
                                              p.system.n_states) for p in (prob, bounded))
    return {"per_step_s": per_step, "transient_step_s": transient, "per_run_s": per_run,
            "per_process_s": per_process, "n_vars": n_vars, "train": train,
            "train_bounded": train_bounded, "batch": batch, "batch_step_s": batch_step,
            "batch_transient_step_s": batch_transient}


def _shifted(event: dict, shift: float) -> dict:
    """A study event ``shift`` seconds earlier (its ``t_on``, ``t_off`` and ``t``)."""
    return {k: (float(v) - shift if k in ("t_on", "t_off", "t") else v) for k, v in event.items()}


def _linear(pr: dict, size: int, one: str, many: str) -> float:
    """A cost linear in the batch's ``size`` through the probe's one run (``pr[one]``) and its
    batch (``pr[many]`` for ``pr["batch"]`` runs), never below one run's."""
    if size <= 1 or pr.get("batch", 1) <= 1:
        return pr[one] * max(size, 1)
    slope = (pr[many] - pr[one]) / (pr["batch"] - 1)
    return pr[one] + max(slope, 0.0) * (size - 1)


def batch_step_cost(pr: dict, size: int) -> float:
    """The cost of one quiet step of a batch of ``size`` runs [s]: linear in ``size`` through
    the probe's one run (``per_step_s``) and its batch (``batch_step_s`` of ``batch`` runs),
    never below one run's step."""
    return _linear(pr, size, "per_step_s", "batch_step_s")


def batch_transient_cost(pr: dict, size: int) -> float:
    """The cost of one step of the transient of a batch of ``size`` runs [s], as
    :func:`batch_step_cost` (``transient_step_s``, ``batch_transient_step_s``)."""
    return _linear(pr, size, "transient_step_s", "batch_transient_step_s")


def planned_runs(study, quick: bool = False) -> int:
    """Runs of the study's sweep counted from its axes, without listing them (the
    ``dt_check`` repetitions not included)."""
    sw = study.data["sweep"]
    axes = _axes(sw, quick)
    n = math.prod(len(v) for v in axes.values()) if sw.get("mode", "product") == "product" \
        else len(next(iter(axes.values())))
    return n * sum(len(sw.get("controllers") or _scenario(study.data, sid)["controllers"])
                   for sid in sw["scenarios"])


def _first_values(study, quick):
    """The study with every axis cut to its first value (one point per scenario and
    controller), standing for all the points of a sweep too large to list."""
    sw = dict(study.data["sweep"])
    q = dict(sw.get("quick") or {})
    key = q if quick and "axes" in q else sw
    key["axes"] = {k: list(v[:1]) for k, v in key["axes"].items()}
    if q:
        sw["quick"] = q
    sw["dt_check"] = {}
    return replace(study, data={**study.data, "sweep": sw})


def estimate_sweep(study, cache_dir, quick: bool = False, workers: int | None = None,
                   scheduler: str | None = None, points=None,
                   batched: bool = True, other_cost: float = 0.0) -> SweepEstimate:
    """Estimate the remaining runs of ``study``'s sweep (cached in ``cache_dir``).

    Nothing is written (the cache folder is not created). ``workers``/``scheduler`` as for
    :func:`weakgrid.sweep.run_sweep` (None: one worker per core; 0: serially here);
    ``batched`` as for :func:`weakgrid.study.sweep.run_study_sweep` (the runs of one grid
    together, in the batches the sweep will make; ``False``: one by one; ``other_cost``:
    the :func:`run_cost` of the other runs the same workers run beside the sweep, as
    :func:`weakgrid.sweep.submit_sweep` takes it). A sweep
    of more than :data:`MAX_LISTED` runs is not listed (that alone would take minutes): its
    runs are counted from the axes, costed like those at the axes' first values, and the
    cache is not consulted.
    """
    scale = 1.0
    if points is None and planned_runs(study, quick) > MAX_LISTED:
        pts = sweep_points(_first_values(study, quick), quick)
        scale = planned_runs(study, quick) / len(pts)
    else:
        pts = sweep_points(study, quick) if points is None else points
    cache = ResultCache(cache_dir, create=False)
    todo: dict[str, object] = {}
    keys = set()
    for p in pts:
        k = run_key(p.inputs, run_point)
        if k in keys:
            continue
        keys.add(k)
        if scale > 1.0 or cache.get(k) is None:
            todo[k] = p
    n_runs = round(len(keys) * scale)
    n_cached = n_runs - round(len(todo) * scale)
    n_par = None if scheduler else (workers if workers is not None else (os.cpu_count() or 1))
    base = _rss()
    signals = any(bool(p.inputs.get("signals")) for p in pts)
    table = 2048.0 * n_runs       # a row of ~60 columns, in pandas and in Parquet
    unlisted = "" if scale == 1.0 else "too many to list: the cache was not consulted"
    if not todo:
        return SweepEstimate(n_runs, n_cached, 0.0, 0.0, 0.0, 0, 0.0, n_par, 0.0,
                             base + table)
    steps = {k: _steps(p.inputs) for k, p in todo.items()}
    batches = _batches(todo, len(pts), workers, other_cost) if batched \
        else [[k] for k in todo]
    largest = max(len(b) for b in batches)
    try:
        pr = probe(next(iter(todo.values())).inputs, batch=largest)
    except Exception as exc:  # a grid that does not run: every run will say why, as a row
        return SweepEstimate(n_runs, n_cached, scale * sum(steps.values()),
                             math.nan, math.nan, 0, math.nan, n_par, None, base + table,
                             note=f"the probe failed: {type(exc).__name__}: "
                                  f"{str(exc)[:120]}")
    runs_per_key: dict[str, int] = {}
    for p in todo.values():
        tk = _training_key(p.inputs)
        if tk is not None:
            runs_per_key[tk] = runs_per_key.get(tk, 0) + 1
    par = max(n_par or 1, 1)
    n_train = sum(min(par, n) for n in runs_per_key.values())
    train_s = sum(min(par, n) * _training(pr, tk).seconds for tk, n in runs_per_key.items())
    quiet = {k: _quiet_steps(p.inputs) for k, p in todo.items()}
    # a batch: each run's fixed cost, then the members' steps together (in lockstep: the
    # longest member's, quiet until the first member's disturbance)
    run_s = []
    for b in batches:
        n, q = max(steps[k] for k in b), min(quiet[k] for k in b)
        run_s.append(len(b) * pr["per_run_s"] + q * batch_step_cost(pr, len(b))
                     + (n - q) * batch_transient_cost(pr, len(b)))
    # each worker process (or this one, serially: already paid by the probe) builds the grid
    # and loads the simulator's kernels once
    once = (pr.get("per_process_s", 0.0) * min(par, len(batches))) if n_par else 0.0
    cpu = scale * sum(run_s) + train_s + once
    # workers beyond the cores share them; a local cluster starts in ≈ 2 s (measured: 1.6 s,
    # then 0.4 s for a worker's first import)
    cores = max(min(par, os.cpu_count() or 1), 1)
    wall = None if n_par is None else \
        max(cpu / cores, max(run_s)) + (CLUSTER_START_S if n_par else 0.0)
    longest = max(steps.values())
    run_bytes = 2 * 8.0 * pr["n_vars"] * longest
    sig = 8.0 * pr["n_vars"] * longest if signals else 0.0
    # a batch's members hold their trajectories until the batch ends
    extra = max([largest * (run_bytes + sig)]
                + [_training(pr, tk).bytes for tk in runs_per_key])
    if n_par is None:     # an existing cluster: its workers are elsewhere; one of them
        total = base + extra
    elif n_par == 0:      # serially in this process
        total = base + table + extra
    else:                 # this process and n_par workers like it
        total = base + table + sig + n_par * (base + extra)
    return SweepEstimate(n_runs, n_cached, scale * sum(steps.values()), pr["per_step_s"],
                         pr["per_run_s"], n_train, cpu, n_par, wall, total, unlisted=unlisted,
                         transient_step_s=pr["transient_step_s"], batch=largest,
                         batch_step_s=batch_step_cost(pr, largest))


def _batches(todo: dict, n_points: int, workers: int | None,
             other_cost: float = 0.0) -> list[list]:
    """The keys of ``todo`` in the batches the sweep makes of them
    (:func:`weakgrid.study.batches.batch_key`, at most
    :func:`~weakgrid.study.batches.batch_size_for` of the sweep's ``n_points`` runs each, none
    above a worker's share of their :func:`run_cost` and ``other_cost``, the workers' other runs:
    :func:`weakgrid.sweep.batches.balanced`, as :func:`weakgrid.sweep.run_sweep` and
    :func:`weakgrid.sweep.submit_sweep` make them)."""
    from ..sweep.batches import balanced
    from .batches import balance_for, batch_key, batch_size_for

    keys = list(todo)
    return [[keys[i] for i in b.rows] for b in
            balanced([todo[k].inputs for k in keys], batch_key, batch_size_for(n_points, workers),
                     run_cost, balance_for(workers), other_cost)]


def check_sweep(est: SweepEstimate, study, quick: bool = False, force: bool = False,
                max_seconds: float = MAX_SECONDS, max_bytes: float | None = None) -> None:
    """Refuse (:class:`ParameterError`, before any run) a sweep beyond the limits of a
    training — 30 min of wall time, 4 GiB (``WEAKGRID_MAX_GIB``) or half the available
    memory — unless ``force``. An existing cluster (unknown size) is never refused."""
    if force or est.workers is None or not est.n_todo or est.note:
        return
    if max_bytes is None:
        max_bytes = min(float(os.environ.get("WEAKGRID_MAX_GIB", "4")) * GiB,
                        0.5 * available_memory())
    slow, big = est.wall_s > max_seconds, est.bytes > max_bytes
    if not (slow or big):
        return
    sw = study.data["sweep"]
    axes = (sw.get("quick") or {}).get("axes") if quick else None
    axes = axes or sw["axes"]
    where = "sweep.quick.axes" if quick and (sw.get("quick") or {}).get("axes") else \
        "sweep.axes"
    widest = max(axes, key=lambda k: len(axes[k]))
    fixes = [f"fewer points on [{where}] of {study.source} (the largest axis, "
             f"\"{widest}\", has {len(axes[widest])})"]
    if slow:
        fixes.append("a shorter sweep.t_end")
        if not quick and sw.get("quick"):
            fixes.append("--quick")
        fixes.append(f"more workers (now {est.workers or 1}; --workers up to the "
                     f"{os.cpu_count() or 1} cores here, or a larger Dask cluster: --scheduler)")
    if big:
        fix = "fewer --workers (each holds a run's trajectories)" if est.workers \
            and est.workers > 1 else "a shorter sweep.t_end"
        if fix not in fixes:
            fixes.append(fix)
    raise ParameterError(
        where, f"{est.n_todo} runs to do",
        f"the sweep needs ≈ {_cpu(est.cpu_s)}, ≈ {_duration(est.wall_s)} on "
        f"{est.workers or 1} worker(s) and ≈ {est.bytes / GiB:.2g} GiB (limits "
        f"{_duration(max_seconds)}, {max_bytes / GiB:.2g} GiB). Fix: "
        + ", ".join(fixes) + "; or pass --force to run it anyway")
