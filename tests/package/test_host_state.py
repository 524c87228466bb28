"""weakgrid leaves its host alone: importing it, drawing its figures and building a grid
change neither matplotlib's backend nor its rcParams nor any logger that is not weakgrid's
(nor the warnings filters, nor NumPy's error and print options).

Each check runs in a fresh interpreter whose matplotlib backend is ``svg`` (not Agg), so
that a switch to Agg (what ``weakgrid.study.figures`` did at import) is seen.
"""

import json
import logging
import os
import subprocess
import sys
import textwrap

import pytest

from weakgrid.logs import quiet_loggers

_PRELUDE = """
import json, logging, pkgutil, importlib
import matplotlib
import numpy, scipy, pandas, pandapower, dask.distributed  # third-party imports first
try:
    import andes  # noqa: F401
except ImportError:
    pass

def state():
    rc = {k: repr(v) for k, v in matplotlib.rcParams.items() if k != "backend"}
    levels = {n: lg.level for n, lg in logging.Logger.manager.loggerDict.items()
              if isinstance(lg, logging.Logger) and not n.startswith("weakgrid")}
    levels["<root>"] = logging.getLogger().level
    import warnings
    other = {"warnings.filters": repr(warnings.filters), "numpy.geterr": repr(numpy.geterr()),
             "numpy.printoptions": repr(numpy.get_printoptions())}
    return {"backend": matplotlib.get_backend(), "rc": rc, "levels": levels, "other": other}

before = state()
"""

_COMPARE = """
after = state()
out = {"backend": [before["backend"], after["backend"]],
       "rc": sorted(k for k in before["rc"] if before["rc"][k] != after["rc"].get(k)),
       # a logger that did not exist before (or was a placeholder) counts as NOTSET
       "levels": sorted(n for n in set(before["levels"]) | set(after["levels"])
                        if before["levels"].get(n, 0) != after["levels"].get(n, 0)),
       # process-wide settings of the standard library and NumPy
       "other": sorted(k for k in before["other"] if before["other"][k] != after["other"][k])}
print("STATE" + json.dumps(out))
"""


def _run(body):
    code = _PRELUDE + textwrap.dedent(body) + _COMPARE
    env = dict(os.environ, MPLBACKEND="svg")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                       timeout=600)
    assert r.returncode == 0, r.stderr[-3000:]
    line = [ln for ln in r.stdout.splitlines() if ln.startswith("STATE")][-1]
    out = json.loads(line[5:])
    mods = [ln for ln in r.stdout.splitlines() if ln.startswith("MODULES")]
    if mods:
        out["modules"] = json.loads(mods[-1][7:])
    return out


def _assert_untouched(out):
    assert out["backend"] == ["svg", "svg"], f"backend switched: {out['backend']}"
    assert out["rc"] == [], f"rcParams changed: {out['rc']}"
    assert out["levels"] == [], f"logger levels changed: {out['levels']}"
    assert out["other"] == [], f"process-wide settings changed: {out['other']}"


#: the optional extras' top-level modules: a module that needs one may fail to import without it
_EXTRAS = {"andes", "kvxopt", "fmpy"}


@pytest.mark.slow
def test_importing_every_module_leaves_the_host_alone():
    out = _run("""
        import pathlib
        import weakgrid

        def stop(name):          # a package that fails to import is an error, not skipped
            raise RuntimeError(f"walk_packages could not import {name}")

        names = ["weakgrid"] + [m.name for m in pkgutil.walk_packages(
            weakgrid.__path__, "weakgrid.", onerror=stop)]
        failed = {}
        for name in names:
            try:
                importlib.import_module(name)
            except ImportError as e:   # an optional extra that is not installed
                failed[name] = e.name or str(e)
        root = pathlib.Path(weakgrid.__path__[0])
        files = sorted(".".join(("weakgrid",) + p.relative_to(root).with_suffix("").parts)
                       .removesuffix(".__init__") for p in root.rglob("*.py"))
        print("MODULES" + json.dumps({"names": names, "failed": failed, "files": files}))
    """)
    _assert_untouched(out)
    mods = out["modules"]
    # every module file of the package was reached (none hidden from the walk) ...
    assert sorted(mods["names"]) == mods["files"]
    # ... and imported, except where an optional extra is missing
    assert all(missing.split(".")[0] in _EXTRAS for missing in mods["failed"].values()), \
        mods["failed"]


def test_drawing_figures_and_maps_leaves_the_host_alone(tmp_path):
    _assert_untouched(_run(f"""
        import pandas as pd
        from weakgrid.study.maps import plot_map
        from weakgrid.study.figures import write_figures
        table = pd.DataFrame({{"a": [0.1, 0.1, 0.3, 0.3], "b": [1, 2, 1, 2],
                               "v": [0.9, 1.1, 0.8, 1.2], "verdict": ["holds", "not"] * 2}})
        plot_map(table, "a", "b", "v", verdict="verdict", center=1.0,
                 path={str(tmp_path / 'map.svg')!r})
        write_figures({{}}, {str(tmp_path)!r}, [{{"id": "f", "title": "t", "panels": ["sg_speed"],
                                                 "runs": [["nothing", "x"]]}}], formats=("svg",))
    """))
    svg = (tmp_path / "map.svg").read_text()
    assert "<text" in svg   # SVG text kept as text (svg.fonttype = none), for that call only


def test_building_a_grid_leaves_library_loggers_alone():
    _assert_untouched(_run("""
        from weakgrid.study.studyfile import load_study
        from weakgrid.study.build import build_setup
        build_setup(load_study("ieee9-sg-upqc"))
    """))


def test_quiet_loggers_restores_every_level():
    lg = logging.getLogger("weakgrid-test-lib")
    lg.setLevel(logging.NOTSET)
    high = logging.getLogger("weakgrid-test-high")
    high.setLevel(logging.CRITICAL)
    with pytest.raises(RuntimeError):
        with quiet_loggers("weakgrid-test-lib", "weakgrid-test-high"):
            assert lg.level == logging.ERROR
            assert high.level == logging.CRITICAL     # never lowered
            raise RuntimeError
    assert lg.level == logging.NOTSET and high.level == logging.CRITICAL
