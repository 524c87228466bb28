"""Sweeps of a study: its ``[sweep]`` table run on :mod:`weakgrid.sweep` (Dask, cache, resume).

A study's ``[sweep]`` table::

    [sweep]
    mode = "product"                         # or "points" (the k-th values of every axis together)
    scenarios = ["c1-high-conv"]             # scenarios run at every point [all]
    controllers = ["hji", "nonlinear-29"]    # controllers run at every point [each scenario's]
    t_end = 3.0                              # shorter runs for the sweep [each scenario's]
    design_load = "high"                     # controllers designed at this load [the run's]
    signals = false                          # keep every run's signals (Parquet) in the cache
    [sweep.axes]                             # dotted study paths (list elements by id) → values
    "upqc.rating" = [0.1, 0.15, 0.3, 0.6, 1.0]
    "scenarios.c1-high-conv.load" = ["high", "low"]
    "scenarios.c1-high-conv.events.0.t_off" = [0.22, 0.25, 0.3]   # or ….duration (s)
    [sweep.quick]                            # replaces axes (and t_end) for `--quick`
    [sweep.dt_check]                         # points (path = values) run again at half the step:
    "upqc.rating" = [0.15]                   # the numerical uncertainty (ties in the maps)
    [[sweep.maps]]                           # one map per claim (weakgrid.study.sweep_maps)

Every run is one task: :func:`run_point` (module level, picklable) receives the full input —
the study dict with the point's values set, the scenario id, the controller name, the design
load — and returns its metrics. Fields are addressed by the study's own dotted paths
(:func:`weakgrid.study.studyfile.get_path`/``set_path``), passed to
:func:`weakgrid.sweep.expand`. The HJI controller of a design point is trained once per worker
process (cached on the design model and the design settings).
"""

from __future__ import annotations

import copy
import dataclasses
from pathlib import Path

import pandas as pd

from ..game.errors import ParameterError
from ..sweep import Point, canonical_json, expand, run_sweep
from .studyfile import get_path, set_path, study_from_dict
from .fields import keys

__all__ = ["SWEEP_KEYS", "validate_sweep", "sweep_points", "describe_sweep", "run_point",
           "prepare_point", "finish_point", "run_study_sweep", "claim_sweep_outputs"]

SWEEP_KEYS = keys("sweep")      # the fields: weakgrid.study.fields

_TRAINED: dict = {}     # per worker process: design key -> trained GameController
_DESIGNS: dict = {}     # per worker process: (grid data, load, structure) -> design model (10)
_NOT_DESIGN = ("scenarios", "sweep", "claims", "figures", "report", "study", "controllers",
               "simulation")


def validate_sweep(d: dict, study) -> None:
    """Check a study dict's ``[sweep]`` table (fields named in every error)."""
    sw = d.get("sweep")
    if sw is None:
        return
    if not isinstance(sw, dict):
        raise ParameterError("sweep", sw, "give a table [sweep]")
    extra = set(sw) - SWEEP_KEYS
    if extra:
        raise ParameterError(f"sweep.{sorted(extra)[0]}", "…", f"unknown field; allowed: "
                             f"{sorted(SWEEP_KEYS)}")
    if sw.setdefault("mode", "product") not in ("product", "points"):
        raise ParameterError("sweep.mode", sw["mode"], "choose 'product' or 'points'")
    ids = [sc["id"] for sc in d["scenarios"]]
    for sid in sw.setdefault("scenarios", ids):
        if sid not in ids:
            raise ParameterError("sweep.scenarios", sid, f"no such scenario; choose from {ids}")
    for c in sw.get("controllers", []):
        if c not in d["controllers"]["compare"]:
            raise ParameterError("sweep.controllers", c, f"not in controllers.compare "
                                 f"{d['controllers']['compare']}")
    if "design_load" in sw and sw["design_load"] not in study.loads:
        raise ParameterError("sweep.design_load", sw["design_load"],
                             f"choose one of {study.loads}")
    for where, axes in (("sweep.axes", sw.get("axes")),
                        ("sweep.quick.axes", (sw.get("quick") or {}).get("axes"))):
        if axes is None:
            if where == "sweep.axes":
                raise ParameterError(where, None, "give [sweep.axes]: dotted study path = "
                                     "list of values, e.g. \"upqc.rating\" = [0.1, 0.3]")
            continue
        if not isinstance(axes, dict) or not axes:
            raise ParameterError(where, axes, "give a table of dotted path = list of values")
        for path, vals in axes.items():
            try:
                get_path(d, path)   # the field exists
            except ParameterError as exc:
                raise ParameterError(f"{where}.\"{path}\"", path, f"no such study field: "
                                     f"{exc.field}: {exc.fix}") from None
            if not isinstance(vals, list) or not vals:
                raise ParameterError(f"{where}.\"{path}\"", vals, "give a non-empty list")
            for v in vals:
                _check_axis_value(d, where, path, v, axes, study)
    for where, t in (("sweep.t_end", sw.get("t_end")),
                     ("sweep.quick.t_end", (sw.get("quick") or {}).get("t_end"))):
        if t is not None and (isinstance(t, bool) or not isinstance(t, (int, float))
                              or not 0 < t < float("inf")):
            raise ParameterError(where, t, "give the simulated time of every run, a number "
                                 "> 0 (s)")
    for where, axes in (("sweep.axes", sw.get("axes")),
                        ("sweep.quick.axes", (sw.get("quick") or {}).get("axes"))):
        ends = {}
        for path in axes or {}:   # a fault's end swept once: t_off or its duration
            head, _, last = path.rpartition(".")
            if last in ("t_off", "duration"):
                if head in ends:
                    raise ParameterError(f"{where}.\"{path}\"", path, f"{head} is swept by "
                                         f"{ends[head]} already: sweep the fault's t_off or its "
                                         "duration, not both")
                ends[head] = path
    _maps(sw, d)
    for path, vals in (sw.get("dt_check") or {}).items():
        if path not in sw.get("axes", {}) or not isinstance(vals, list):
            raise ParameterError(f"sweep.dt_check.\"{path}\"", vals, "give a list of values of "
                                 "a swept field (a path of [sweep.axes])")


MAP_KEYS = keys("sweep.maps")


def _maps(sw, d):
    """``[[sweep.maps]]``: known keys, kind, controllers of the study, a file-name id, axes
    among the swept fields."""
    from ..fileio import check_file_name
    from .sweep_maps import MAP_KINDS

    maps = sw.get("maps", [])
    if not isinstance(maps, list):
        raise ParameterError("sweep.maps", maps, "give [[sweep.maps]] tables")
    axes = set(sw.get("axes") or {}) | set((sw.get("quick") or {}).get("axes") or {})
    compare = d["controllers"]["compare"]
    seen = set()
    for i, m in enumerate(maps):
        w = f"sweep.maps.{i}"
        if not isinstance(m, dict):
            raise ParameterError(w, m, "must be a table [[sweep.maps]]")
        extra = sorted(set(m) - MAP_KEYS)
        if extra:
            raise ParameterError(f"{w}.{extra[0]}", m[extra[0]], f"unknown field; allowed: "
                                 f"{sorted(MAP_KEYS)}")
        if not isinstance(m.get("claim"), str):
            raise ParameterError(f"{w}.claim", m.get("claim"), "give the claim's id (text)")
        mid = check_file_name(m.get("id", m["claim"]), f"{w}.id" if "id" in m else f"{w}.claim")
        if mid in seen:
            raise ParameterError(f"{w}.id", mid, "map ids must be unique (each is a file name)")
        seen.add(mid)
        if m.get("kind") not in MAP_KINDS:
            raise ParameterError(f"{w}.kind", m.get("kind"), f"choose one of {list(MAP_KINDS)}")
        for k in ("a", "b"):
            if k in m and m[k] not in compare:
                raise ParameterError(f"{w}.{k}", m[k], f"not in controllers.compare {compare}")
        for k in ("x", "y", "facet"):
            if k in m and m[k] not in axes:
                raise ParameterError(f"{w}.{k}", m[k], f"not a swept field; choose one of "
                                     f"{sorted(axes)}")


def _check_axis_value(d, where, path, value, axes=None, study=None):
    """A value of an axis must be valid for its field: the study with it is validated (a
    fault's t_on with the first value of its swept duration, if swept: the end follows it)."""
    trial = {k: copy.deepcopy(v) for k, v in d.items() if k != "sweep"}
    head, _, last = path.rpartition(".")
    with_end = f"{head}.duration"
    try:
        if last == "t_on" and with_end in (axes or {}):
            set_path(trial, with_end, copy.deepcopy(axes[with_end][0]))
        set_path(trial, path, copy.deepcopy(value))
        study_from_dict(trial, getattr(study, "source", ""), getattr(study, "base_dir", None))
    except ParameterError as exc:
        fix = exc.fix if exc.field == path else str(exc)
        raise ParameterError(f"{where}.\"{path}\"", value,
                             f"not a valid value of {path}: {fix}") from None


def _axes(sw: dict, quick: bool) -> dict:
    q = sw.get("quick") or {}
    return dict(q["axes"]) if quick and "axes" in q else dict(sw["axes"])


def sweep_points(study, quick: bool = False, scenarios=None, controllers=None):
    """The points of the study's sweep: a :class:`weakgrid.sweep.Point` per (axis values ×
    scenario × controller); its ``inputs`` is the full input of :func:`run_point`."""
    sw = study.data.get("sweep")
    if not sw:
        raise ParameterError("sweep", None, f"study '{study.name}' has no [sweep] table; add "
                             "one (see weakgrid.study.sweep)")
    # a run's full input: the study without what does not change a run (so that editing a
    # map, a figure or a claim's wording keeps the cached runs)
    base_study = {k: copy.deepcopy(v) for k, v in study.data.items()
                  if k not in ("sweep", "figures", "claims")}
    t_end = (sw.get("quick") or {}).get("t_end") if quick else None
    t_end = t_end or sw.get("t_end")
    scs = scenarios or sw["scenarios"]
    out = []
    for sid in scs:
        sc = get_path(base_study, f"scenarios.{sid}")
        ctls = controllers or sw.get("controllers") or sc["controllers"]
        for c in ctls:
            if c not in study.controllers:
                raise ParameterError("sweep.controllers", c, "not a controller of the study")
        base = {"study": base_study, "scenario": sid, "controller": ctls[0],
                "design_load": sw.get("design_load"), "t_end": t_end,
                "signals": bool(sw.get("signals", False)), "dt_factor": 1.0}
        axes = {f"study.{p}": v for p, v in _axes(sw, quick).items()}
        axes["controller"] = list(ctls)
        pts = expand(base, axes, "product", getter=get_path, setter=set_path) \
            if sw["mode"] == "product" else _points_mode(base, axes)
        for pt in pts:
            pt.params = {k[6:] if k.startswith("study.") else k: v for k, v in
                         pt.params.items()}
            pt.params = {"scenario": sid, **pt.params, "dt_factor": 1.0}
            out.append(pt)
            chk = {} if quick else (sw.get("dt_check") or {})
            if chk and all(pt.params.get(k) in v for k, v in chk.items()):
                half = Point(dict(pt.params, dt_factor=0.5),
                             dict(copy.deepcopy(pt.inputs), dt_factor=0.5))
                out.append(half)
    return out


def describe_sweep(study, quick: bool = False) -> str:
    """One line saying what the study's sweep runs: its run count and how it is made up (the
    axes and their sizes, the controllers, the scenarios, the runs at half the step)."""
    sw = study.data["sweep"]
    pts = sweep_points(study, quick)
    half = sum(1 for p in pts if p.params.get("dt_factor", 1.0) != 1.0)
    axes = _axes(sw, quick)
    scs = sw["scenarios"]
    ctls = sw.get("controllers")
    parts = [f"{p} ({len(v)})" for p, v in axes.items()]
    parts.append(f"controllers ({len(ctls)}: {', '.join(ctls)})" if ctls else
                 "each scenario's controllers")
    t_end = ((sw.get("quick") or {}).get("t_end") if quick else None) or sw.get("t_end")
    src = "[sweep.quick]" if quick and "axes" in (sw.get("quick") or {}) else "[sweep]"
    return (f"{study.name}: its sweep {src}, {len(pts)} runs: {' × '.join(parts)} on "
            f"scenario{'s' if len(scs) > 1 else ''} {', '.join(scs)}"
            + (f", {t_end:g} s each" if t_end else "")
            + (f" ({half} of them at half the step: the numerical uncertainty)" if half else ""))


def _points_mode(base, axes):
    """Listed points (every study axis equally long) × the controllers (× dt factors)."""
    study_axes = {k: v for k, v in axes.items() if k.startswith("study.")}
    pts = expand(base, study_axes, "points", getter=get_path, setter=set_path)
    out = []
    for pt in pts:
        extra = {k: v for k, v in axes.items() if not k.startswith("study.")}
        for sub in expand(pt.inputs, extra, "product", getter=get_path, setter=set_path):
            sub.params = {**pt.params, **sub.params}
            out.append(sub)
    return out


def _design(study, load, upqc):
    """The design model (10) at ``load``/``upqc`` (it does not depend on the UPQC rating)."""
    from .build import build_setup

    d = {k: v for k, v in study.data.items() if k not in _NOT_DESIGN}
    d["upqc"] = {k: v for k, v in d["upqc"].items() if k != "rating"}
    key = canonical_json([d, load, upqc])
    if key not in _DESIGNS:
        _DESIGNS[key] = build_setup(study, load, upqc).design
    return _DESIGNS[key]


def _trained(study, design, key_extra):
    from .controllers import train_hji

    key = canonical_json([design.to_dict(), study.data["design"], key_extra])
    ctl = _TRAINED.get(key)
    if ctl is None:
        ctl = train_hji(study, design)[1]
        _TRAINED[key] = ctl
    return ctl


def run_point(inputs: dict):
    """Run one point of a sweep (on a worker) and return its metrics (and signals).

    ``inputs``: ``study`` (a study dict, the point's values set), ``scenario`` (id),
    ``controller`` (name), ``design_load`` (or None: the run's own load), ``t_end`` (or None),
    ``signals`` (bool), ``dt_factor`` (integration step = factor × the study's step; 0.5 for
    the numerical uncertainty check, run with the simulator's default tolerance for that
    step: :func:`weakgrid.study.runner.sim_settings`). A run that loses stability or whose
    Newton iteration fails returns ``status = "failed"`` with its cause. The three parts
    (:func:`prepare_point`, the simulation, :func:`finish_point`) are what
    :func:`weakgrid.study.batches.simulate_many` runs for a batch of points.
    """
    from .runner import simulate_prepared

    prep = prepare_point(inputs)
    res, wall = simulate_prepared([prep], batched=False)[0]
    return finish_point(inputs, prep, res, wall)


def prepare_point(inputs: dict):
    """The point's run made ready to simulate (:func:`weakgrid.study.runner.prepare_run`):
    its study built from ``inputs``, its design model and trained controller (cached per
    worker process)."""
    from .controllers import controller_kind
    from .runner import Run, metric_signals, prepare_run, sim_settings

    st = study_from_dict(inputs["study"], source=f"sweep:{inputs['study']['study']['name']}")
    sc = next((s for s in st.scenarios() if s["id"] == inputs["scenario"]), None)
    if sc is None:
        raise ParameterError("scenario", inputs["scenario"], "no such scenario in the study")
    if inputs.get("t_end"):
        sc = dict(sc, t_end=float(inputs["t_end"]))
    name = inputs["controller"]
    run = Run.of(st, sc, name)
    dload = inputs.get("design_load") or run.load
    trained = {}
    design = _design(st, dload, run.upqc)
    if controller_kind(st, name) == "hji":
        trained[(dload, run.upqc)] = _trained(st, design, [dload, run.upqc])
    dt, tol = sim_settings(st, float(inputs.get("dt_factor") or 1.0))
    prep = prepare_run(st, run, trained, dt=dt, tol=tol, design_load=dload, design=design)
    if not inputs.get("signals"):   # only its metrics are kept: record what they read
        prep = dataclasses.replace(prep, record=metric_signals(prep.setup))
    return prep


def finish_point(inputs: dict, prep, res, wall: float):
    """The point's row (metrics; and its run file's table with ``signals``) from its
    simulation ``res`` that took ``wall`` seconds."""
    from .runner import finish_run

    rec = finish_run(prep, res, wall)
    m = dict(rec.metrics)
    for k in ("id", "case", "controller", "load", "upqc", "wall_s"):
        m.pop(k, None)
    m["sim_wall_s"] = rec.metrics.get("wall_s")
    m["run_load"] = rec.metrics.get("load")
    if rec.metrics.get("failed"):
        m["status"] = "failed"
        m["failure"] = rec.metrics.get("failure") or "simulation failed"
    m.pop("failed", None)
    if inputs.get("signals"):   # the run file: every signal by name, the samples, metadata
        from .cache import run_file_table

        return m, run_file_table(rec)
    return m


def claim_sweep_outputs(study, output, quick=False, maps=False, force=False,
                        write=True) -> Path:
    """List the files a sweep writes into ``output`` (its table; the maps' files with
    ``maps``) in the folder's manifest before anything is written; a file of another origin
    in the way is refused unless ``force`` (:class:`weakgrid.manifest.Manifest`; ``write =
    False``: only the check, nothing written). Returns the table's path."""
    from ..manifest import Manifest

    out = Path(output)
    table_path = out / f"{study.name}-sweep{'-quick' if quick else ''}.parquet"
    files = [table_path] + ([out / "maps" / f"map-{study.name}-{m.get('id', m['claim'])}.png"
                             for m in study.data["sweep"].get("maps", [])] if maps else [])
    m = Manifest(out)
    (m.claim if write else m.check)(files, force=force)
    return table_path


def run_study_sweep(study, output, *, quick=False, scheduler=None, workers=None,
                    progress=True, log=None, cache_dir=None, force=False,
                    maps=False, batched=True) -> pd.DataFrame:
    """Run the study's sweep; write ``<output>/<study>-sweep.parquet``; return the table.

    The cache (``<output>/cache`` unless given) keeps every finished run: an interrupted
    sweep resumes, a repeated one runs nothing. The table (and the maps' files, ``maps``)
    are listed in the folder's manifest before they are written; a file of another origin
    in the way stops the sweep before any run unless ``force``
    (:class:`weakgrid.manifest.Manifest`). ``batched`` (default): the runs of one grid go to
    :func:`weakgrid.study.batches.simulate_many` together, a task per batch (at least one
    batch per worker: :func:`weakgrid.study.batches.batch_size_for`, and none above a worker's
    share of the sweep's cost: :func:`weakgrid.study.batches.balance_for`); ``False``: a task
    per run, the scalar path (the same table to round-off).
    """
    from .batches import STUDY_BATCHES, balance_for, batch_size_for
    from .sweep_estimate import batch_cost, run_cost

    out = Path(output)
    table_path = claim_sweep_outputs(study, out, quick, maps, force)
    pts = sweep_points(study, quick)
    from ..manifest import Manifest

    table = run_sweep(pts, run_point, cache_dir=cache_dir or out / "cache",
                      scheduler=scheduler, workers=workers, progress=progress, log=log,
                      cost=run_cost, batch_cost=batch_cost, table_path=table_path,
                      desc=f"sweep {study.name}",
                      batch=STUDY_BATCHES if batched else None,
                      batch_size=batch_size_for(len(pts), workers) if batched else None,
                      balance=balance_for(workers) if batched else None)
    Manifest(out).record([table_path])   # its content, as written
    return table
