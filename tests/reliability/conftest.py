"""Shared pieces of the bad-input catalogue.

Every catalogue entry runs the real CLI in-process (``main([...])``) in a fresh
folder holding a valid problem file, a valid controller file and a "precious"
earlier result, and checks four things: the exit code, that stderr names the
field/element and the value, that no traceback was printed, and that every file
that existed before is byte-for-byte unchanged (no temporary left behind).
"""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path

import pytest

from weakgrid.cli.main import main

PRESET = Path(str(resources.files("weakgrid") / "data" / "presets" / "case1-paper.toml"))
STUDY = Path(str(resources.files("weakgrid") / "data" / "studies" / "case1-weak-grid.toml"))


@pytest.fixture(scope="session")
def controller_record():
    """A controller of case1-paper, trained once (as the dict its file holds)."""
    from weakgrid.models import load_preset

    return load_preset("case1-paper").train().to_dict()


class Workspace:
    """A folder with valid inputs and a precious earlier result."""

    def __init__(self, root: Path, record: dict):
        self.root = root
        self.problem = root / "problem.toml"
        self.problem.write_text(PRESET.read_text())
        self.controller = root / "ctl.json"
        self.controller.write_text(json.dumps(record))
        self.record = record
        self.precious = root / "precious.json"
        self.precious.write_text('{"earlier": "result"}\n')
        self.before = None

    def problem_with(self, edit) -> Path:
        """A copy of the problem file changed by ``edit(text) -> text``."""
        p = self.root / "edited.toml"
        text = edit(PRESET.read_text())
        assert text != PRESET.read_text(), "the edit changed nothing"
        p.write_text(text)
        return p

    @property
    def study(self) -> Path:
        """A copy of the shipped study case1-weak-grid (made on first use)."""
        p = self.root / "study.toml"
        if not p.exists():
            p.write_text(STUDY.read_text())
        return p

    def study_with(self, old: str, new: str, *more: str) -> Path:
        """A copy of the study with the first ``old`` replaced by ``new`` (and so on for
        further pairs ``old2, new2, …`` in ``more``)."""
        text = STUDY.read_text()
        pairs = [(old, new)] + list(zip(more[::2], more[1::2]))
        for o, n in pairs:
            assert o in text, f"{o!r} is not in the study"
            text = text.replace(o, n, 1)
        p = self.root / "edited-study.toml"
        p.write_text(text)
        return p

    @staticmethod
    def closed_port() -> int:
        """A local TCP port with nobody listening (bound, then released)."""
        import socket

        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            return s.getsockname()[1]

    def controller_with(self, edit) -> Path:
        """A controller file whose record (a deep copy) is changed by ``edit(d)``."""
        d = json.loads(json.dumps(self.record))
        r = edit(d)
        d = r if isinstance(r, (list, str, dict)) else d
        p = self.root / "edited.controller.json"
        p.write_text(json.dumps(d) if not isinstance(d, str) else d)
        return p

    def snapshot(self):
        self.before = {p: p.read_bytes() for p in self.root.rglob("*") if p.is_file()}
        self.beside = sorted(p.name for p in self.root.parent.iterdir())

    def check_nothing_written(self, inside=()):
        """No new file under the workspace (but in the folders ``inside``) and none beside
        it (a name read from a file that escaped the output folder would land there)."""
        new = [p for p in self.root.rglob("*") if p.is_file() and p not in self.before
               and not any(Path(d) in p.parents for d in inside)]
        assert not new, f"files written: {new}"
        assert sorted(p.name for p in self.root.parent.iterdir()) == self.beside, \
            "a file or folder appeared beside the workspace (outside the output folder)"

    def check_untouched(self):
        after = {p for p in self.root.rglob("*") if p.is_file()}
        leftovers = [p.name for p in after if p.name.endswith(".tmp") or ".tmp." in p.name]
        assert not leftovers, f"temporary files left behind: {leftovers}"
        for p, data in self.before.items():
            assert p.exists() and p.read_bytes() == data, f"{p.name} was damaged"


@pytest.fixture
def ws(tmp_path, controller_record, monkeypatch):
    monkeypatch.chdir(tmp_path)
    return Workspace(tmp_path, controller_record)


@pytest.fixture
def cli(capsys):
    """``cli(argv)`` → (exit code, stdout, stderr) of ``main(argv)``; fails on a traceback."""
    def run(argv):
        code = main([str(a) for a in argv])
        out, err = capsys.readouterr()
        assert "Traceback" not in out + err, err
        return code, out, err
    return run

