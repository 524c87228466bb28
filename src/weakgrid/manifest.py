"""Which files of an output folder weakgrid wrote: it deletes and overwrites only those.

Layer-neutral (like :mod:`weakgrid.fileio`). An output folder (``run -o``, ``reproduce -o``,
``sweep -o``) holds a manifest, ``.weakgrid-manifest.json``, listing the files weakgrid
writes there (relative paths), written atomically. Before a command writes, it claims the
files it is about to write (:meth:`Manifest.claim`): a file that exists and is not listed is
the user's, and the command stops naming it and the fix (move it, another folder, or
``--force``). Clean-ups (:meth:`Manifest.remove`) delete only listed files; anything else in
the folder is left alone. A file is listed before it is written, so that a run killed between
the two leaves at most a listed name without a file, never a file of weakgrid's that is not
listed.
"""

from __future__ import annotations

import json
import logging
from pathlib import Path

from .fileio import write_json_atomic

__all__ = ["Manifest", "MANIFEST_NAME"]

MANIFEST_NAME = ".weakgrid-manifest.json"
FORMAT = "weakgrid-manifest/1"
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

    def _read(self) -> set:
        if not self.path.exists():
            return set()
        try:
            d = json.loads(self.path.read_text(encoding="utf-8"))
            if not (isinstance(d, dict) and d.get("format") == FORMAT
                    and isinstance(d.get("files"), list)
                    and all(isinstance(f, str) for f in d["files"])):
                raise ValueError("not a weakgrid manifest")
        except (OSError, ValueError) as exc:
            raise _parameter_error()(
                self.option, str(self.folder),
                f"its {MANIFEST_NAME} is not weakgrid's manifest ({exc}); weakgrid cannot tell "
                "its own files from yours there. Fix: write to another folder") from None
        return set(d["files"])

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
        """Whether weakgrid wrote (or is about to write) ``path``."""
        return self.rel(path) in self.files

    def foreign(self, paths) -> list[Path]:
        """The existing files among ``paths`` that weakgrid did not write."""
        return [Path(p) for p in paths if Path(p).exists() and not self.owns(p)]

    def check(self, paths, force: bool = False) -> None:
        """Refuse (naming the file and the fix) if one of ``paths`` exists and is not
        weakgrid's, unless ``force``; writes nothing."""
        paths = list(paths)
        theirs = self.foreign(paths)
        if theirs and not force:
            more = f" (and {len(theirs) - 1} more: {', '.join(p.name for p in theirs[1:4])}" \
                   f"{' …' if len(theirs) > 4 else ''})" if len(theirs) > 1 else ""
            raise _parameter_error()(
                self.option, str(self.folder),
                f"{theirs[0]} is in the way: weakgrid wants to write that name but did not "
                f"write the file there{more}; it is left alone. Fix: move it, give another "
                f"output folder, or --force to overwrite it")

    def claim(self, paths, force: bool = False) -> None:
        """List ``paths`` as weakgrid's before writing them; refuse if one exists and is not
        weakgrid's (unless ``force``), as :meth:`check`."""
        paths = list(paths)
        self.check(paths, force)
        rels = [self.rel(p) for p in paths]
        new = set(rels) - self.files
        if new or not self.path.exists():
            self.files |= new
            self.save()

    def save(self) -> None:
        write_json_atomic(self.path, {"format": FORMAT, "files": sorted(self.files)})

    def remove(self, paths) -> list[Path]:
        """Delete the listed files among ``paths`` (others are left alone); returns those
        deleted."""
        gone = []
        for p in paths:
            p = Path(p)
            if self.owns(p):
                if p.is_file():
                    p.unlink()
                    gone.append(p)
                self.files.discard(self.rel(p))
        if gone:
            self.save()
        return gone

    def listed_under(self, sub: str) -> list[Path]:
        """The listed files in subfolder ``sub`` (direct children)."""
        return [self.folder / f for f in sorted(self.files)
                if Path(f).parent.as_posix() == sub]
