"""Which files of an output folder weakgrid wrote: it deletes and overwrites only those.

Layer-neutral (like :mod:`weakgrid.fileio`). An output folder (``run -o``, ``reproduce -o``,
``sweep -o``) holds a manifest, ``.weakgrid-manifest.json``, listing the files weakgrid
writes there (relative paths), written atomically. Before a command writes, it claims the
files it is about to write (:meth:`Manifest.claim`): a file that exists and is not listed is
the user's, and the command stops naming it and the fix (move it, another folder, or
``--force``). Clean-ups (:meth:`Manifest.remove`) delete only listed files; anything else in
the folder is left alone. A file is listed before it is written, so that a run killed between
the two leaves at most a listed name without a file, never a file of weakgrid's that is not
listed. Once written, a file's SHA-256 is recorded (:meth:`Manifest.record`,
:func:`weakgrid.hashing.file_sha256`): a listed file whose content no longer matches (the
user's file swapped in, or one edited by hand) is the user's again — left alone, reported,
never overwritten or deleted without ``--force``. A file claimed but not yet recorded (a run
killed between the write and the record) is weakgrid's by its name.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path

from .fileio import write_json_atomic
from .hashing import file_sha256

__all__ = ["Manifest", "MANIFEST_NAME"]

MANIFEST_NAME = ".weakgrid-manifest.json"
FORMAT = "weakgrid-manifest/2"   # files: {relative path: SHA-256 or null (not yet written)}
_FORMAT_1 = "weakgrid-manifest/1"  # files: [relative path] (read: no content recorded)
_log = logging.getLogger(__name__)


def _parameter_error():
    from .game.errors import ParameterError

    return ParameterError


class Manifest:
    """The manifest of output folder ``folder`` (read at creation; missing: nothing listed).

    Parameters
    ----------
    folder : str or Path
        The output folder the user gave.
    option : str
        The command-line option that named the folder (in error messages).
    """

    def __init__(self, folder, option: str = "--output"):
        self.folder = Path(folder)
        self.path = self.folder / MANIFEST_NAME
        self.option = option
        self.files = self._read()

    def _read(self) -> dict:
        """``{relative path: SHA-256 or None}`` of the manifest on disk (none: empty)."""
        if not self.path.exists():
            return {}
        try:
            d = json.loads(self.path.read_text(encoding="utf-8"))
            files = d.get("files") if isinstance(d, dict) else None
            if d.get("format") == _FORMAT_1 and isinstance(files, list) and \
                    all(isinstance(f, str) for f in files):
                return dict.fromkeys(files)
            if not (d.get("format") == FORMAT and isinstance(files, dict)
                    and all(isinstance(h, (str, type(None))) for h in files.values())):
                raise ValueError("not a weakgrid manifest")
        except (OSError, ValueError) as exc:
            raise _parameter_error()(
                self.option, str(self.folder),
                f"its {MANIFEST_NAME} is not weakgrid's manifest ({exc}); weakgrid cannot tell "
                "its own files from yours there. Fix: write to another folder") from None
        return dict(files)

    def rel(self, path) -> str:
        """``path`` relative to the folder (POSIX form); it must lie inside the folder."""
        p = Path(path)
        try:
            rel = p.relative_to(self.folder)
            if ".." in rel.parts:
                raise ValueError(rel)
            return rel.as_posix()
        except ValueError:
            raise _parameter_error()(self.option, str(p), f"lies outside the output folder "
                                     f"{self.folder}; weakgrid writes only there") from None

    def owns(self, path) -> bool:
        """Whether weakgrid wrote (or is about to write) ``path``: it is listed and, if its
        content was recorded and it exists, its content is still the one weakgrid wrote."""
        rel = self.rel(path)
        if rel not in self.files:
            return False
        return not self.changed(path)

    def changed(self, path) -> bool:
        """Whether ``path`` is listed with a recorded content that its file no longer has."""
        want = self.files.get(self.rel(path))
        p = Path(path)
        if want is None or not p.is_file():
            return False
        try:
            return file_sha256(p) != want
        except OSError:
            return True

    def foreign(self, paths) -> list[Path]:
        """The existing files among ``paths`` that weakgrid did not write (or whose content
        changed since it wrote them)."""
        return [Path(p) for p in paths if Path(p).exists() and not self.owns(p)]

    def check(self, paths, force: bool = False) -> None:
        """Refuse (naming the file and the fix) if one of ``paths`` exists and is not
        weakgrid's, unless ``force``; writes nothing."""
        paths = list(paths)
        theirs = self.foreign(paths)
        if theirs and not force:
            more = f" (and {len(theirs) - 1} more: {', '.join(p.name for p in theirs[1:4])}" \
                   f"{' …' if len(theirs) > 4 else ''})" if len(theirs) > 1 else ""
            how = ("its content changed since weakgrid wrote it (a file of yours, or one "
                   "edited)" if self.changed(theirs[0]) else "weakgrid did not write the file "
                   "there")
            raise _parameter_error()(
                self.option, str(self.folder),
                f"{theirs[0]} is in the way: weakgrid wants to write that name but {how}"
                f"{more}; it is left alone. Fix: move it, give another "
                f"output folder, or --force to overwrite it")

    def claim(self, paths, force: bool = False) -> None:
        """List ``paths`` as weakgrid's before writing them; refuse if one exists and is not
        weakgrid's (unless ``force``), as :meth:`check`. Their content is recorded again
        once written (:meth:`record`)."""
        paths = list(paths)
        self.check(paths, force)
        rels = [self.rel(p) for p in paths]
        pending = {r for r in rels if self.files.get(r, "") is not None}
        if pending or not self.path.exists():
            self.files.update(dict.fromkeys(pending))
            self.save()

    def record(self, paths) -> None:
        """Record the content (SHA-256) of the listed files among ``paths`` that exist, once
        weakgrid finished writing them."""
        new = {}
        for p in paths:
            rel = self.rel(p)
            if rel in self.files and Path(p).is_file():
                h = file_sha256(p)
                if self.files[rel] != h:
                    new[rel] = h
        if new:
            self.files.update(new)
            self.save()

    def save(self) -> None:
        write_json_atomic(self.path, {"format": FORMAT,
                                      "files": dict(sorted(self.files.items()))})

    def remove(self, paths) -> list[Path]:
        """Delete the listed files among ``paths`` (others are left alone; a listed file
        whose content changed since weakgrid wrote it is the user's: left alone, unlisted and
        reported as a warning); returns those deleted."""
        gone, kept = [], []
        for p in paths:
            p = Path(p)
            if self.rel(p) not in self.files:
                continue
            if self.changed(p):
                kept.append(p)
            elif p.is_file():
                p.unlink()
                gone.append(p)
            self.files.pop(self.rel(p), None)
        if kept:
            _log.warning("left alone %d file(s) weakgrid wrote whose content has changed since "
                         "(yours now): %s", len(kept), ", ".join(str(p) for p in kept[:6]))
        if gone or kept:
            self.save()
        return gone

    def listed_under(self, sub: str) -> list[Path]:
        """The listed files in subfolder ``sub`` (direct children)."""
        return [self.folder / f for f in sorted(self.files)
                if Path(f).parent.as_posix() == sub]
