"""The package's metadata: licence, typing marker, a static version, and lower bounds that CI
installs (``.ci/lowest.txt``, job 4 of ``.ci/run``) for every base dependency and the ``fast``
extra's."""

import re
import subprocess
import sys
import tomllib
from pathlib import Path

import weakgrid

ROOT = Path(__file__).resolve().parents[2]


def _project():
    return tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]


def _name(req):
    return re.match(r"[A-Za-z0-9_.-]+", req).group(0).lower()


def test_licence_is_mit_with_its_file():
    p = _project()
    assert p["license"] == "MIT" and p["license-files"] == ["LICENSE"]
    assert (ROOT / "LICENSE").read_text().startswith("MIT License")
    assert "License ::" not in " ".join(p["classifiers"])   # SPDX expression, no classifier


def test_the_package_is_marked_typed():
    assert (Path(weakgrid.__file__).parent / "py.typed").is_file()
    assert "Typing :: Typed" in _project()["classifiers"]


def test_every_lower_bound_is_installed_by_the_lowest_versions_job():
    lowest = {}
    for line in (ROOT / ".ci" / "lowest.txt").read_text().splitlines():
        if line.strip() and not line.startswith("#"):
            name, version = line.split("==")
            lowest[name.lower()] = version.strip()
    # the base dependencies and the `fast` extra's (job 4 installs [test,fast]: numba's lowest
    # release against NumPy's lowest, the compiled kernels checked there too)
    reqs = _project()["dependencies"] + _project()["optional-dependencies"]["fast"]
    for req in reqs:
        m = re.fullmatch(r"([A-Za-z0-9_.-]+)(\[([a-z,]+)\])?>=([0-9.]+)", req)
        assert m, f"{req}: a base dependency has one lower bound and no upper bound"
        names = [m.group(1).lower()] + (m.group(3).split(",") if m.group(3) else [])
        for n in names:         # dask[distributed]: both dask and distributed at the bound
            assert lowest.get(n) == m.group(4) + ".*", (req, n, lowest.get(n))
    assert set(lowest) <= {_name(r) for r in reqs} | {"distributed"}


def test_the_version_is_static():
    """``import weakgrid`` reads no package metadata (0.53 s of a 0.6-s import once)."""
    code = "import sys, weakgrid; print(weakgrid.__version__, 'importlib.metadata' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert out == [weakgrid.__version__, "False"]
    assert re.fullmatch(r"\d+\.\d+\.\d+", weakgrid.__version__)
