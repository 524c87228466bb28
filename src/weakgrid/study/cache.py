"""Finished runs on disk, keyed by a content hash of their inputs: resume, never redo.

A run is written as its series (``ID.parquet``, ``ID.samples.parquet``) and then
its record ``ID.json``, each atomically; the record is written last and carries
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
import pandas as pd

from .. import __version__
from ..fileio import replace_atomic, write_json_atomic
from ..hashing import checksum_ok, content_key, with_checksum

__all__ = ["inputs_key", "save_run", "load_run", "remove_stale"]


def inputs_key(**inputs) -> str:
    """A short hash of ``inputs`` (JSON-serializable) and of the code (every source and data
    file of the package): a changed input or a changed code never reuses a stale result
    (:func:`weakgrid.hashing.content_key`)."""
    return content_key(inputs)


def _frame(series: dict, length_of: str):
    n = np.shape(series.get(length_of, ()))
    cols = {}
    for k, v in series.items():
        if isinstance(v, np.ndarray) and v.ndim >= 1 and v.shape[0] == n[0] and n:
            if v.ndim == 1:
                cols[k] = v
            elif v.ndim == 2:
                for j in range(v.shape[1]):
                    cols[f"{k}[{j}]"] = v[:, j]
    return pd.DataFrame(cols)


def _unframe(df) -> dict:
    out, parts = {}, {}
    for c in df.columns:
        if c.endswith("]") and "[" in c:
            k, j = c[:-1].split("[")
            parts.setdefault(k, {})[int(j)] = df[c].to_numpy()
        else:
            out[c] = df[c].to_numpy()
    for k, cols in parts.items():
        out[k] = np.column_stack([cols[j] for j in sorted(cols)])
    return out


def save_run(rec, folder, key: str, version: str = __version__) -> Path:
    """Write one finished run: series first, the record (with ``key``) last."""
    folder = Path(folder)
    sid = rec.scenario.id
    t_frame = _frame(rec.series, "t")
    replace_atomic(folder / f"{sid}.parquet", t_frame.to_parquet)
    s_frame = _frame({k: v for k, v in rec.series.items() if k not in t_frame.columns}, "tk")
    replace_atomic(folder / f"{sid}.samples.parquet", s_frame.to_parquet)
    record = {"scenario": rec.scenario.to_dict(), "metrics": rec.metrics, "info": rec.info,
              "weakgrid_version": version, "inputs_key": key}
    files = [folder / f"{sid}.parquet", folder / f"{sid}.samples.parquet"]
    return write_json_atomic(folder / f"{sid}.json", with_checksum(record, files))


def load_run(folder, scenario, key: str, record_class):
    """The finished run of ``scenario`` if its record matches ``key``, else None."""
    folder = Path(folder)
    sid = scenario.id
    paths = [folder / f"{sid}.json", folder / f"{sid}.parquet", folder / f"{sid}.samples.parquet"]
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
        series = _unframe(pd.read_parquet(paths[1]))
        series.update(_unframe(pd.read_parquet(paths[2])))
    except (OSError, ValueError):  # unreadable: run it again
        return None
    metrics = {k: (math.nan if v is None else v) for k, v in d.get("metrics", {}).items()}
    return record_class(scenario, metrics, series, d.get("info", {}))


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
