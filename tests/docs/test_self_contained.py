"""The repository points at nothing outside itself (no specification or issue tracker paths).

The method is restated in ``docs/theory.md``; findings are in ``docs/findings.md``. A clone
must be complete: references to files that live beside the repository are errors.
"""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
FORBIDDEN = ("SPEC §", "SPEC.md", "../shared", "shared/paper")
SUFFIXES = {".py", ".md", ".toml", ".txt", ".rst", ".cfg", ".m", ".json", ""}


def repository_files():
    for top in ("src", "tests", "docs", "benchmarks", ".ci"):
        for p in sorted((ROOT / top).rglob("*")):
            if p.is_file() and p.suffix in SUFFIXES and "_build" not in p.parts \
                    and "generated" not in p.parts and p != Path(__file__).resolve() \
                    and not any(q.endswith(".egg-info") for q in p.parts):  # build output
                yield p
    for name in ("README.md", "pyproject.toml"):
        yield ROOT / name


@pytest.mark.parametrize("path", list(repository_files()), ids=lambda p: str(p.relative_to(ROOT)))
def test_no_reference_outside_the_repository(path):
    text = path.read_text(errors="replace")
    found = [s for s in FORBIDDEN if s in text]
    assert not found, f"{path.relative_to(ROOT)} refers outside the repository: {found}"
