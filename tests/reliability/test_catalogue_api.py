"""The catalogue of bad inputs through the public Python API (see README.md).

Each entry raises a weakgrid error (``WeakgridError`` or ``SimError``, never a bare
numpy/KeyError) whose message names the field or element and the value.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from weakgrid.game.errors import WeakgridError
from weakgrid.sim.errors import DataError, SimError, SimulationError

sys.path.insert(0, str(Path(__file__).parents[1] / "sim"))
from sim_cases import build_gti_upqc_sg, two_machine_case  # noqa: E402

ERRORS = (WeakgridError, SimError)


def _branch(R=0.0, X=0.3, B=0.0):
    c = two_machine_case()
    c["branch"][0, 2:5] = [R, X, B]
    return c


def _network(case):
    from weakgrid.sim.network import Network

    return Network(case)


def _islanded():
    c = two_machine_case()
    c["bus"] = np.vstack([c["bus"], [7, 1, 20, 5, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5]])
    n = _network(c)
    return n.solve_power_flow()


@pytest.fixture(scope="module")
def smib():
    """A small set-up system (SG + GTI + UPQC)."""
    return build_gti_upqc_sg()


def _sim(system, t_end, **kw):
    from weakgrid.sim.integrate import Simulator

    return Simulator(system, **kw).run(t_end)


def _run(system, t_end, events=()):
    from weakgrid.sim.integrate import Simulator

    return Simulator(system).run(t_end, events=events)


def _problem(edit):
    from weakgrid.models import problem_from_dict
    import tomllib
    from importlib import resources

    text = (resources.files("weakgrid") / "data" / "presets" / "case1-paper.toml").read_text()
    d = tomllib.loads(text)
    edit(d)
    return problem_from_dict(d)


def _controller(edit):
    from weakgrid.game.controller import controller_from_dict

    d = json.loads(json.dumps(_controller.record or {}))
    edit(d)
    return controller_from_dict(d)


def _from_dict(d):
    from weakgrid.game.controller import controller_from_dict

    return controller_from_dict(d)


def _fault(t_on, t_off):
    from weakgrid.sim.events import Fault

    return Fault(2, t_on, t_off)


API = [
    # simulator: time windows
    ("simulate-t-end-negative", lambda s: _run(s, -1.0), DataError, ["t_end", "-1.0"]),
    ("simulate-t-end-nan", lambda s: _run(s, math.nan), DataError, ["t_end", "nan"]),
    ("simulate-t-end-zero", lambda s: _run(s, 0.0), DataError, ["t_end", "0.0"]),
    ("simulate-t-end-text", lambda s: _run(s, "long"), DataError, ["t_end", "long"]),
    ("simulate-fault-after-end", lambda s: _run(s, 0.5, [_fault(1.0, 1.1)]), DataError, ["Fault", "1.0", "after the end"]),
    ("simulate-fault-reversed", lambda s: _run(s, 0.5, [_fault(0.3, 0.2)]), DataError, ["t_off", "0.2"]),
    ("simulate-dt-negative", lambda s: _sim(s, 1.0, dt=-0.01), DataError, ["dt", "-0.01"]),
    # network data
    ("branch-zero-impedance", lambda s: _network(_branch(R=0.0, X=0.0)), DataError, ["branch 0", "BR_X", "0.0", "non-zero impedance"]),
    ("branch-nan-X", lambda s: _network(_branch(X=math.nan)), DataError, ["branch 0", "BR_X", "nan"]),
    ("branch-inf-B", lambda s: _network(_branch(B=math.inf)), DataError, ["branch 0", "BR_B", "inf"]),
    ("bus-nan-load", lambda s: _network({**two_machine_case(), "bus": np.where(np.arange(13) == 2, math.nan, two_machine_case()["bus"])}), DataError, ["bus 1", "PD", "nan"]),
    ("islanded-bus", lambda s: _islanded(), DataError, ["bus 7", "islanded"]),
    # problems, meshes, costs
    ("problem-Q-text", lambda s: _problem(lambda d: d["cost"].update(Q="abc")), WeakgridError, ["cost.Q", "abc"]),
    ("problem-max-outer-text", lambda s: _problem(lambda d: d["solver"].update(max_outer="many")), WeakgridError, ["solver.max_outer", "many"]),
    ("problem-mesh-3x3", lambda s: _problem(lambda d: d["mesh"].update(step=[1.0, 10.0])).train(), WeakgridError, ["mesh.step", "too few mesh points"]),
    ("mesh-step-text", lambda s: __import__("weakgrid.game", fromlist=["GridMesh"]).GridMesh([-1, -1], [1, 1], "fine"), WeakgridError, ["mesh.step", "fine"]),
    ("cost-gamma-negative", lambda s: __import__("weakgrid.game", fromlist=["GameCost"]).GameCost(np.eye(2), np.eye(2), np.eye(1), -1.0), WeakgridError, ["gamma", "-1"]),
    # controller records
    ("controller-list", lambda s: _from_dict([1, 2]), WeakgridError, ["controller file", "list"]),
    ("controller-nan-weight", lambda s: _controller(lambda d: d["weights"].__setitem__(0, math.nan)), WeakgridError, ["weights", "NaN"]),
    ("controller-gamma-negative", lambda s: _controller(lambda d: d["problem"]["cost"].update(gamma=-5)), WeakgridError, ["gamma", "-5"]),
]


@pytest.fixture(scope="module", autouse=True)
def _record():
    from weakgrid.models import load_preset

    _controller.record = load_preset("case1-paper").train().to_dict()


@pytest.mark.parametrize("case", API, ids=[c[0] for c in API])
def test_api_bad_input(case, smib):
    name, call, kind, needles = case
    with pytest.raises(kind) as info:
        call(smib)
    assert isinstance(info.value, ERRORS)
    for needle in needles:
        assert needle in str(info.value), f"{needle!r} missing from: {info.value}"


def test_undeclared_negative_reactance_is_accepted_with_a_warning():
    """Standard cases (MATPOWER's case300) have negative series reactances: said, not refused."""
    from weakgrid.sim.errors import DataWarning

    with pytest.warns(DataWarning, match=r"branch 0.*BR_X = -0.3.*series_capacitors"):
        n = _network(_branch(R=0.01, X=-0.3))
    assert n.branch[0, 3] == -0.3


def test_negative_resistance_is_accepted_with_a_warning():
    """Network equivalents (case9241pegase, ACTIVSg10k, PSS/E) have R < 0: said, not refused."""
    from weakgrid.sim.errors import DataWarning

    with pytest.warns(DataWarning, match=r"branch 0 \(1-2\) BR_R = -0.05.*negative_resistance"):
        n = _network(_branch(R=-0.05, X=0.3))
    assert n.branch[0, 2] == -0.05


def test_declared_series_capacitor_is_accepted():
    n = _network({**_branch(R=0.0, X=-0.1), "series_capacitors": [0]})
    assert n.branch[0, 3] == -0.1


def test_huge_step_is_diagnosed_as_a_step_problem():
    """Regression: was a bare Newton failure. A 0.5-s step against ms time constants."""
    from weakgrid.sim.integrate import Simulator

    s = build_gti_upqc_sg()
    with pytest.warns(RuntimeWarning), pytest.raises(SimulationError) as info:
        Simulator(s, dt=0.5).run(10.0, events=[_fault(1.0, 1.1)])
    msg = str(info.value)
    assert "dt = 0.5 s is too large relative to the fastest time constant" in msg


def test_json_writer_never_writes_nan(tmp_path):
    from weakgrid.fileio import write_json_atomic

    p = write_json_atomic(tmp_path / "a.json", {"x": math.nan, "y": [1.0, math.inf],
                                                 "z": np.float64("nan")})
    assert json.loads(p.read_text(), parse_constant=pytest.fail) == {"x": None,
                                                                    "y": [1.0, None],
                                                                    "z": None}


def test_safe_name_cannot_leave_the_folder():
    from weakgrid.fileio import safe_name

    for bad in ("../x", "..", "/etc/passwd", "a/../../b", "..\\x", ""):
        s = safe_name(bad)
        assert s and "/" not in s and "\\" not in s and ".." not in s and s not in (".", "..")
