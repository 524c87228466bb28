"""The study engine: design, train, run every scenario × controller, measure, write a report.

:func:`run_studies` is what ``weakgrid run STUDY`` and ``weakgrid reproduce`` (the shipped
studies marked ``reproduce = true``) execute. Per study it derives the design model (10) at every
operating point a scenario needs (load level × UPQC structure), compares the design model's
mode with the full grid's (:mod:`weakgrid.design.modes`), trains the HJI controller once per
operating point, runs every (scenario, controller), and writes:

* ``runs/<run id>.parquet`` (every signal) and ``runs/<run id>.json`` (scenario, metrics, design),
* ``controllers/<study>-<load>-<upqc>.controller.json``,
* ``figures/*.png|svg``, ``metrics.csv``, ``metrics.md``, ``claims.json``, ``report.html``,
* for a study with a ``[sweep]`` (its ``[sweep.quick]`` with ``quick``): ``sweep.parquet``
  (``sweep-quick.parquet``), its ``[[sweep.maps]]`` in ``maps/`` and, in the report, the maps
  and a table of the sweep's runs. What runs (the runs, the sweep's size) is logged first.

Every file is written atomically (:mod:`weakgrid.fileio`).
"""

from __future__ import annotations

import contextlib
import logging
import json
import time
from pathlib import Path

import numpy as np

from .. import __version__
from ..design import design_mode, machine_mode, mode_states, modes
from ..fileio import write_json_atomic
from ..manifest import Manifest
from ..models import load_preset
from .batches import STUDY_BATCHES, balance_for, batch_size_for
from .build import build_setup
from .cache import inputs_key, load_run, remove_stale, save_run
from .claims import STABILITY_NOTE, judge_all
from .controllers import controller_kind, controller_variant, train_hji
from .figures import figure_specs, write_figures
from .protocol import controller_name, protocol_of
from .report import who_did_best, write_html, write_tables
from ..sweep import TaskFeed, open_client, run_sweep, submit_sweep
from .runner import Run, RunRecord, check_engine, make_events, run_scenario, run_scenarios
from .sweep import _axes, describe_sweep, run_point, sweep_points
from .sweep_estimate import batch_cost, estimate_sweep, run_cost
from .sweep_maps import draw_maps, map_summaries, metric_uncertainty

__all__ = ["run_studies", "mode_check", "MODE_TOLERANCE"]

MODE_TOLERANCE = 0.05
# the definitions every report states (whatever the study); a study's own protocol is
# weakgrid.study.protocol.protocol_of (its data) and its [report] notes
DEFINITIONS = [
    "Rating: per run, clip_fraction = fraction of the post-fault controller samples at which "
    "the demanded |u| exceeds the UPQC rating (u is then scaled down to it); the demanded "
    "(u_demanded_peak_pu) and applied (u_applied_peak_pu) peaks and control costs are both "
    "reported.",
    "Training region Ω: omega_reach = max over samples and states of x_i / (Ω's bound on "
    "that side); > 1 means the controller evaluates its value function outside the region it "
    "was trained on (extrapolation = true).",
    "Numerics: every run integrates with the study's [simulation] step and Newton tolerance "
    "(default: the controller's sampling period T and the simulator's tolerance scaled with "
    "it).",
    STABILITY_NOTE,
]
SWEEP_DEFINITIONS = [
    "Maps: each claim's measured quantity and verdict over the axes of the study's [sweep]; "
    "the study's own setting is outlined. The claim table gives the verdict at that setting "
    "(the regular runs) and, from the maps, the value there and the region where it holds.",
    "Ties (one rule for the claim table and the maps): a difference between two runs smaller "
    "than their measured uncertainty is a tie (=), not a win. A run's uncertainty is relative "
    "and the sum of (1) step halving, |m(T) − m(T/2)| / |m(T)|, measured by running the "
    "[sweep.dt_check] points again at half the integration step (with the simulator's "
    "default, tighter, tolerance, so it includes the tolerance chosen; not measured in "
    "--quick; the claim table takes the largest over the sweeps) and (2) the metric's "
    "sensitivity to its own definition, re-measured on the run's trajectory (settling band "
    "1.5 % and 3 % around 2 %; backswing against the final value instead of the set-point; "
    "ITAE and costs summed over a horizon 10 % shorter). Losses count: a run of the claim's "
    "controller that failed where its baseline finished is 'not' (its cause named); the "
    "baseline failing where the controller finished stays 'holds'/'reproduced', named.",
]   # design-model mode vs the full grid's mode: relative frequency mismatch


def _progress(total, enabled=True):
    from tqdm import tqdm

    return tqdm(total=total, disable=not enabled, unit="step", dynamic_ncols=True,
                bar_format="{l_bar}{bar}| {n_fmt}/{total_fmt} [{elapsed}<{remaining}] {postfix}")


def mode_check(setup) -> dict:
    """The design model's mode beside the full grid's mode in which the machine participates
    most; ``ok`` when their frequencies agree within :data:`MODE_TOLERANCE`."""
    der = setup.derivation
    lam_d = design_mode(der.model)
    m = modes(setup.system)
    k, part = machine_mode(m, mode_states(der))
    out = {"design_lambda": lam_d, "design_f_hz": abs(lam_d.imag) / (2 * np.pi),
           "states": mode_states(der)}
    if k is None:
        out.update(grid_lambda=None, grid_f_hz=float("nan"), grid_zeta=float("nan"),
                   participation=0.0, mismatch=float("inf"), ok=False, dominant="")
        return out
    lam = m.eigenvalues[k]
    f = float(m.frequency_hz[k])
    mis = abs(out["design_f_hz"] - f) / f
    out["grid_model"] = der.grid_model
    out["forms"] = {}     # both design forms (paper's stiff Vr, grid's Thevenin): signed mismatch
    for name, mod in der.forms.items():
        if mod is not None:
            fd = abs(design_mode(mod).imag) / (2 * np.pi)
            out["forms"][name] = {"f_hz": fd, "mismatch": (fd - f) / f}
    out.update(grid_lambda=complex(lam), grid_f_hz=f, grid_zeta=float(m.damping_ratio[k]),
               participation=part, mismatch=mis, ok=bool(mis <= MODE_TOLERANCE),
               dominant=", ".join(f"{n} {p:.2f}" for n, p in m.dominant_states(k)))
    return out


def _load_trained(path: Path, key: str):
    """The controller trained earlier into ``path`` if it was trained on the same inputs."""
    from ..models import load_controller

    if not path.is_file():
        return None
    try:
        ctl = load_controller(path)
    except (ValueError, OSError):
        return None
    return ctl if ctl.problem.get("inputs_key") == key else None


def _design_notes(study, setup, check):
    d = setup.design
    pre = load_preset(study.data["design"]["settings"]).system
    rel = {k: (getattr(d, k) - getattr(pre, k)) / getattr(pre, k)
           for k in ("a", "Vr_bar", "phi_s0")}
    notes = [f"{study.name}, {setup.load} load, {setup.upqc} UPQC: the training uses Q, R, P, γ, "
             f"Ω, mesh, basis and initial policy of the {study.data['design']['settings']} "
             "preset" + (f"; derived a {rel['a']:+.2%}, V̄r {rel['Vr_bar']:+.2%}, ϕs0 "
                         f"{rel['phi_s0']:+.2%} from its design model"
                         if study.data["study"]["reproduce"] else "")]
    if not check["ok"]:
        notes.append(f"MISMATCH: the design model's mode ({check['design_f_hz']:.3g} Hz) differs "
                     f"from the full grid's mode of the controlled machine "
                     f"({check['grid_f_hz']:.3g} Hz) by {check['mismatch']:.1%} "
                     f"(> {MODE_TOLERANCE:.0%}): the design model (10) does not describe this "
                     "grid's dynamics well at this operating point")
    return notes


def _sweep_file(quick: bool) -> str:
    """The sweep's table in the output folder (Parquet, every metric of every run)."""
    return f"sweep{'-quick' if quick else ''}.parquet"


def _run_task(study, run, trained):
    """One (scenario, controller) on a worker: the record without the study object."""
    return run_scenario(study, run, trained)


def _run_batch_task(study, runs, trained):
    """Runs of one study, load and UPQC structure on a worker, simulated together
    (:func:`weakgrid.study.runner.run_scenarios`): their records, in order."""
    return run_scenarios(study, runs, trained, batched=True)


def _run_batches(todo, workers):
    """``todo`` (study, run, trained, key) in batches of runs that can share a batched
    simulation (one study, UPQC structure, grid variant, final time and event times off the
    step grid; both load levels: each member holds its own loads, as in a sweep's batches),
    at least one batch per worker (:func:`weakgrid.study.batches.batch_size_for`) and none
    costing more than a worker's share of the runs' steps; lists of rows of ``todo``, the
    costliest first (a cluster starts them first).

    Grouped by load level as well, case 1's 20 runs made 8 batches (4 of one run) instead of
    4 and took 129 s serially instead of 89 s (2026-12-03); the runs move by round-off, as
    they do between a batch and a run alone (docs: performance)."""
    from ..sweep.batches import balanced
    from .batches import balance_for, batch_size_for, event_breakpoints
    from .runner import sim_settings

    def key(item):
        st, run, _, _ = item
        return (id(st), run.upqc, controller_variant(st, run.controller), run.t_end,
                event_breakpoints(run.events, sim_settings(st)[0]))

    def steps(item):        # the run's steps: its cost, all runs of a study at one step
        st, run, _, _ = item
        return run.t_end / sim_settings(st)[0]

    batches = balanced(todo, key, batch_size_for(len(todo), workers), steps,
                       balance_for(workers))
    cost = [sum(steps(todo[i]) for i in b.rows) for b in batches]
    order = sorted(range(len(batches)), key=lambda j: -cost[j])   # stable: ties in order
    return [list(batches[j].rows) for j in order]


def _draw_maps_of(studies, tables, folder: Path, quick: bool, client=None) -> list:
    """:func:`weakgrid.study.sweep_maps.draw_maps` of each study (its sweep's rows in
    ``tables``), in order: with ``client`` (a local cluster: its workers write into this
    machine's ``folder``) a study per worker, at once (``reproduce``'s 13 maps: 2.1 and 2.4 s
    one after the other in this process); here otherwise."""
    if client is None or len(studies) < 2:
        return [draw_maps(st, t, folder, quick) for st, t in zip(studies, tables)]
    futures = [client.submit(draw_maps, st, t, folder, quick, pure=False)
               for st, t in zip(studies, tables)]
    return client.gather(futures)


def planned_files(out: Path, plan, quick: bool, maps: bool) -> list[Path]:
    """Every file :func:`run_studies` writes into ``out`` for ``plan`` (the sweep cache's
    hash-named files aside)."""
    files = [out / n for n in ("metrics.csv", "metrics.md", "report.html", "claims.json",
                               "designs.json")]
    for st, runs, keys in plan:
        files += [out / "runs" / f"{r.id}{ext}" for r in runs
                  for ext in (".json", ".parquet")]
        files += [out / "controllers" / f"{st.name}-{ld}-{u}.controller.json" for ld, u in keys]
        files += [out / "figures" / f"{f['id']}.{fmt}" for f in figure_specs(st, quick)
                  for fmt in ("png", "svg")]
        if maps and st.data.get("sweep"):
            files += [out / "maps" / f"map-{st.name}-{m.get('id', m['claim'])}.png"
                      for m in st.data["sweep"].get("maps", [])]
    if maps and any(st.data.get("sweep") for st, _, _ in plan):
        files.append(out / f"sweep{'-quick' if quick else ''}.parquet")
    return files


def check_events(plan) -> None:
    """Build every run's events on its grid (:func:`weakgrid.study.runner.make_events`) so
    that an event the grid cannot carry (an unknown bus or branch, the UPQC's own branch, a
    load step beyond the grid's size, overlapping faults) stops the command before any
    training; a grid is set up once per (study, load, UPQC structure, variant). With a DPsim
    engine (``[simulation] engine``) every model and event of every run is checked against
    it too (:func:`weakgrid.study.runner.check_engine`): a model it lacks is refused by name
    before any run."""
    setups = {}
    for st, runs, _ in plan:
        for run in runs:
            key = (id(st), run.load, run.upqc, controller_variant(st, run.controller))
            if key not in setups:
                setups[key] = build_setup(st, *key[1:])
            check_engine(st, setups[key], make_events(setups[key], run))


def run_studies(studies, output, quick=False, log=None, title=None, progress=True,
                scheduler=None, workers=None, maps=True, force=False, batched=True) -> dict:
    """Run every (scenario, controller) of ``studies`` and write everything to ``output``.

    The runs (and the sweeps of the studies that have a ``[sweep]`` table, drawn as maps
    when ``maps``) go to one Dask cluster: a local one with ``workers`` processes (default
    one per core), or the one at ``scheduler``; ``workers = 0`` runs everything serially here.
    On a cluster the tasks are fed a free worker at a time, the highest priority first
    (:class:`weakgrid.sweep.feed.TaskFeed`), and the maps' runs are queued with the scenario
    runs, below them (:func:`weakgrid.sweep.submit_sweep`): a worker with no scenario run
    left goes on with the maps while the last scenario runs end and this process draws their
    figures.

    weakgrid writes only into ``output`` and deletes there only files it wrote (its manifest,
    :class:`weakgrid.manifest.Manifest`): a file of another origin with the name of an output
    stops the run before any work (unless ``force``: overwritten); other files are left alone.
    Every run's events are built on its grid while planning (:func:`check_events`): a bad
    event stops the command before any training or write.

    ``batched`` (default): the runs of one study and UPQC structure (both load levels) are
    simulated together (:func:`weakgrid.study.runner.run_scenarios`, a task per batch) and so
    are the maps' sweep runs of one grid (:func:`weakgrid.study.batches.simulate_many`);
    ``False``: a task per run, the scalar path (the same results to round-off, but the wall
    times).

    Returns a summary dict (claims, metrics, figures, report, designs, maps).
    """
    log = log or logging.getLogger(__name__).info
    out = Path(output)
    runs_dir = out / "runs"
    t0 = time.perf_counter()
    plan = []   # (study, [Run], training keys)
    for st in studies:
        runs = [Run.of(st, sc, c) for sc, c in st.runs(quick)]
        keys = sorted({r.design_key for r in runs if controller_kind(st, r.controller) == "hji"})
        plan.append((st, runs, keys))
    swept = [st for st in studies if maps and st.data.get("sweep")]
    for st, runs, _ in plan:   # what this command runs, before it runs it
        log(f"{st.name}: {len(runs)} run{'s' if len(runs) != 1 else ''}"
            + (" (--quick: each scenario's quick settings)" if quick else "") + ": "
            + ", ".join(r.id for r in runs))
        if st in swept:
            n_maps = len(st.data["sweep"].get("maps", []))
            log(describe_sweep(st, quick) + f"; its results: the report's section \"Sweep of "
                f"{st.name}\"" + (f" and {n_maps} map{'s' if n_maps != 1 else ''}"
                                   if n_maps else "") + f", {_sweep_file(quick)}")
    total = sum(len(r) + len(k) for _, r, k in plan)
    # the files this plan writes are weakgrid's (listed before they are written); a file of
    # the user's in the way, or a bad event, stops here, before any work or write
    manifest = Manifest(out)
    files = planned_files(out, plan, quick, maps)
    manifest.check(files, force=force)
    check_events(plan)
    manifest.claim(files, force=force)
    runs_dir.mkdir(parents=True, exist_ok=True)
    # a used folder: runs this plan does not make are stale (only those weakgrid wrote);
    # finished runs with the same inputs are kept and not redone (an interrupted run
    # continues where it stopped)
    remove_stale(runs_dir, [r.id for _, runs, _ in plan for r in runs], log, manifest=manifest)
    remove_stale(out / "controllers", [f"{st.name}-{ld}-{u}" for st, _, keys in plan
                                       for ld, u in keys], log, suffix=".controller.json",
                 manifest=manifest)
    n_kept = 0
    bar = _progress(total, progress)
    designs, notes, metrics, records, claims_spec, fig_specs = [], {}, [], {}, [], []
    all_runs = []   # (study, Run, trained controllers)
    for st, runs, keys in plan:
        trained = {}
        case_notes = list(st.data["study"]["notes"])
        sim = st.data.get("simulation") or {}
        if sim:
            case_notes.append("numerics: " + ", ".join(
                f"{k} = {sim[k]:g}" for k in ("dt", "tol") if k in sim)
                + (f", engine = {sim['engine']}" if "engine" in sim else "") + " ([simulation]); "
                + "; ".join(sim.get("notes", [])))
        pre = load_preset(st.data["design"]["settings"]).system
        for load, upqc in keys:
            bar.set_postfix_str(f"design + train {st.name} {load} {upqc}")
            setup = build_setup(st, load, upqc)
            check = mode_check(setup)
            ckey = inputs_key(study=st.data, load=load, upqc=upqc)
            cpath = out / "controllers" / f"{st.name}-{load}-{upqc}.controller.json"
            ctl = _load_trained(cpath, ckey)
            if ctl is None:
                problem, ctl = train_hji(st, setup.design)
                ctl.problem["inputs_key"] = ckey
                ctl.save(cpath)
                manifest.record([cpath])
            else:
                n_kept += 1
            trained[(load, upqc)] = ctl
            case_notes += _design_notes(st, setup, check)
            d = setup.design
            designs.append({
                "case": st.name, "load": load, "upqc": upqc, "T": f"{d.T:.4g}",
                "a": f"{d.a:.4g}", "Vr_bar": f"{d.Vr_bar:.4g}", "phi_s0": f"{d.phi_s0:.4g}",
                "preset": f"{pre.T:.4g}, {pre.a:.4g}, {pre.Vr_bar:.4g}, {pre.phi_s0:.4g}",
                "modes": f"{check['design_f_hz']:.3g} Hz vs {check['grid_f_hz']:.3g} Hz "
                         f"(ζ = {check['grid_zeta']:.3g}; {check['mismatch']:+.1%})"
                         + ("" if check["ok"] else " MISMATCH"),
                "training": f"{ctl.iterations['outer']} outer, W = "
                            f"{np.array2string(ctl.weights, precision=3, max_line_width=200)}",
                "derivation": setup.derivation.to_dict(), "mode_check": {
                    k: (str(v) if isinstance(v, complex) else v) for k, v in check.items()}})
            bar.update(1)
        notes[st.name] = case_notes
        for run in runs:
            hji = trained.get(run.design_key)
            rkey = inputs_key(study=st.data, run=run.to_dict(),
                              controller=hji.problem.get("inputs_key") if hji else None)
            all_runs.append((st, run, trained, rkey))
        claims_spec += st.data["claims"]
        fig_specs += figure_specs(st, quick)
    # finished runs with the same inputs (an earlier, maybe interrupted, run) are loaded
    todo = []
    for st, run, trained, rkey in all_runs:
        rec = load_run(runs_dir, run, rkey, RunRecord)
        if rec is None:
            todo.append((st, run, trained, rkey))
        else:
            records[run.id] = rec
            n_kept += 1
            bar.update(1)
    pts = [p for st in swept for p in sweep_points(st, quick)]
    n_tasks = len(todo) + len(pts)
    serial = workers == 0 or (scheduler is None and n_tasks <= 3)
    sweep_table = None
    # the scenario runs' cost in the maps' unit: the workers' shares that cap a map batch
    # count them too (the maps' runs are queued beside them)
    other = sum(run_cost({"study": st.data, "scenario": run.scenario, "t_end": run.t_end})
                for st, run, _, _ in todo) if swept else 0.0
    if swept:   # the shipped maps' sweep: its estimate is printed, never refused; its probe
        # runs before the cluster starts (it times runs in this process, on idle cores)
        log(estimate_sweep(None, out / "sweep-cache", quick, workers=0 if serial else
                           workers, scheduler=scheduler, points=pts, batched=batched,
                           other_cost=other).line("maps"))
    maps_kw = dict(cache_dir=out / "sweep-cache", progress=progress, log=log, cost=run_cost,
                   batch_cost=batch_cost,
                   desc="maps", batch=STUDY_BATCHES if batched else None,
                   batch_size=batch_size_for(len(pts), 0 if serial else workers)
                   if batched else None,
                   balance=balance_for(0 if serial else workers) if batched else None)
    with contextlib.ExitStack() as stack:
        client = None if serial or not n_tasks else \
            stack.enter_context(open_client(scheduler, workers))
        def keep(run, rkey, rec):
            records[run.id] = rec
            save_run(rec, runs_dir, rkey)    # kept as soon as it is finished
            manifest.record(runs_dir / f"{run.id}{x}" for x in (".parquet", ".json"))
            rec.results = None               # every signal is in its run file now
            bar.set_postfix_str(run.id)
            bar.update(1)

        batches = _run_batches(todo, 0 if client is None else workers) if batched else \
            [[i] for i in range(len(todo))]
        pending = None
        if client is not None:
            feed = TaskFeed(client)   # a task per free worker, the highest priority first
            for rank, rows in enumerate(batches):   # the costliest first, by priority
                st = todo[rows[0]][0]
                runs = [todo[i][1] for i in rows]
                tr = {k: v for i in rows for k, v in todo[i][2].items()
                      if k in {r.design_key for r in runs}}
                task = (_run_batch_task, st, runs, tr) if batched else \
                    (_run_task, st, runs[0], tr)
                feed.add("runs", rows, *task, priority=len(batches) - rank)
            # the maps' runs are queued too, after the scenario runs (priorities below
            # theirs): a worker done with the scenario runs goes on with the maps while the
            # last scenario runs end and their figures are drawn here
            pending = submit_sweep(pts, run_point, feed=feed, other_cost=other,
                                   **maps_kw) if swept else None
            try:
                for rows, recs in feed.take("runs"):
                    for i, rec in zip(rows, recs if batched else [recs]):
                        keep(todo[i][1], todo[i][3], rec)
            except BaseException:
                if pending is not None:   # the maps' runs finished so far are kept
                    pending.store_finished()
                feed.cancel()
                raise
        else:
            for rows in batches:
                st, trained = todo[rows[0]][0], todo[rows[0]][2]
                runs = [todo[i][1] for i in rows]
                bar.set_postfix_str(runs[0].id)
                for i, rec in zip(rows, run_scenarios(st, runs, trained, batched=batched)):
                    keep(todo[i][1], todo[i][3], rec)
        metrics = [records[run.id].metrics for _, run, _, _ in all_runs]
        bar.close()
        if n_kept:
            log(f"kept {n_kept} finished result(s) of an earlier run with the same inputs")
        # the scenario runs' figures, drawn here while the maps' runs go on on the workers
        figs = write_figures(records, out / "figures", fig_specs)
        if pending is not None:
            sweep_table = pending.collect(out / _sweep_file(quick))
        elif swept:
            sweep_table = run_sweep(pts, run_point, workers=0 if serial else None,
                                    client=client, table_path=out / _sweep_file(quick),
                                    **maps_kw)
        subs = [sweep_table[sweep_table["scenario"].isin(st.data["sweep"]["scenarios"])]
                .dropna(axis=1, how="all") for st in swept]
        all_drawn = _draw_maps_of(swept, subs, out / "maps", quick,
                                  client if scheduler is None else None)
    map_list, sweeps, uncertainty = [], [], {}
    for st, sub, drawn in zip(swept, subs, all_drawn):
        map_list += [dict(m, study=st.name) for m in drawn]
        sweeps.append({"study": st.name, "file": _sweep_file(quick), "frame": sub,
                       "axes": list(_axes(st.data["sweep"], quick)),
                       "text": describe_sweep(st, quick),
                       "open": not any(m.get("path") for m in drawn)})
        for k, u in metric_uncertainty(sub, _axes(st.data["sweep"], quick)).items():
            uncertainty[k] = max(uncertainty.get(k, 0.0), u)
    summaries = map_summaries(map_list)
    run_title = title or ", ".join(st.data["study"].get("title", st.name) for st in studies)
    csv, md = write_tables(metrics, out, title=run_title)
    protocol = [p for st in studies for p in protocol_of(st, quick)
                + list(st.data["report"]["notes"])]
    protocol += DEFINITIONS + (SWEEP_DEFINITIONS if swept else [])
    names = {c: controller_name(st, c) for st in studies for sc in st.scenarios(quick)
             for c in sc["controllers"]}
    best = who_did_best(metrics, uncertainty, names)
    claims = judge_all(claims_spec, {m["id"]: m for m in metrics}, uncertainty)
    for c in claims:
        ms = [m for m in summaries if m["claim"] == c["id"]]
        tag = (lambda m: f"[{m['id']}] ") if len(ms) > 1 else (lambda m: "")
        c["map_setting"] = "; ".join(tag(m) + m["at_setting"] for m in ms)
        c["map_region"] = "; ".join(f"{tag(m)}{m['region']} ({m['n_holds']} of "
                                    f"{m['n_cells']} cells)" for m in ms)
    wall = time.perf_counter() - t0
    params = json.dumps({"studies": [{"source": st.source, "study": st.data} for st in studies],
                         "quick": quick}, indent=1, default=str)
    report = write_html(out / "report.html", claims=claims, metrics=metrics,
                        figures=[p for p in figs if p.suffix == ".png"],
                        designs=designs, notes=notes, protocol=protocol, best=best,
                        maps=[dict(s_, path=m["path"], study=m["study"]) for s_, m in
                              zip(summaries, map_list)], sweeps=sweeps,
                        meta={"version": __version__, "n_runs": len(metrics), "wall_s": wall,
                              "mode": "quick" if quick else "full", "parameters": params,
                              "title": run_title})
    write_json_atomic(out / "claims.json", {"claims": claims, "weakgrid_version": __version__,
                                            "quick": quick, "wall_s": wall})
    write_json_atomic(out / "designs.json", {"designs": designs, "weakgrid_version": __version__})
    manifest.record(planned_files(out, plan, quick, maps))   # their content, as written
    log(f"wrote {report}, {csv}, {md}, {len(figs)} figure files in {wall:.0f} s")
    return {"claims": claims, "metrics": metrics, "figures": figs, "report": report,
            "csv": csv, "markdown": md, "wall_s": wall, "designs": designs,
            "maps": summaries, "sweep": sweep_table}
