"""The design model's Thevenin option: the grid seen from the UPQC shunt bus (weakgrid.design)."""

import math

import numpy as np
import pytest

from weakgrid.design import derive_design, design_mode, machine_mode, mode_states, modes
from weakgrid.design.thevenin import grid_thevenin, two_machine_factor
from weakgrid.game.errors import ParameterError
from weakgrid.sim.gti import GTI
from weakgrid.sim.system import System
from weakgrid.sim.upqc import UPQC
from weakgrid.study.studyfile import load_study


def _chain(load_r=(30.0, 10.0), load_g=(0.0, 0.0), r_line=0.01, x_line=0.2, p=30.0):
    """SG bus 1 -- x 0.1 -- bus 2 --[UPQC 3->2, x 0.05]-- bus 3 (r) -- line -- slack bus 4."""
    bus = np.array([
        [1, 2, 0, 0, 0, 0, 1, 1.0, 0, 20, 1, 1.5, 0.5],
        [2, 1, 0, 0, 0, 0, 1, 1.0, 0, 20, 1, 1.5, 0.5],
        [3, 1, *load_r, 0, 0, 1, 1.0, 0, 20, 1, 1.5, 0.5],
        [4, 3, *load_g, 0, 0, 1, 1.0, 0, 20, 1, 1.5, 0.5],
    ], float)
    gen = np.array([[1, p, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11,
                    [4, 0, 0, 999, -999, 1.0, 200, 1, 999, -999] + [0] * 11], float)
    branch = np.array([
        [3, 2, 0.0, 0.05, 0.0, 0, 0, 0, 0, 0, 1, -360, 360],
        [1, 2, 0.0, 0.1, 0.0, 0, 0, 0, 0, 0, 1, -360, 360],
        [3, 4, r_line, x_line, 0.0, 0, 0, 0, 0, 0, 1, -360, 360],
    ], float)
    return {"baseMVA": 100.0, "bus": bus, "gen": gen, "branch": branch}


def _system(case, M_grid=1e4, xd_grid=0.01, M_sg=8.0, gti=False):
    s = System(case)
    s.add_machine("GENCLS", "Grid", 1, Sn=100, M=M_grid, D=0.0, ra=0.0, xd1=xd_grid)
    if gti:
        s.add_component(GTI()).add_gti("PV", gen=0, ref_bus=3, C=0.05, Vc0=1.0, chi=0.0, B=5.0,
                                       ks_max=2.0, tau=2.0)
    else:
        s.add_machine("GENCLS", "SG", 0, Sn=100, M=M_sg, D=0.0, ra=0.0, xd1=0.3)
    s.add_component(UPQC()).add_upqc("U", branch=0, Vmax=0.2)
    s.setup()
    return s


def test_thevenin_impedance_and_voltage_of_a_three_bus_grid_by_hand():
    s = _system(_chain())
    V = s.network.pf.V
    y_load = (0.30 - 0.10j) / abs(V[2]) ** 2                  # conj(S)/|V|², bus 3 (r)
    z_line = 0.01 + 0.2j
    # the grid machine as E' behind x'd (it has no exciter): in series with the line
    th = grid_thevenin(s, 0, 0, "transient")
    assert th.Z == pytest.approx(1 / (1 / (z_line + 0.01j) + y_load), rel=1e-12)
    assert grid_thevenin(s, 0, 0, "auto").Z == pytest.approx(th.Z, rel=1e-15)
    # held at its terminal (bus 4): the line and the load only; E_th is the open-circuit
    # voltage of r, the divider V4·y_line/(y_line + y_load), whatever the power flow's current
    th = grid_thevenin(s, 0, 0, "terminal")
    y_line = 1 / z_line
    assert th.Z == pytest.approx(1 / (y_line + y_load), rel=1e-12)
    assert th.E == pytest.approx(V[3] * y_line / (y_line + y_load), rel=1e-10)
    assert th.M_behind == 1e4
    assert two_machine_factor(8.0, math.inf) == 1.0
    assert two_machine_factor(8.0, 12.0) == pytest.approx(1 + 8 / 12)


def test_thevenin_form_is_the_two_machine_mode_of_the_full_grid():
    """Two classical machines, lossless, no load: the Thevenin form's mode is the linearized
    grid's exactly (ω² = ωs·E1·E2·B·cos δ12·(1/M1 + 1/M2)); the paper's stiff Vr misses it."""
    s = _system(_chain(load_r=(0.0, 0.0), r_line=0.0), M_grid=40.0, xd_grid=0.1)
    d = derive_design(s, "SG", "U", T=1e-3, grid_model="thevenin")
    assert d.grid_model == "thevenin" and d.model is d.forms["thevenin"]
    m = modes(s)
    k, _ = machine_mode(m, mode_states(d))
    f_grid = m.frequency_hz[k]
    f_th = abs(design_mode(d.forms["thevenin"]).imag) / (2 * math.pi)
    f_paper = abs(design_mode(d.forms["paper"]).imag) / (2 * math.pi)
    assert f_th == pytest.approx(f_grid, rel=1e-6)
    assert abs(f_paper - f_grid) / f_grid > 0.1
    assert d.details["inertia_factor"] == pytest.approx(1 + 8 / 40, rel=1e-12)
    assert d.forms["thevenin"].source["B"] == pytest.approx(1 / (0.3 + 0.1 + 0.05 + 0.2 + 0.1))


def test_paper_form_stays_the_default_and_a_gti_keeps_it():
    s = _system(_chain(), M_grid=12.0)
    d = derive_design(s, "SG", "U", T=1e-3)
    assert d.grid_model == "paper" and d.model is d.forms["paper"]
    assert d.forms["thevenin"] is not None and d.forms["thevenin"] is not d.model
    # a GTI's angle is referred to r by its own control: the Thevenin form is the paper's
    g = _system(_chain(), M_grid=12.0, gti=True)
    dg = derive_design(g, "PV", "U", T=1e-3, grid_model="thevenin")
    assert dg.forms["thevenin"] is dg.forms["paper"] is dg.model


def test_bad_grid_model_is_refused_naming_the_field():
    s = _system(_chain())
    with pytest.raises(ParameterError, match="grid_model"):
        derive_design(s, "SG", "U", T=1e-3, grid_model="stiff")
    with pytest.raises(ParameterError, match="design.grid_model"):
        load_study("ieee9-sg-upqc", overrides=[("design.grid_model", "stiff")])


def test_design_and_modes_print_both_forms_and_the_option_switches(capsys):
    from weakgrid.cli.main import main

    # the study designs with the Thevenin form; --set switches back to the paper's
    assert main(["design", "ieee9-sg-upqc", "--no-train"]) == 0
    out = capsys.readouterr().out
    assert "grid_model = 'thevenin' (used): 2.045 Hz, -1.0%" in out
    assert "grid_model = 'paper': 2.455 Hz, +18.9%" in out
    assert "MISMATCH" not in out
    assert main(["design", "ieee9-sg-upqc", "--no-train", "--set",
                 "design.grid_model=paper"]) == 0
    out = capsys.readouterr().out
    assert "grid_model = 'paper' (used)" in out and "MISMATCH" in out
    assert main(["modes", "ieee9-sg-upqc"]) == 0
    out = capsys.readouterr().out
    assert "grid_model = 'thevenin' (used): 2.045 Hz, -1.0% vs the grid's 2.065 Hz" in out
