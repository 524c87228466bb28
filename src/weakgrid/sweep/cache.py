"""Finished runs cached under a content hash of their full input.

The key of a run is the SHA-256 of its input (canonical JSON), the name of the
function that runs it and a fingerprint of the package's code (every ``.py``
and data file of :mod:`weakgrid`), so a changed input or a changed code never
reuses a stale result, and an interrupted sweep resumes where it stopped. Each
run is one JSON file written atomically (plus its signals as Parquet, on
request): a result is either complete on disk or absent.
"""

from __future__ import annotations

import functools
import hashlib
import json
import math
from pathlib import Path

from .. import __version__
from ..fileio import replace_atomic, write_json_atomic

__all__ = ["ResultCache", "code_fingerprint", "run_key", "canonical_json"]


def _canon(obj):
    """JSON-able canonical form: tuples → lists, numpy scalars → Python, finite floats."""
    if isinstance(obj, dict):
        return {str(k): _canon(v) for k, v in sorted(obj.items(), key=lambda kv: str(kv[0]))}
    if isinstance(obj, (list, tuple)):
        return [_canon(v) for v in obj]
    if hasattr(obj, "tolist") and not isinstance(obj, (str, bytes)):
        return _canon(obj.tolist())
    if isinstance(obj, float):
        if math.isnan(obj):
            return None
        if math.isinf(obj):
            return "Infinity" if obj > 0 else "-Infinity"
        return float(repr(obj)) if obj != 0 else 0.0
    if obj is None or isinstance(obj, (bool, int, str)):
        return obj
    return repr(obj)


def canonical_json(obj) -> str:
    """A canonical JSON text of ``obj`` (sorted keys, no spaces): equal inputs, equal text."""
    return json.dumps(_canon(obj), sort_keys=True, separators=(",", ":"), allow_nan=False)


@functools.lru_cache(maxsize=1)
def code_fingerprint() -> str:
    """SHA-256 over the package's source and data files (relative path and content)."""
    root = Path(__file__).resolve().parents[1]
    h = hashlib.sha256(__version__.encode())
    for p in sorted(root.rglob("*")):
        if p.is_file() and p.suffix in (".py", ".toml", ".json", ".m") and \
                "__pycache__" not in p.parts:
            h.update(str(p.relative_to(root)).encode())
            h.update(p.read_bytes())
    return h.hexdigest()


def _func_name(run) -> str:
    f = getattr(run, "func", run)  # functools.partial
    return f"{getattr(f, '__module__', '?')}.{getattr(f, '__qualname__', repr(f))}"


def run_key(inputs: dict, run=None) -> str:
    """The cache key of a run: hash of its input, its function and the code (hex, 24 chars)."""
    h = hashlib.sha256()
    h.update(canonical_json(inputs).encode())
    h.update(_func_name(run).encode() if run is not None else b"")
    if run is not None and hasattr(run, "keywords"):
        h.update(canonical_json(run.keywords).encode())
    h.update(code_fingerprint().encode())
    return h.hexdigest()[:24]


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
        return rec if isinstance(rec, dict) and rec.get("key") == key else None

    def put(self, record: dict, signals=None) -> Path:
        """Store a finished run (atomically; signals first, so a record implies its signals)."""
        key = record["key"]
        if signals is not None:
            replace_atomic(self.folder / f"{key}.parquet",
                           lambda tmp: signals.to_parquet(tmp, index=False))
            record = dict(record, signals_file=f"{key}.parquet")
        return write_json_atomic(self.path(key), _canon(record))

    def signals_path(self, key: str) -> Path:
        return self.folder / f"{key}.parquet"
