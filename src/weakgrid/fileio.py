"""Atomic file writes: a finished result is never lost to a half-written file.

Layer-neutral (imported by every layer): write to a temporary file in the same
folder, then rename it over the target.
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

__all__ = ["write_text_atomic", "write_json_atomic", "replace_atomic"]


def replace_atomic(path, write) -> Path:
    """Call ``write(tmp_path)`` on a temporary file beside ``path``, then rename it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    os.close(fd)
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


def write_text_atomic(path, text: str) -> Path:
    """Write ``text`` to ``path`` atomically (temporary file + rename); return the path."""
    def w(tmp):
        with open(tmp, "w") as fh:
            fh.write(text)

    return replace_atomic(path, w)


def write_json_atomic(path, obj) -> Path:
    """Write ``obj`` as indented JSON to ``path`` atomically; return the path."""
    return write_text_atomic(path, json.dumps(obj, indent=1) + "\n")
