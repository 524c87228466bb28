"""Finished runs cached under a content hash of their full input (:mod:`weakgrid.hashing`).

The key of a run is the SHA-256 of its input (canonical JSON), the name of the
function that runs it and a fingerprint of the package's code (every ``.py``
and data file of :mod:`weakgrid`), so a changed input or a changed code never
reuses a stale result, and an interrupted sweep resumes where it stopped. Each
run is one JSON file written atomically (plus its signals as Parquet, on
request): a result is either complete on disk or absent. Each record carries a checksum of
its content and of its signals file; a record that fails it is refused with a warning and
its run is done again.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path

from ..fileio import replace_atomic, write_json_atomic
from ..hashing import canonical_json, checksum_ok, code_fingerprint, content_key, with_checksum

__all__ = ["ResultCache", "code_fingerprint", "run_key", "canonical_json"]

_log = logging.getLogger(__name__)


def _func_name(run) -> str:
    f = getattr(run, "func", run)  # functools.partial
    return f"{getattr(f, '__module__', '?')}.{getattr(f, '__qualname__', repr(f))}"


def run_key(inputs: dict, run=None) -> str:
    """The cache key of a run: hash of its input, its function (and a partial's keywords) and
    the code (hex, 24 chars; :func:`weakgrid.hashing.content_key`)."""
    return content_key({"inputs": inputs, "run": _func_name(run) if run is not None else "",
                        "keywords": getattr(run, "keywords", None)})


def _write_parquet(table, path):
    if hasattr(table, "to_parquet"):
        table.to_parquet(path, index=False)
    else:
        import pyarrow.parquet as pq

        pq.write_table(table, path)


class ResultCache:
    """A folder of finished runs, one ``<key>.json`` each (and ``<key>.parquet`` signals).

    Parameters
    ----------
    folder : str or Path
        Created if missing (unless ``create`` is false: a missing folder holds nothing).
    """

    def __init__(self, folder, create: bool = True):
        self.folder = Path(folder)
        if create:
            self.folder.mkdir(parents=True, exist_ok=True)

    def path(self, key: str) -> Path:
        return self.folder / f"{key}.json"

    def get(self, key: str):
        """The cached record of run ``key``, or None (a damaged file counts as absent)."""
        p = self.path(key)
        if not p.is_file():
            return None
        try:
            rec = json.loads(p.read_text())
        except (OSError, ValueError):
            return None
        if not isinstance(rec, dict) or rec.get("key") != key:
            return None
        files = [self.folder / rec["signals_file"]] if rec.get("signals_file") else []
        if not checksum_ok(rec, files):
            _log.warning("the cached run %s does not match its checksum (edited or damaged); "
                         "it is run again", p)
            return None
        return rec

    def put(self, record: dict, signals=None) -> Path:
        """Store a finished run (atomically; signals first, so a record implies its signals)."""
        key = record["key"]
        if signals is not None:   # a DataFrame, or a pyarrow Table (a run file's)
            replace_atomic(self.folder / f"{key}.parquet", lambda tmp: _write_parquet(signals, tmp))
            record = dict(record, signals_file=f"{key}.parquet")
        files = [self.folder / record["signals_file"]] if record.get("signals_file") else []
        return write_json_atomic(self.path(key), with_checksum(record, files))

    def signals_path(self, key: str) -> Path:
        return self.folder / f"{key}.parquet"
