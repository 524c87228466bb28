"""A study's grid is read once per process (per grid, UPQC placement, load and case file), and
every setup gets its own copy: the runs on it are those on a freshly read grid."""

import copy
import dataclasses
import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from weakgrid.study import build
from weakgrid.study.build import build_setup
from weakgrid.study.runner import Run, run_scenario
from weakgrid.study.studyfile import load_study, set_path, study_from_dict

DATA = Path(__file__).resolve().parents[1] / "data"


@pytest.fixture
def counted(monkeypatch):
    """The grid builder with a call counter; an empty cache before and after."""
    calls = []
    real = build._build_network

    def counting(study, load):
        calls.append(load)
        return real(study, load)

    monkeypatch.setattr(build, "_build_network", counting)
    build._NETWORKS.clear()
    yield calls
    build._NETWORKS.clear()


def _arrays(setup):
    net = setup.system.network
    return [net.bus, net.gen, net.branch, net.pf.V]


def test_a_grid_is_read_once_and_every_setup_owns_its_copy(counted):
    st = load_study("ieee9-sg-upqc")
    a = build_setup(st, "base")
    a.system.network.branch[:, 3] *= 2.0      # a caller edits its grid
    b = build_setup(st, "base")
    assert counted == ["base"]                # read once
    build._NETWORKS.clear()
    c = build_setup(st, "base")               # read again: the reference
    assert len(counted) == 2
    for x, y in zip(_arrays(b), _arrays(c)):
        np.testing.assert_array_equal(x, y)   # the edit of a did not reach b
    assert b.design.to_dict() == c.design.to_dict()


def test_the_rating_shares_the_grid_the_placement_does_not(counted):
    st = load_study("ieee9-sg-upqc")
    build_setup(st, "base")
    rated = study_from_dict(set_path(copy.deepcopy(st.data), "upqc.rating", 0.3))
    assert build_setup(rated, "base").system.components["UPQC"].p["Vmax"][0] == 0.3
    assert len(counted) == 1                  # the grid does not depend on the rating
    placed = study_from_dict(set_path(copy.deepcopy(st.data), "upqc.insert.x", 0.03))
    build_setup(placed, "base")
    assert len(counted) == 2                  # another UPQC placement: another grid


def test_an_edited_case_file_is_read_again(counted, tmp_path):
    from test_grid_edits import pv_edits, pv_study

    shutil.copytree(DATA / "matpower", tmp_path / "matpower")
    gens = [{"name": f"G{b}", "bus": b, "machine": {
        "model": "GENCLS", "Sn": 100.0, "fn": 60.0, "M": 10.0 if b > 1 else 1e4, "D": 0.0,
        "ra": 0.0, "xd1": 0.06}} for b in (1, 2, 3)]
    grid = {"kind": "matpower", "file": "matpower/case9.m", **pv_edits(5, 345.0)}
    st = study_from_dict(pv_study(grid, 5, gens), base_dir=tmp_path)
    build_setup(st)
    build_setup(st)
    assert len(counted) == 1
    case = tmp_path / "matpower" / "case9.m"
    case.write_text(case.read_text() + "\n% edited\n")
    build_setup(st)
    assert len(counted) == 2                  # the file changed: read again


def _same(metrics):
    """The metrics as comparable text (NaN equal to NaN), the wall time left out."""
    return json.dumps({k: v for k, v in metrics.items() if k != "wall_s"}, sort_keys=True,
                      default=str)


def test_a_run_on_the_cached_grid_equals_a_run_on_a_fresh_one():
    st = load_study("ieee9-sg-upqc")
    sc = next(s for s in st.scenarios(False) if s["id"] == "fault-r")
    run = dataclasses.replace(Run.of(st, sc, "lqr"), t_end=1.2)
    build._NETWORKS.clear()
    fresh = run_scenario(st, run)
    cached = run_scenario(st, run)            # its grid from the cache
    build._NETWORKS.clear()
    assert _same(fresh.metrics) == _same(cached.metrics)
    assert fresh.results.names == cached.results.names
    np.testing.assert_array_equal(fresh.results.t, cached.results.t)
    np.testing.assert_array_equal(fresh.results.data, cached.results.data)
