"""Grid edits of a study file on every grid kind: a PV plant (a GTI with its dc link, on a new
bus behind a new branch) added to a stock case, in the power flow, answering a fault."""

from pathlib import Path

import numpy as np
import pytest

from weakgrid.game.errors import ParameterError
from weakgrid.study.build import build_setup
from weakgrid.study.runner import Run, run_scenario
from weakgrid.study.studyfile import study_from_dict

DATA = Path(__file__).resolve().parents[1] / "data"

P_MW = 30.0   # the PV plant's output in the power flow [MW]


def pv_edits(at, vn_kv, sn_mva=100.0, p_mw=P_MW):
    """A PV plant on a new bus "PV" behind a new 'PV link' (from the grid's bus ``at``)."""
    return {
        "add_bus": [{"name": "PV", "vn_kv": vn_kv}],
        "add_impedance": [{"name": "PV link", "from": at, "to": "PV", "r_pu": 0.005,
                           "x_pu": 0.05, "sn_mva": sn_mva}],
        "add_gen": [{"name": "PV", "bus": "PV", "p_mw": p_mw}],
    }


def gti(B=4.0, C=0.05):
    """The PV plant's GTI and dc link (pu on the system base)."""
    return {"name": "PV", "bus": "PV", "C": C, "Vc0": 1.0, "chi": 0.02, "B": B,
            "ks_max": 1.5, "tau": 47.3}


def pv_study(grid, at, generators=(), upqc_branch="PV link", gti_kw=None, fault_bus=None):
    return {
        "study": {"name": "pv-edit"},
        "grid": grid,
        "dynamics": {"generator": list(generators), "gti": [gti(**(gti_kw or {}))]},
        "machine": {"name": "PV"},
        "upqc": {"name": "UPQC", "branch": upqc_branch, "structure": "reduced",
                 "rating": 0.15},
        "design": {"T": 1e-3, "settings": "case1-paper"},
        "controllers": {"compare": ["pss-only"]},
        "report": {"speed_of": ""},
        "scenarios": [{"id": "f", "t_end": 0.4, "events": [
            {"kind": "fault", "bus": fault_bus if fault_bus is not None else at, "t_on": 0.1,
             "duration": 0.05, "xf": 0.05}]}],
    }


def run_fault(d, base_dir=None, p_mw=P_MW):
    """Build (the new generator in the power flow at p_mw), run the fault; the GTI's ac power
    [pu] over time and the setup."""
    study = study_from_dict(d, base_dir=base_dir)
    s = build_setup(study)
    net = s.system.network
    pv = s.bus("PV")
    assert pv in net.bus_ids and s.shunt_bus == s.bus(d["grid"]["add_impedance"][0]["from"])
    rows = np.nonzero(net.gen[:, 0].astype(int) == pv)[0]
    assert len(rows) == 1 and net.gen[rows[0], 1] == pytest.approx(p_mw)
    sc = study.scenarios()[0]
    rec = run_scenario(study, Run.of(study, sc, "pss-only"))
    t = np.asarray(rec.results.t)
    p = np.asarray(rec.results["PV.P_ac"])
    return s, t, p


def assert_responds(t, p, p_pu):
    """In the power flow at p_pu before the fault, steady until it, moved during it."""
    pre = t < 0.1
    assert p[0] == pytest.approx(p_pu, rel=2e-2, abs=1e-3)
    assert np.ptp(p[pre]) < 1e-3 * max(abs(p_pu), 1e-3) + 1e-6         # no drift before
    during = (t > 0.1) & (t < 0.15)
    assert np.max(np.abs(p[during] - p[0])) > 0.1 * abs(p_pu)          # the fault moves it


def test_matpower_case9_gains_a_pv_plant():
    grid = {"kind": "matpower", "file": "matpower/case9.m", **pv_edits(5, 345.0)}
    gens = [{"name": f"G{b}", "bus": b, "machine": {
        "model": "GENCLS", "Sn": 100.0, "fn": 60.0, "M": 10.0 if b > 1 else 1e4, "D": 0.0,
        "ra": 0.0, "xd1": 0.06}} for b in (1, 2, 3)]
    s, t, p = run_fault(pv_study(grid, 5, gens), base_dir=DATA)
    assert s.system.network.nb == 10 and s.system.network.nl == 10
    assert_responds(t, p, P_MW / 100.0)


def test_psse_omib_gains_a_pv_plant():
    grid = {"kind": "psse", "raw": "raw/PSS2A__OMIB.raw", "dyr": "OMIB_GENCLS.dyr",
            **pv_edits("GENBUS", 24.0)}
    s, t, p = run_fault(pv_study(grid, "GENBUS"), base_dir=DATA / "psse_reader")
    assert s.bus("PV") == 3                            # one above the case's largest number
    assert_responds(t, p, P_MW / 100.0)


@pytest.mark.andes
def test_andes_ieee14_gains_a_pv_plant():
    pytest.importorskip("andes")
    grid = {"kind": "andes", "file": "andes:ieee14/ieee14.raw",
            "dyr": "andes:ieee14/ieee14.dyr", **pv_edits(14, 13.8)}
    s, t, p = run_fault(pv_study(grid, 14))
    assert s.system.network.nb == 15
    assert_responds(t, p, P_MW / 100.0)


@pytest.mark.andes
def test_andes_static_generator_becomes_a_gti():
    """ieee14 without dynamic data: its PV generators are static (PVSource); the one at bus 2
    (40 MW), halved and moved behind a new branch, becomes the study's GTI."""
    pytest.importorskip("andes")
    edits = pv_edits(2, 69.0)
    edits.pop("add_gen")
    grid = {"kind": "andes", "file": "andes:ieee14/ieee14.raw", **edits,
            "sgen_to_gen": [{"name": "PV_2", "bus": "PV", "scale": 0.5}]}
    s, t, p = run_fault(pv_study(grid, 2), p_mw=20.0)
    assert "PV_2" not in s.system.components["PVSource"].names
    net = s.system.network
    assert net.bus[net.index_of(2), 1] == 1                  # bus 2 kept no generator: PQ
    assert_responds(t, p, 0.2)
    d = pv_study(dict(grid, sgen_to_gen=[{"name": "PV_9"}]), 2)
    with pytest.raises(ParameterError, match=r"sgen_to_gen.0.name.*PV_9.*PV_2"):
        build_setup(study_from_dict(d))


def test_pandapower_network_from_a_json_file(tmp_path):
    """The user's own pandapower network (pandapower.to_json), edited like a stock one."""
    import pandapower as pp
    import pandapower.networks as pn

    pp.to_json(pn.create_cigre_network_mv(with_der="pv_wind"), str(tmp_path / "my net.json"))
    grid = {"kind": "pandapower", "network": "from_json", "file": "my net.json",
            **pv_edits("Bus 7", 20.0, sn_mva=2.0, p_mw=1.5)}
    gens = [{"name": "Grid", "bus": "Bus 0", "machine": {
        "model": "GENCLS", "Sn": 1000.0, "fn": 50.0, "M": 1.0e4, "D": 0.0, "ra": 0.0,
        "xd1": 0.01}}]
    d = pv_study(grid, "Bus 7", gens, upqc_branch={"from": "Bus 7", "to": "PV"},
                 gti_kw={"B": 13.3, "C": 0.5}, fault_bus="Bus 8")
    s, t, p = run_fault(d, base_dir=tmp_path, p_mw=1.5)
    assert_responds(t, p, 1.5 / s.Sb_mva)


@pytest.mark.parametrize("content, text", [
    (None, "no such file"), ('{"a": 1}', "not a pandapower network"),
    ("not json", "not a pandapower network")])
def test_from_json_bad_file(tmp_path, content, text):
    if content is not None:
        (tmp_path / "net.json").write_text(content)
    d = pv_study({"kind": "pandapower", "network": "from_json", "file": "net.json"}, "Bus 7")
    with pytest.raises(ParameterError, match=f"grid.file.*{text}"):
        build_setup(study_from_dict(d, base_dir=tmp_path))


def test_unknown_bus_lists_the_valid_ones():
    grid = {"kind": "psse", "raw": "raw/PSS2A__OMIB.raw", "dyr": "OMIB_GENCLS.dyr",
            **pv_edits("NOSUCH", 24.0)}
    with pytest.raises(ParameterError) as e:
        build_setup(study_from_dict(pv_study(grid, "GENBUS"), base_dir=DATA / "psse_reader"))
    msg = str(e.value)
    assert "grid.add_impedance.0.from" in msg and "NOSUCH" in msg and "GENBUS" in msg
    assert "[1, 2" in msg


@pytest.mark.parametrize("edit, field, text", [
    ({"add_gen": [{"bus": 1}]}, "grid.add_gen.0.name", "missing"),
    ({"add_gen": [{"name": "G", "bus": 1, "pmw": 3}]}, "grid.add_gen.0.pmw", "unknown field"),
    ({"add_bus": [{"name": "B", "vn_kv": -1}]}, "grid.add_bus.0.vn_kv", "> 0"),
    ({"add_impedance": [{"from": 1, "to": 2, "r_pu": 0, "x_pu": 0, "sn_mva": 1}]},
     "grid.add_impedance.0.x_pu", "non-zero"),
    ({"add_gen": [{"name": "G", "bus": 1, "p_mw": {"peak": 3}}]}, "grid.add_gen.0.p_mw.peak",
     "no load level"),
    ({"sgen_to_gen": [{"name": "WT"}]}, "grid.sgen_to_gen", "no static generators"),
    ({"add_gen": {"name": "G"}}, "grid.add_gen", "list of tables"),
])
def test_edit_validation(edit, field, text):
    d = pv_study({"kind": "matpower", "file": "matpower/case9.m",
                  "loads": {"levels": {"base": 1.0}}, **edit}, 5)
    with pytest.raises(ParameterError) as e:
        study_from_dict(d, base_dir=DATA)
    assert field in str(e.value) and text in str(e.value)


def test_inline_grid_refuses_edits():
    from weakgrid.study.studyfile import load_study

    d = load_study("case1-weak-grid").data
    d["grid"]["add_gen"] = [{"name": "G", "bus": 1}]
    with pytest.raises(ParameterError, match="grid.add_gen.*inline"):
        study_from_dict(d)


def test_added_bus_number_taken():
    grid = {"kind": "matpower", "file": "matpower/case9.m", **pv_edits(5, 345.0)}
    grid["add_bus"][0]["number"] = 5
    with pytest.raises(ParameterError, match=r"grid.add_bus.0.number.*exists.*largest: 9"):
        build_setup(study_from_dict(pv_study(grid, 5), base_dir=DATA))


@pytest.mark.parametrize("grid, text", [
    ({"network": "from_json"}, "grid.file.*missing"),
    ({"network": "from_json", "file": "net.p"}, "grid.file.*pandapower.to_json"),
    ({"network": "case9", "file": "net.json"}, "grid.file.*from_json"),
])
def test_from_json_fields(grid, text):
    d = pv_study({"kind": "pandapower", **grid}, "Bus 7")
    with pytest.raises(ParameterError, match=text):
        study_from_dict(d)


def test_psse_generator_without_dynamic_data_becomes_a_gti():
    """The OMIB .raw without its .dyr: the 90 MW generator at bus 1 is static
    (PVSource_1_1); scaled to 27 MW and moved behind a new branch, it becomes a GTI."""
    edits = pv_edits("GENBUS", 24.0)
    edits.pop("add_gen")
    grid = {"kind": "psse", "raw": "raw/PSS2A__OMIB.raw", **edits,
            "sgen_to_gen": [{"name": "PVSource_1_1", "bus": "PV", "scale": 0.3}]}
    s, t, p = run_fault(pv_study(grid, "GENBUS"), base_dir=DATA / "psse_reader", p_mw=27.0)
    assert "PVSource" not in s.system.components
    assert_responds(t, p, 0.27)


# ---------------------------------------------------------------- add_impedance: b and tap
STUB = {"r_pu": 0.0, "x_pu": 0.2, "b": 0.3, "tap": 1.05, "sn_mva": 50.0}


def stub_voltage(grid, at, generators=(), base_dir=None, upqc_branch="PV link", **stub):
    """The power-flow voltage [pu] of a dead-end bus "stub" fed from ``at`` through an added
    branch (``STUB`` changed by ``stub``), and of ``at``: the oracle of a lossless pi model with
    its ratio at the from end is |V_stub| = |V_at| / (tap·(1 − x·b/2)) (the to-end shunt's
    charging current through x; x·b is the same on any base)."""
    z = dict(STUB, **stub)
    grid = dict(grid, add_bus=grid["add_bus"] + [{"name": "stub", "vn_kv": grid["add_bus"][0]
                                                   ["vn_kv"]}],
                add_impedance=grid["add_impedance"] + [dict(z, name="stub link", **{
                    "from": at, "to": "stub"})])
    s = build_setup(study_from_dict(pv_study(grid, at, generators, upqc_branch),
                                    base_dir=base_dir))
    net = s.system.network
    v = np.abs(net.pf.V)
    return v[net.index_of(s.bus("stub"))], v[net.index_of(s.bus(at))], z


def expected(v_at, z):
    return v_at / (z.get("tap", 1.0) * (1.0 - z["x_pu"] * z.get("b", 0.0) / 2.0))


@pytest.mark.parametrize("stub", [{}, {"tap": 1.0}, {"b": 0.0}])
def test_matpower_branch_with_shunt_and_tap(stub):
    grid = {"kind": "matpower", "file": "matpower/case9.m", **pv_edits(5, 345.0)}
    gens = [{"name": f"G{b}", "bus": b, "machine": {
        "model": "GENCLS", "Sn": 100.0, "fn": 60.0, "M": 10.0 if b > 1 else 1e4, "D": 0.0,
        "ra": 0.0, "xd1": 0.06}} for b in (1, 2, 3)]
    v, v_at, z = stub_voltage(grid, 5, gens, base_dir=DATA, **stub)
    assert v == pytest.approx(expected(v_at, z), rel=1e-6)
    assert abs(v - v_at) > 0.01          # the oracle is not trivially met


def test_psse_branch_with_shunt_and_tap():
    grid = {"kind": "psse", "raw": "raw/PSS2A__OMIB.raw", "dyr": "OMIB_GENCLS.dyr",
            **pv_edits("GENBUS", 24.0)}
    v, v_at, z = stub_voltage(grid, "GENBUS", base_dir=DATA / "psse_reader")
    assert v == pytest.approx(expected(v_at, z), rel=1e-6)


@pytest.mark.andes
def test_andes_branch_with_shunt_and_tap():
    pytest.importorskip("andes")
    grid = {"kind": "andes", "file": "andes:ieee14/ieee14.raw",
            "dyr": "andes:ieee14/ieee14.dyr", **pv_edits(14, 13.8)}
    v, v_at, z = stub_voltage(grid, 14)
    assert v == pytest.approx(expected(v_at, z), rel=1e-6)


@pytest.mark.parametrize("stub", [{}, {"tap": 1.0}])
def test_pandapower_branch_with_shunt_and_tap(stub):
    """pandapower: an impedance element, or a transformer for tap ≠ 1, and two shunts."""
    grid = {"kind": "pandapower", "network": "case9", **pv_edits("5", 345.0)}
    gens = [{"name": f"G{b}", "bus": str(b), "machine": {
        "model": "GENCLS", "Sn": 100.0, "fn": 60.0, "M": 10.0 if b > 1 else 1e4, "D": 0.0,
        "ra": 0.0, "xd1": 0.06}} for b in (1, 2, 3)]
    v, v_at, z = stub_voltage(grid, "5", gens, upqc_branch={"from": "5", "to": "PV"}, **stub)
    assert v == pytest.approx(expected(v_at, z), rel=1e-6)


@pytest.mark.parametrize("bad, text", [({"tap": 0.0}, "must be > 0"), ({"tap": 2.0}, "0.5 .. 1.5"),
                                       ({"b": "x"}, "finite number")])
def test_add_impedance_b_tap_validation(bad, text):
    grid = {"kind": "matpower", "file": "matpower/case9.m", **pv_edits(5, 345.0)}
    grid["add_impedance"][0].update(bad)
    with pytest.raises(ParameterError, match=rf"grid.add_impedance.0.{list(bad)[0]}.*{text}"):
        study_from_dict(pv_study(grid, 5), base_dir=DATA)
