"""Atomic file writes: a finished result is never lost to a half-written file.

Layer-neutral (imported by every layer). Every file the package writes goes
through :func:`replace_atomic` (or :func:`replace_many_atomic` for outputs made of
several files): the content is written to a temporary file in the target's
folder, flushed and ``fsync``-ed, given an ordinary file mode (``0o666`` minus the
umask, like ``open()``), then renamed over the target. A failure at any point
(disk full, permission, Ctrl-C) leaves the previous file untouched and removes
the temporary.
"""

from __future__ import annotations

import json
import math
import os
import re
import shutil
import tempfile
from pathlib import Path

__all__ = ["write_text_atomic", "write_bytes_atomic", "write_json_atomic", "replace_atomic",
           "replace_many_atomic", "write_texts_atomic", "savefig_atomic", "safe_name",
           "check_file_name", "json_safe"]


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _fsync_file(path):
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _fsync_dir(folder):
    try:
        fd = os.open(folder, os.O_RDONLY)
    except OSError:  # pragma: no cover (platforms without directory fds)
        return
    try:
        os.fsync(fd)
    except OSError:  # pragma: no cover
        pass
    finally:
        os.close(fd)


def _target(path) -> Path:
    path = Path(path)
    if path.is_dir():
        raise IsADirectoryError(21, "is a folder, not a file: give a file name", str(path))
    path.parent.mkdir(parents=True, exist_ok=True)
    return path


def _temp_beside(path: Path) -> str:
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    except OSError as exc:  # name the target, not the temporary, in the error
        exc.filename = str(path)
        raise
    os.close(fd)
    return tmp


def _finish(tmp):
    """fsync the written temporary and give it an ordinary mode (mkstemp makes 0o600)."""
    _fsync_file(tmp)
    os.chmod(tmp, 0o666 & ~_umask())


def _name_target(exc, path):
    """An OSError without a file name (ENOSPC from write/fsync) gets the target's."""
    if isinstance(exc, OSError) and (exc.filename is None or str(exc.filename).endswith(".tmp")):
        exc.filename = str(path)


def replace_atomic(path, write) -> Path:
    """Call ``write(tmp_path)`` on a temporary file beside ``path``, fsync it, rename it.

    ``write`` may be any function writing a file at the path it gets (e.g.
    ``DataFrame.to_parquet``, ``Figure.savefig``).
    """
    path = _target(path)
    tmp = _temp_beside(path)
    try:
        write(tmp)
        _finish(tmp)
        os.replace(tmp, path)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        _name_target(exc, path)
        raise
    _fsync_dir(path.parent)
    return path


def replace_many_atomic(writers: dict) -> list[Path]:
    """Write several files that must appear together or not at all.

    ``writers`` maps each target path to its ``write(tmp_path)`` function. Every
    file is first written and fsync-ed to a temporary beside its target; only
    when all succeeded are they renamed, in order. If a rename fails midway the
    targets already renamed are restored from backups of their previous
    content, so the set is never left half old and half new.
    """
    targets = [_target(p) for p in writers]
    tmps = []
    try:
        for path, write in zip(targets, writers.values()):
            tmp = _temp_beside(path)
            tmps.append(tmp)
            write(tmp)
            _finish(tmp)
    except BaseException as exc:
        for t in tmps:
            if os.path.exists(t):
                os.unlink(t)
        _name_target(exc, targets[len(tmps) - 1] if tmps else targets[0])
        raise
    backups, done = {}, []
    try:
        for path in targets:
            if path.exists():
                bak = f"{_temp_beside(path)}.bak"
                os.unlink(bak[:-4])
                try:
                    os.link(path, bak)  # a second name for the previous content
                except OSError:  # file systems without hard links
                    shutil.copy2(path, bak)
                backups[path] = bak
        for path, tmp in zip(targets, tmps):
            os.replace(tmp, path)
            done.append(path)
    except BaseException:
        for path in done:
            if path in backups:
                os.replace(backups.pop(path), path)
            else:
                os.unlink(path)
        for t in tmps:
            if os.path.exists(t):
                os.unlink(t)
        raise
    finally:
        for bak in backups.values():
            if os.path.exists(bak):
                os.unlink(bak)
    for folder in {p.parent for p in targets}:
        _fsync_dir(folder)
    return targets


def _text_writer(text: str):
    def w(tmp):
        with open(tmp, "w", encoding="utf-8") as fh:
            fh.write(text)
    return w


def write_text_atomic(path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    return replace_atomic(path, _text_writer(text))


def write_bytes_atomic(path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically."""
    def w(tmp):
        with open(tmp, "wb") as fh:
            fh.write(data)
    return replace_atomic(path, w)


def write_texts_atomic(files: dict) -> list[Path]:
    """Several text files (path → text) that appear together or not at all."""
    return replace_many_atomic({p: _text_writer(t) for p, t in files.items()})


def json_safe(obj):
    """``obj`` with every non-finite float replaced by ``None`` (JSON has no NaN/inf)."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: json_safe(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [json_safe(v) for v in obj]
    if hasattr(obj, "tolist") and hasattr(obj, "dtype"):  # numpy scalars and arrays
        return json_safe(obj.tolist())
    return obj


def write_json_atomic(path, obj) -> Path:
    """Write ``obj`` as strict JSON (NaN and infinities written as ``null``)."""
    return write_text_atomic(path, json.dumps(json_safe(obj), indent=1, allow_nan=False) + "\n")


def savefig_atomic(fig, path, **kwargs) -> Path:
    """``fig.savefig(path)`` through the atomic writer (format from the target's suffix)."""
    import matplotlib

    path = Path(path)
    fmt = kwargs.pop("format", path.suffix.lstrip(".") or None)

    def save(tmp):
        # SVG text kept as text (labels stay searchable), for this call only: the host's
        # rcParams are left alone
        with matplotlib.rc_context({"svg.fonttype": "none"}):
            fig.savefig(tmp, format=fmt, **kwargs)

    return replace_atomic(path, save)


_UNSAFE = re.compile(r"[^A-Za-z0-9_.+-]")


def safe_name(name, default: str = "unnamed") -> str:
    """A file-name component made from ``name`` (e.g. a name read from a file).

    Path separators, ``..`` and other characters outside ``[A-Za-z0-9_.+-]`` are
    replaced with ``_`` so that the result can never leave the folder it is
    joined to; an empty or dot-only result becomes ``default``.
    """
    s = _UNSAFE.sub("_", str(name)).strip(".")
    s = re.sub(r"\.{2,}", "_", s)
    return s[:120] or default


_FILE_NAME = re.compile(r"[A-Za-z0-9_+-][A-Za-z0-9_.+-]{0,119}")


def check_file_name(value, field: str) -> str:
    """``value`` (a name read from a file: a study name, a scenario id, a figure id, a
    controller or load-level name…) checked where it becomes part of an output file name.

    Only letters, digits and ``_ . + -`` are allowed, not starting with a dot, without
    ``..``, at most 120 characters: the name can never be a path separator, a parent folder
    or an absolute path, so every output stays in the folder the user gave.

    Raises
    ------
    weakgrid.game.errors.ParameterError
        Naming ``field``, the value and the fix (a name made of the allowed characters).
    """
    if isinstance(value, str) and _FILE_NAME.fullmatch(value) and ".." not in value:
        return value
    from .game.errors import ParameterError

    raise ParameterError(field, value, "it becomes part of an output file name: use only "
                         "letters, digits and _ . + - (no path separator, no '..', not starting "
                         f"with '.', at most 120 characters), e.g. {safe_name(value)!r}")
