"""Derivation of the design model (10) from a set-up grid (weakgrid.design)."""

import math

import numpy as np
import pytest

from weakgrid.design import derive_design, machine_side_buses, source_twoport
from weakgrid.game.errors import ParameterError
from weakgrid.sim.gti import GTI
from weakgrid.sim.system import System
from weakgrid.sim.upqc import UPQC
from weakgrid.study.build import build_setup
from weakgrid.study.studyfile import load_study


# the values the former case modules (study/cases/case1.py, case2.py) derived, to 7 digits
TODAY = {
    ("case1-weak-grid", "high"): (8.100248e-4, 896.8940, 0.8336197, 0.3138279),
    ("case1-weak-grid", "low"): (8.100248e-4, 973.2275, 0.9127296, 0.2629915),
    ("case2-lv-microgrid", "high"): (1.0e-3, 501.5925, 1.0, 0.2211478),
    ("case2-lv-microgrid", "low"): (1.0e-3, 499.6848, 1.0, 0.1089611),
}


@pytest.mark.parametrize("key", sorted(TODAY))
def test_paper_grids_give_todays_values(key):
    s = build_setup(load_study(key[0]), key[1])
    d = s.design
    for got, want in zip((d.T, d.a, d.Vr_bar, d.phi_s0), TODAY[key]):
        assert got == pytest.approx(want, rel=2e-7)
    if key == ("case1-weak-grid", "high"):     # the rounding
        assert (f"{d.T:.3e}", f"{d.a:.2f}", f"{d.Vr_bar:.4f}", f"{d.phi_s0:.4f}") == \
            ("8.100e-04", "896.89", "0.8336", "0.3138")
    # every value carries its source
    names = [v["name"] for v in s.derivation.values]
    assert {"a", "B", "Vr_bar", "phi_s0", "T"} <= set(names)
    assert all(v["source"] for v in s.derivation.values)


def _chain_case(x_line=0.1, x_up=0.05, p=50.0, loads=True):
    """GTI/SG bus 1 -- line -- bus 2 --[UPQC 3->2]-- bus 3 (r, load) -- line -- slack bus 4."""
    bus = np.array([
        [1, 2, 0, 0, 0, 0, 1, 1.0, 0, 20, 1, 1.5, 0.5],
        [2, 1, 0, 0, 0, 0, 1, 1.0, 0, 20, 1, 1.5, 0.5],
        [3, 1, 30 if loads else 0, 10 if loads else 0, 0, 0, 1, 1.0, 0, 20, 1, 1.5, 0.5],
        [4, 3, 40, 10, 0, 0, 1, 1.0, 0, 20, 1, 1.5, 0.5],
    ], float)
    gen = np.array([[1, p, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11,
                    [4, 0, 0, 999, -999, 1.0, 200, 1, 999, -999] + [0] * 11], float)
    branch = np.array([
        [3, 2, 0.0, x_up, 0.0, 0, 0, 0, 0, 0, 1, -360, 360],
        [1, 2, 0.0, x_line, 0.0, 0, 0, 0, 0, 0, 1, -360, 360],
        [3, 4, 0.01, 0.2, 0.0, 0, 0, 0, 0, 0, 1, -360, 360],
    ], float)
    return {"baseMVA": 100.0, "bus": bus, "gen": gen, "branch": branch}


def _slack(s):
    s.add_machine("GENCLS", "Grid", 1, Sn=100, M=1e4, D=0.0, ra=0.0, xd1=0.01)


def test_gti_two_port_of_a_lossless_chain_is_the_series_sum():
    s = System(_chain_case())
    _slack(s)
    g = s.add_component(GTI())
    g.add_gti("PV", gen=0, ref_bus=3, C=0.05, Vc0=1.0, chi=0.0, B=5.0, ks_max=2.0, tau=2.0)
    s.add_component(UPQC()).add_upqc("U", branch=0, Vmax=0.2)
    s.setup()
    d = derive_design(s, "PV", "U", T=1e-3)
    B = 1.0 / (1 / 5.0 + 0.1 + 0.05)
    assert d.twoport.B == pytest.approx(B, rel=1e-12)
    assert d.twoport.loss_angle == pytest.approx(0.0, abs=1e-12)
    assert d.model.a == pytest.approx(2.0 * g.Vs0[0] * B / 0.05, rel=1e-12)
    # the lossless design model's equilibrium is the power flow's: Pm = Vs·V̄r·B·sin ϕs0
    assert d.details["P_design"] == pytest.approx(0.5, rel=1e-9)
    assert d.model.Vr_bar == pytest.approx(abs(s.network.pf.V[2]), rel=1e-12)


def test_sg_behind_a_line_and_the_upqc():
    s = System(_chain_case(p=30.0))
    _slack(s)
    s.add_machine("GENCLS", "SG", 0, Sn=100, M=8.0, D=0.0, ra=0.0, xd1=0.3)
    s.add_component(UPQC()).add_upqc("U", branch=0, Vmax=0.2)
    s.setup()
    d = derive_design(s, "SG", "U", T=1e-3)
    B = 1.0 / (0.3 + 0.1 + 0.05)
    assert d.twoport.B == pytest.approx(B, rel=1e-12)
    E = d.details["E_prime"]
    ws = 2 * math.pi * s.network.f_hz
    assert d.model.a == pytest.approx(ws * E * B / 8.0, rel=1e-12)       # ωs·E'·B/(2H)
    # equilibrium: Pm = E'·V̄r·B·sin ϕs0 = 0.3 pu (lossless path)
    assert E * d.model.Vr_bar * B * math.sin(d.model.phi_s0) == pytest.approx(0.3, rel=1e-9)


def test_a_path_with_a_load_or_around_the_upqc_is_refused():
    case = _chain_case()
    case["bus"][1, 2] = 5.0                     # a load on the machine side
    s = System(case)
    _slack(s)
    s.add_machine("GENCLS", "SG", 0, Sn=100, M=8.0, D=0.0, ra=0.0, xd1=0.3)
    s.setup()
    with pytest.raises(ParameterError, match="no\\s+load"):
        source_twoport(s, 0, 1 / 0.3j, 0)
    ring = _chain_case()
    ring["branch"] = np.vstack([ring["branch"], [1, 4, 0, 0.5, 0, 0, 0, 0, 0, 0, 1, -360, 360]])
    s2 = System(ring)
    _slack(s2)
    s2.add_machine("GENCLS", "SG", 0, Sn=100, M=8.0, D=0.0, ra=0.0, xd1=0.3)
    s2.setup()
    with pytest.raises(ParameterError, match="upqc.branch"):
        machine_side_buses(s2.network, 0, 0)
