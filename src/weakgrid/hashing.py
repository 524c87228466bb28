"""Content hashes and checksums: the one mechanism behind every cache key of the package
(layer-neutral).

* :func:`canonical_json` — equal inputs give equal text (sorted keys, canonical floats).
* :func:`code_fingerprint` — SHA-256 over the package's source and data files, so that a key
  made with :func:`content_key` changes whenever the code changes.
* :func:`content_key` — the key of a computation: its inputs and the code (sweep runs, study
  runs, training checkpoints).
* :func:`checksum` — of a record's own content, stored in the record and verified when it is
  read back, so that a damaged or hand-edited record is refused (and recomputed), not used.
* :func:`stamp_c` / :func:`stamped_c_ok` — the same for generated C text (a last comment line
  with the SHA-256 of the text above it): a hand-edited file is told from weakgrid's own.
"""

from __future__ import annotations

import functools
import hashlib
import json
import math
from pathlib import Path

from ._version import __version__

__all__ = ["canonical_json", "code_fingerprint", "content_key", "checksum", "file_sha256",
           "with_checksum", "checksum_ok", "stamp_c", "stamped_c_ok"]


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
    root = Path(__file__).resolve().parent
    h = hashlib.sha256(__version__.encode())
    for p in sorted(root.rglob("*")):
        if p.is_file() and p.suffix in (".py", ".toml", ".json", ".m") and \
                "__pycache__" not in p.parts:
            h.update(str(p.relative_to(root)).encode())
            h.update(p.read_bytes())
    return h.hexdigest()


def content_key(inputs, length: int = 24) -> str:
    """The key of a computation: SHA-256 (hex, ``length`` characters) of its ``inputs``
    (JSON-able) and of the code (:func:`code_fingerprint`)."""
    text = canonical_json({"inputs": inputs, "code": code_fingerprint()})
    return hashlib.sha256(text.encode()).hexdigest()[:length]


def checksum(obj) -> str:
    """SHA-256 (hex) of the canonical JSON of ``obj``."""
    return hashlib.sha256(canonical_json(obj).encode()).hexdigest()


def file_sha256(path) -> str:
    """SHA-256 (hex) of a file's bytes."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def with_checksum(record: dict, files=()) -> dict:
    """``record`` (canonical form) with ``"checksum"`` over its content and the bytes of
    ``files`` (e.g. the Parquet signals it describes), for :func:`checksum_ok`."""
    rec = _canon({k: v for k, v in record.items() if k != "checksum"})
    rec["checksum"] = checksum({"record": rec, "files": [file_sha256(p) for p in files]})
    return rec


def checksum_ok(record: dict, files=()) -> bool:
    """Whether ``record`` carries the checksum of its own content and of ``files``."""
    want = record.get("checksum") if isinstance(record, dict) else None
    if not isinstance(want, str):
        return False
    try:
        digests = [file_sha256(p) for p in files]
    except OSError:
        return False
    rec = _canon({k: v for k, v in record.items() if k != "checksum"})
    return checksum({"record": rec, "files": digests}) == want


_STAMP = "/* weakgrid checksum sha256:{} */\n"


def stamp_c(text: str) -> str:
    """Generated C ``text`` with a last comment line holding the SHA-256 of the text above it
    (:func:`stamped_c_ok`)."""
    text = text if text.endswith("\n") else text + "\n"
    return text + _STAMP.format(hashlib.sha256(text.encode()).hexdigest())


def stamped_c_ok(data: bytes) -> bool:
    """Whether ``data`` (a file's bytes) is C text stamped by :func:`stamp_c` and unchanged
    since (a hand edit, or a file of another origin, gives False)."""
    body, sep, last = data.rstrip(b"\n").rpartition(b"\n")
    if not sep:
        return False
    body += b"\n"
    want = _STAMP.format(hashlib.sha256(body).hexdigest()).encode()
    return last + b"\n" == want and data == body + want
