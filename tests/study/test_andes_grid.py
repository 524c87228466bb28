"""A study on a grid read by ANDES (PSS/E-style data, machines and controls from the file)."""

import pytest

from weakgrid.study.build import build_setup
from weakgrid.study.engine import mode_check
from weakgrid.study.studyfile import study_from_dict

pytestmark = pytest.mark.andes


def kundur_study():
    return {
        "study": {"name": "kundur-g3"},
        "grid": {"kind": "andes", "file": "andes:kundur/kundur_full.xlsx"},
        "machine": {"name": "GENROU_3"},
        # G3's step-up transformer (ANDES Line_13, bus 3 -> bus 9): the shunt bus r is bus 9
        "upqc": {"branch": "Line_13", "side": "to", "rating": 0.1},
        "design": {"T": 1e-3, "settings": "case2-paper"},
        "controllers": {"compare": ["lqr", "pss-only"]},
        "scenarios": [{"id": "f", "t_end": 1.0, "events": [
            {"kind": "fault", "bus": "9", "t_on": 0.1, "duration": 0.05, "xf": 0.05}]}],
    }


def test_kundur_generator_behind_a_upqc_in_its_step_up_transformer():
    pytest.importorskip("andes")
    s = build_setup(study_from_dict(kundur_study()))
    der = s.derivation
    assert der.machine == "sg" and der.name == "GENROU_3"
    gm = s.system.components["GENROU"]
    i = gm.names.index("GENROU_3")
    net = s.system.network
    Xu = float(net.branch[s.upqc_branch, 3])
    assert s.shunt_bus == s.bus("9")
    assert der.twoport.B == pytest.approx(1 / (gm.p["xd1"][i] + Xu), rel=1e-12)
    chk = mode_check(s)
    assert chk["grid_lambda"] is not None and chk["participation"] > 0.3


def test_kundur_upqc_inserted_into_a_line():
    pytest.importorskip("andes")
    d = kundur_study()
    d["upqc"] = {"insert": {"branch": "Line_13", "side": "to", "x": 0.01}, "rating": 0.1}
    s = build_setup(study_from_dict(d))
    net = s.system.network
    assert s.shunt_bus == s.bus("9") and net.nb == 11 and net.nl == 16   # 10 buses, 15 lines + 1
    gm = s.system.components["GENROU"]
    i = gm.names.index("GENROU_3")
    # G3 now sees its transformer and the series transformer in series: a path over 2 branches
    x_tr = float(net.branch[s.branch_names["Line_13"], 3])
    assert s.derivation.twoport.B == pytest.approx(1 / (gm.p["xd1"][i] + x_tr + 0.01), rel=1e-9)


def test_unknown_line_is_refused_with_its_buses():
    """A newcomer picking the UPQC's branch needs the Lines' buses, not only their idx."""
    pytest.importorskip("andes")
    from weakgrid.game.errors import ParameterError

    d = kundur_study()
    d["upqc"] = {"insert": {"branch": "Line_99", "side": "to", "x": 0.01}, "rating": 0.1}
    with pytest.raises(ParameterError, match=r"upqc.insert.branch.*Line_99.*Line_13 \(3-9\)"):
        build_setup(study_from_dict(d))
