"""A UPQC rating checked against the line and the converter once the grid is built
(study/build.py ``build_setup``): its largest series power ``|Vu|max · |I_line|``.

Beyond the converter's rating (``upqc.insert.sn_mva``) it is refused; beyond the line's own
apparent power (a series voltage above the shunt bus's) it is a loud warning, since the
shipped sweeps reach rating 1.0 pu on purpose (case 1: above its 0.83-pu shunt bus).
"""

import logging
import re

import pytest

from weakgrid.game.errors import ParameterError
from weakgrid.study.build import build_setup
from weakgrid.study.studyfile import load_study


def _line(setup):
    """``(|V_r|, |I_line| Sb)`` of the UPQC's branch, recomputed from the power flow."""
    from weakgrid.sim.network import BR_R, BR_X, F_BUS, T_BUS

    net = setup.system.network
    k = setup.upqc_branch
    r, b = net.index_of(int(net.branch[k, F_BUS])), net.index_of(int(net.branch[k, T_BUS]))
    i = abs((net.pf.V[r] - net.pf.V[b]) / complex(net.branch[k, BR_R], net.branch[k, BR_X]))
    return abs(net.pf.V[r]), i * float(net.Sb)


def test_a_series_power_beyond_the_converters_rating_is_refused():
    st = load_study("ieee9-sg-upqc")
    _, per_pu = _line(build_setup(st))                  # MVA per pu of |Vu|: 85 MVA
    sn = 0.5 * st.data["upqc"]["rating"] * per_pu        # half the series power it needs
    bad = st.with_values(**{"upqc.insert.sn_mva": sn})
    with pytest.raises(ParameterError) as exc:
        build_setup(bad)
    e = exc.value
    assert e.field == "upqc.rating" and e.value == 0.15
    msg = str(e)
    assert "upqc.insert.sn_mva" in msg and f"{sn:g} MVA" in msg and "MVA at load 'base'" in msg
    # (sn_mva is also the inserted branch's base: the line's current moves a little)
    pct = float(re.search(r"\((\d+) % of the converter", msg).group(1))
    assert 180 < pct < 220
    fix = float(re.search(r"a rating at most ([0-9.e-]+) pu", msg).group(1))
    assert fix == pytest.approx(0.15 * 100 / pct, rel=0.02)
    build_setup(bad.with_values(**{"upqc.rating": 0.99 * fix}))     # the fix it names works

def test_a_series_voltage_above_the_shunt_bus_is_said_loudly(caplog):
    st = load_study("case1-weak-grid")
    v_r, _ = _line(build_setup(st, "high"))
    assert v_r < 0.9                                   # case 1's weak grid sags
    with caplog.at_level(logging.WARNING, logger="weakgrid"):
        build_setup(st.with_values(**{"upqc.rating": 0.95}), "high")
    said = [r.getMessage() for r in caplog.records if "upqc.rating" in r.getMessage()]
    assert len(said) == 1, said
    assert "0.95" in said[0] and "line's power" in said[0] and \
        f"at most {v_r:.3g} pu" in said[0]
    caplog.clear()
    with caplog.at_level(logging.WARNING, logger="weakgrid"):
        build_setup(st.with_values(**{"upqc.rating": 0.8}), "high")   # below |V_r|: quiet
    assert not [r for r in caplog.records if "upqc.rating" in r.getMessage()]


@pytest.mark.parametrize("name", ["case1-weak-grid", "case2-lv-microgrid",
                                  "cigre-mv-wind-gti", "ieee9-sg-upqc"])
def test_the_shipped_ratings_are_within_the_line_and_the_converter(name, caplog):
    st = load_study(name)
    with caplog.at_level(logging.WARNING, logger="weakgrid"):
        for load in st.loads:
            build_setup(st, load)
    assert not [r for r in caplog.records if "upqc.rating" in r.getMessage()]
