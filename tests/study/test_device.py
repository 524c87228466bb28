"""The UPQC as a physical device in studies: its study fields, the simulator parameters they
give, its power metrics and the map marker where its power exceeds its rating or the line's."""

import math

import numpy as np
import pandas as pd
import pytest

from weakgrid.game.errors import ParameterError
from weakgrid.study.build import build_setup
from weakgrid.study.device import power_metrics, s_rating_mva, upqc_params
from weakgrid.study.maps import DEVICE_MARK, plot_map
from weakgrid.study.studyfile import read_study_dict, set_path, study_from_dict
from weakgrid.study.sweep_maps import device_power_flags


def paper1():
    return read_study_dict("case1-weak-grid")[0]


@pytest.mark.parametrize("field,value", [("s_rating", 0.0), ("s_rating", -5.0),
                                         ("s_rating", "big"), ("s_rating", True),
                                         ("s_rating", math.inf), ("chi", -0.02),
                                         ("h_dc", 0.0), ("t_dc", -1.0), ("r_shunt", -0.1)])
def test_bad_device_fields_are_named(field, value):
    d = paper1()
    set_path(d, f"upqc.{field}", value)
    with pytest.raises(ParameterError) as e:
        study_from_dict(d, "test")
    assert f"upqc.{field}" in str(e.value) and "must be a finite number" in str(e.value)


def test_device_parameters_from_the_study():
    d = study_from_dict(paper1(), "test").data
    d["upqc"].update(s_rating=25.0, r_shunt=0.01, h_dc=0.02, t_dc=0.05)
    p = upqc_params(d, "conventional", 100.0)
    assert p["Imax"] == pytest.approx(0.25)                # 25 MVA at 1 pu on 100 MVA
    assert p["Rsh"] == pytest.approx(0.01 / 0.25)          # pu on s_rating -> pu on Sb
    assert p["Cdc"] == pytest.approx(2 * 0.02 * 0.25)      # H·S = C·Vdc0²/2
    assert p["Cdc"] / p["kp_dc"] == pytest.approx(0.05)
    assert p["chi"] == 0.0 and p["Vmax"] == d["upqc"]["rating"]
    # reduced: the series power passes through the controlled GTI's converter, its chi (15)
    gti_chi = next(g["chi"] for g in d["dynamics"]["gti"] if g["name"] == d["machine"]["name"])
    assert gti_chi > 0 and upqc_params(d, "reduced", 100.0)["chi"] == gti_chi
    d["upqc"]["chi"] = 0.05
    assert upqc_params(d, "reduced", 100.0)["chi"] == 0.05
    del d["upqc"]["s_rating"]                                 # no rating: no limit
    assert upqc_params(d, "conventional", 100.0)["Imax"] == 0.0
    # an inserted UPQC's converter rating is its default
    assert s_rating_mva({"insert": {"sn_mva": 40.0}}) == 40.0
    assert s_rating_mva({"s_rating": 30.0, "insert": {"sn_mva": 40.0}}) == 30.0


def test_built_setup_carries_the_device():
    st = study_from_dict(paper1(), "test")
    s = build_setup(st)
    u = s.system.components["UPQC"]
    assert u.p["Imax"][0] == pytest.approx(st.data["upqc"]["s_rating"] / s.Sb_mva)
    assert s.s_rating_mva == st.data["upqc"]["s_rating"]
    assert s.line_mva >= abs(s.line_power_mw) > 0
    assert {"s_series", "s_shunt", "upqc_vdc", "shunt_limited"} <= set(s.signals)


def test_power_metrics():
    t = np.linspace(0, 1, 11)
    post = t >= 0.5
    ser = {"s_series": np.where(t < 0.5, 9.0, 0.3 * t), "s_shunt": 0.1 * t,
           "shunt_limited": (np.arange(11) == 6).astype(float)}
    m = power_metrics(ser, post, 100.0, 25.0, 40.0)
    assert m["s_series_peak_mva"] == pytest.approx(30.0)     # before `post` not counted
    assert m["s_series_peak_pct_rating"] == pytest.approx(120.0)
    assert m["s_series_peak_pct_line"] == pytest.approx(75.0)
    assert m["s_shunt_peak_pct_rating"] == pytest.approx(40.0)
    assert m["device_over_rating"] and not m["device_over_line"] and m["shunt_limit_reached"]
    m = power_metrics(ser, post, 100.0, None, 20.0)
    assert math.isnan(m["s_series_peak_pct_rating"]) and not m["device_over_rating"]
    assert m["device_over_line"]


def _sweep_table():
    rows = []
    for r, d in [(0.1, 0.05), (0.3, 0.05), (0.1, 0.1), (0.3, 0.1)]:
        for c in ("hji", "lqr"):
            rows.append({"upqc.rating": r, "duration": d, "controller": c, "scenario": "s",
                         "dt_factor": 1.0, "status": "ok", "cost": 1.0 + r,
                         "device_over_rating": c == "lqr" and r == 0.3,
                         "device_over_line": c == "lqr" and r == 0.3 and d == 0.1})
    return pd.DataFrame(rows)


def test_map_cells_flag_device_power_and_the_map_draws_it(tmp_path):
    tab = _sweep_table()
    spec = {"claim": "C", "kind": "ratio", "metric": "cost", "a": "hji", "b": "lqr",
            "x": "upqc.rating", "y": "duration"}
    from weakgrid.study.sweep_maps import map_cells

    cells = device_power_flags(map_cells(tab, spec, ["upqc.rating", "duration"]), tab, spec,
                               ["upqc.rating", "duration"])
    got = {(r["upqc.rating"], r["duration"]): r["device_over"] for _, r in cells.iterrows()}
    assert got == {(0.1, 0.05): "", (0.3, 0.05): "rating", (0.1, 0.1): "",
                   (0.3, 0.1): "rating+line"}
    fig = plot_map(cells, "upqc.rating", "duration", "value", verdict="verdict",
                   device="device_over", path=tmp_path / "m.png")
    texts = [t.get_text() for t in fig.axes[0].texts]
    assert texts.count(DEVICE_MARK["rating"]) == 1 and texts.count(DEVICE_MARK["rating+line"]) == 1
    assert "device power above its rating" in fig._suptitle.get_text().replace("\n", " ")
    # a table without the device metrics (an old sweep): no flag, no marker
    old = tab.drop(columns=["device_over_rating", "device_over_line"])
    assert set(device_power_flags(map_cells(old, spec, ["upqc.rating", "duration"]), old, spec,
                                  ["upqc.rating", "duration"])["device_over"]) == {""}
