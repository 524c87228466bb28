"""Finished runs on disk, keyed by a content hash of their inputs: resume, never redo.

A run is written as its run file (``ID.parquet``: every recorded signal by name and the
controller's samples, :mod:`weakgrid.sim.runfile`) and then its record ``ID.json``, each
atomically; the record is written last and carries
``inputs_key``, a hash of everything the run depends on (scenario, controller,
package version). A re-run with the same inputs loads the run instead of
simulating it again; a changed input gives another key and the run is redone.
"""

from __future__ import annotations

import json
import logging
import math
from pathlib import Path

import numpy as np

from .. import __version__
from ..fileio import write_json_atomic
from ..hashing import checksum_ok, content_key, with_checksum

__all__ = ["inputs_key", "save_run", "load_run", "remove_stale", "write_run_file", "read_run_file",
           "run_meta", "run_file_table"]


def inputs_key(**inputs) -> str:
    """A short hash of ``inputs`` (JSON-serializable) and of the code (every source and data
    file of the package): a changed input or a changed code never reuses a stale result
    (:func:`weakgrid.hashing.content_key`)."""
    return content_key(inputs)


def run_meta(rec, version: str = __version__) -> dict:
    """File-level metadata of a study run's run file: study, scenario, controller, version,
    run parameters (dt, tol, events, bypass, t_end) and the figure keys' aliases."""
    sc = rec.scenario
    sim = rec.info.get("sim", {})
    return {"study": sc.case, "scenario": sc.scenario, "controller": sc.controller,
            "run_id": sc.id, "load": sc.load, "upqc": sc.upqc, "design_load": sc.design_load,
            "t_end": sc.t_end, "events": [dict(e) for e in sc.events],
            "bypass": [list(b) for b in sc.bypass], "dt": sim.get("dt"), "tol": sim.get("tol"),
            "Sb_mva": rec.info.get("Sb_mva"), "aliases": dict(rec.aliases),
            "derived": sorted(k for k in rec.series if k != "t" and k not in rec.aliases),
            "weakgrid_version": version}


def _results_of(rec):
    """The record's full trajectories, or its series as trajectories (a record built without
    a simulation: every series key a signal of its own, aliased to itself)."""
    if rec.results is not None:
        return rec.results, dict(rec.aliases)
    from ..sim.results import Results

    keys = [k for k in rec.series if k != "t"]
    t = np.asarray(rec.series["t"], float)
    data = np.column_stack([np.asarray(rec.series[k], float) for k in keys]) if keys \
        else np.zeros((len(t), 0))
    return Results(t, keys, data, ["pu"] * len(keys), np.ones(len(keys))), {k: k for k in keys}


def run_file_table(rec, version: str = __version__):
    """A study run's run-file table (:func:`weakgrid.sim.runfile.run_table`): every recorded
    signal, the controller's samples, the metadata of :func:`run_meta`."""
    from ..sim.runfile import run_table

    res, aliases = _results_of(rec)
    meta = run_meta(rec, version)
    meta["aliases"] = aliases
    meta["derived"] = [k for k in meta["derived"] if k not in aliases]
    return run_table(res, samples=rec.samples if rec.samples else None, meta=meta)


def write_run_file(rec, path, version: str = __version__) -> Path:
    """Write a study run as a run file (atomically; the table of :func:`run_file_table`)."""
    import pyarrow.parquet as pq

    from ..fileio import replace_atomic

    table = run_file_table(rec, version)
    return replace_atomic(path, lambda tmp: pq.write_table(table, tmp))


def read_run_file(path):
    """``(series, samples)`` of a study run's run file: the figure keys (aliases read, derived
    ones recomputed) per instant, every row kept, and the per-sample columns."""
    from ..sim.runfile import read_meta, read_run, read_samples
    from .runner import derive_series

    meta = read_meta(path)
    aliases = meta.get("aliases") or {}
    df = read_run(path, list(dict.fromkeys(aliases.values())) or [], pre_event=True)
    series = {"t": df["t"].to_numpy()}
    for k, name in aliases.items():
        series[k] = df[name].to_numpy()
    if meta.get("Sb_mva") is not None:
        series.update(derive_series(series, float(meta["Sb_mva"])))
    sm = read_samples(path)
    samples = {("tk" if c == "t" else c): sm[c].to_numpy() for c in sm.columns} \
        if meta.get("n_samples") else {}
    return series, samples, aliases


def save_run(rec, folder, key: str, version: str = __version__) -> Path:
    """Write one finished run: its run file ``ID.parquet`` first (every signal, the samples,
    :func:`run_meta`), the record ``ID.json`` (with ``key``) last."""
    folder = Path(folder)
    sid = rec.scenario.id
    write_run_file(rec, folder / f"{sid}.parquet", version)
    record = {"scenario": rec.scenario.to_dict(), "metrics": rec.metrics, "info": rec.info,
              "weakgrid_version": version, "inputs_key": key}
    files = [folder / f"{sid}.parquet"]
    return write_json_atomic(folder / f"{sid}.json", with_checksum(record, files))


def load_run(folder, scenario, key: str, record_class):
    """The finished run of ``scenario`` if its record matches ``key``, else None (its
    ``results`` not loaded: read them from ``ID.parquet`` with :func:`weakgrid.read_run`)."""
    from ..sim.errors import DataError

    folder = Path(folder)
    sid = scenario.id
    paths = [folder / f"{sid}.json", folder / f"{sid}.parquet"]
    if not all(p.is_file() for p in paths):
        return None
    try:
        d = json.loads(paths[0].read_text(encoding="utf-8"))
        if not isinstance(d, dict) or d.get("inputs_key") != key:
            return None
        if not checksum_ok(d, paths[1:]):
            logging.getLogger(__name__).warning(
                "the finished run %s does not match its checksum (edited or damaged); it is "
                "run again", paths[0])
            return None
        series, samples, aliases = read_run_file(paths[1])
    except (OSError, ValueError, KeyError, DataError):  # unreadable or older format: run again
        return None
    metrics = {k: (math.nan if v is None else v) for k, v in d.get("metrics", {}).items()}
    return record_class(scenario, metrics, series, d.get("info", {}), samples=samples,
                        aliases={k: v for k, v in aliases.items() if k != v})


def remove_stale(folder, keep_ids, log=None, suffix=".json", manifest=None) -> list[str]:
    """Remove the runs in ``folder`` whose id is not in ``keep_ids`` — only files weakgrid
    wrote (listed in ``manifest``, by default the manifest of ``folder``,
    :class:`weakgrid.manifest.Manifest`); any other file is left alone. Say what was removed
    (``log``, default this module's logger as a warning)."""
    from ..manifest import Manifest

    log = log or logging.getLogger(__name__).warning
    folder = Path(folder)
    if not folder.is_dir():
        return []
    manifest = manifest if manifest is not None else Manifest(folder)
    keep = set(keep_ids)
    listed = manifest.listed_under(manifest.rel(folder))
    stale = sorted({p.name[:-len(suffix)] for p in listed if p.name.endswith(suffix)
                    and p.name[:-len(suffix)] not in keep and p.is_file()})
    for sid in stale:
        manifest.remove(p for p in folder.glob(f"{sid}.*"))
    if stale:
        log(f"warning: removed {len(stale)} stale run(s) of an earlier run in {folder} "
            f"that this one does not make: {', '.join(stale[:6])}{' …' if len(stale) > 6 else ''}"
            " (only files weakgrid wrote; anything else there is left alone)")
    return stale
