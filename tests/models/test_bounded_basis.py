"""The basis of the rating-aware (bounded) problem: ``[basis] bounded`` of a problem file."""

import tomllib
from importlib import resources

import numpy as np
import pytest

from weakgrid.game import full_monomials, paper_basis
from weakgrid.game.errors import ParameterError
from weakgrid.game.rollout import rollout
from weakgrid.models import load_preset
from weakgrid.models.problem import problem_from_dict


def _raw(name="case1-paper"):
    with (resources.files("weakgrid") / "data" / "presets" / f"{name}.toml").open("rb") as f:
        return tomllib.load(f)


@pytest.mark.parametrize("name", ["case1-paper", "case2-paper"])
def test_the_presets_train_the_bounded_problem_on_the_full_degree_4_basis(name):
    p = load_preset(name)
    assert p.basis == paper_basis()                   # the paper's problem: the paper's basis
    b = p.with_input_bound(0.1)
    assert b.basis == full_monomials(2, 4)
    assert b.with_input_bound(None).basis == paper_basis()
    # a bound written in the file's [cost] takes the bounded basis too
    raw = _raw(name)
    raw["cost"]["u_bound"] = 0.1
    assert problem_from_dict(raw).basis == full_monomials(2, 4)


def test_without_a_bounded_table_the_bounded_problem_keeps_its_basis():
    raw = _raw()
    del raw["basis"]["bounded"]
    assert problem_from_dict(raw).with_input_bound(0.15).basis == paper_basis()


def test_a_bad_bounded_basis_names_its_field():
    raw = _raw()
    raw["basis"]["bounded"] = {"kind": "fullest"}
    with pytest.raises(ParameterError, match=r"basis\.bounded\.kind"):
        problem_from_dict(raw)
    raw["basis"]["bounded"] = "full"
    with pytest.raises(ParameterError, match=r"basis\.bounded"):
        problem_from_dict(raw)


@pytest.mark.slow
def test_the_bounded_case1_controller_has_no_ridge_and_converges_from_every_start():
    # the paper's basis gave the bounded J a ridge at |ϕ̂| ≈ 1.03 (x·∇J ≤ 0 at 15 mesh
    # points of Ω, 254 on Ω×1.25) and 63/81 converging starts; full degree 4: 0, 0, 81/81
    prob = load_preset("case1-paper").with_input_bound(0.15)
    ctl = prob.train()
    X = prob.mesh.points
    assert ctl.diagnostics(X)["n_radial_decrease"] == 0
    assert ctl.diagnostics(1.25 * X)["n_radial_decrease"] == 0
    lo, hi = np.asarray(prob.mesh.lower), np.asarray(prob.mesh.upper)
    g = np.stack([v.ravel() for v in np.meshgrid(np.linspace(lo[0], hi[0], 9),
                                                 np.linspace(lo[1], hi[1], 9), indexing="ij")],
                 -1)
    r = rollout(prob.system, ctl.control, g, 6000, bound=100.0)
    final = np.linalg.norm(r.states[-1] / hi, axis=-1)
    assert not r.diverged.any() and np.all(final < 1e-2)
