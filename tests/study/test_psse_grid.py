"""A study on a PSS/E case read by weakgrid's own reader (``[grid] kind = "psse"``)."""

from pathlib import Path

import pytest

from weakgrid.game.errors import ParameterError
from weakgrid.study.build import build_setup
from weakgrid.study.studyfile import study_from_dict

DATA = Path(__file__).resolve().parents[1] / "data" / "psse_reader"


def genrou_study(**grid):
    return {
        "study": {"name": "psse-omib"},
        # PSID's PSS2A one-machine case: GENCLS (H = 4 s) at bus 1, infinite bus (H = 0) at bus 2
        "grid": {"kind": "psse", "raw": "raw/PSS2A__OMIB.raw", "dyr": "OMIB_GENCLS.dyr", **grid},
        "machine": {"name": "GENCLS_1_1"},
        # the machine's line to the infinite bus: the shunt bus r is bus 2 (the line's to-bus)
        "upqc": {"branch": "1-2-1", "side": "to", "rating": 0.1},
        "design": {"T": 1e-3, "settings": "case2-paper"},
        "controllers": {"compare": ["lqr", "pss-only"]},
        "scenarios": [{"id": "f", "t_end": 1.0, "events": [
            {"kind": "fault", "bus": "2", "t_on": 0.1, "duration": 0.05, "xf": 0.05}]}],
    }


def test_psse_grid_machine_behind_a_upqc():
    s = build_setup(study_from_dict(genrou_study(), base_dir=DATA))
    assert s.derivation.name == "GENCLS_1_1" and s.derivation.machine == "sg"
    assert s.shunt_bus == s.bus("2") == s.bus("INFBUS")       # by number or by PSS/E name
    assert s.system.source == "psse"
    assert s.system.components["InfiniteBus"].names == ["GENCLS_2_1"]   # H = 0
    gm = s.system.components["GENCLS"]
    Xu = float(s.system.network.branch[s.upqc_branch, 3])
    assert s.derivation.twoport.B == pytest.approx(1 / (gm.p["xd1"][0] + Xu), rel=1e-12)


def test_psse_grid_upqc_inserted():
    d = genrou_study()
    d["upqc"] = {"insert": {"branch": "1-2-1", "side": "to", "x": 0.01}, "rating": 0.1}
    s = build_setup(study_from_dict(d, base_dir=DATA))
    assert s.system.network.nb == 3 and s.system.network.nl == 2


@pytest.mark.parametrize("grid, field, text", [
    ({"raw": None}, "grid.raw", "missing"),
    ({"raw": "case.m"}, "grid.raw", "PSS/E .raw"),
    ({"dyr": "x.txt"}, "grid.dyr", "PSS/E .dyr"),
    ({"file": "a.raw"}, "grid.file", "unknown field"),
])
def test_psse_grid_validation(grid, field, text):
    d = genrou_study()
    for k, v in grid.items():
        if v is None:
            d["grid"].pop(k)
        else:
            d["grid"][k] = v
    with pytest.raises(ParameterError) as e:
        study_from_dict(d, base_dir=DATA)
    assert field in str(e.value) and text in str(e.value)


def test_psse_grid_missing_file_and_branch():
    d = genrou_study(raw="nosuch.raw")
    with pytest.raises(ParameterError, match="grid.raw.*no such file"):
        build_setup(study_from_dict(d, base_dir=DATA))
    d = genrou_study()
    d["upqc"]["branch"] = "1-3-1"
    with pytest.raises(ParameterError, match="upqc.branch.*I-J-CKT"):
        build_setup(study_from_dict(d, base_dir=DATA))


def test_psse_grid_from_a_toml_study_file(tmp_path):
    """Paths in [grid] are relative to the study file."""
    import shutil

    from weakgrid.study.studyfile import load_study

    (tmp_path / "case").mkdir()
    shutil.copy(DATA / "raw" / "PSS2A__OMIB.raw", tmp_path / "case" / "omib.raw")
    shutil.copy(DATA / "OMIB_GENCLS.dyr", tmp_path / "case" / "omib.dyr")
    (tmp_path / "study.toml").write_text('''
[study]
name = "omib"
[grid]
kind = "psse"
raw = "case/omib.raw"
dyr = "case/omib.dyr"
[machine]
name = "GENCLS_1_1"
[upqc]
branch = "1-2-1"
side = "to"
rating = 0.1
[design]
T = 1e-3
settings = "case2-paper"
[controllers]
compare = ["lqr"]
[[scenarios]]
id = "f"
t_end = 0.5
events = [{kind = "fault", bus = "2", t_on = 0.1, duration = 0.05, xf = 0.05}]
''')
    s = build_setup(load_study(tmp_path / "study.toml"))
    assert s.derivation.name == "GENCLS_1_1"
    assert s.system.psse_files[0].endswith("omib.raw")
