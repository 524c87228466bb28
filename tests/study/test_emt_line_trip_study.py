"""A study with a `line_trip` event on a DPsim engine (issue 25: refused before line trips were
mapped, weakgrid.sim.emt.events).

The grid of case 1 with its generator classical (GENCLS, no controls: the models DPsim has, as
tests/study/test_emt_study.py) and a second, weaker tie in parallel with the line from the UPQC
bus (3) to the grid bus (4), tripped at 0.2 s: the study plans and runs in DPsim (DP and EMT)
and its SG's speed excursion is the phasor engine's within a few per cent.
"""

import numpy as np
import pytest

from paper_setups import classical_case1

from weakgrid.study.studyfile import study_from_dict

pytest.importorskip("dpsimpy")

pytestmark = pytest.mark.emt

T_TRIP, T_END = 0.2, 0.6


def _study(engine):
    d, source = classical_case1()
    line = next(b for b in d["grid"]["branch"] if b["name"] == "line")
    d["grid"]["branch"].append({**line, "name": "line b", "r": 2 * line["r"], "x": 2 * line["x"]})
    sc = next(s for s in d["scenarios"] if s["id"] == "c1-high-conv")
    sc.update(events=[{"kind": "line_trip", "branch": "line b", "t": T_TRIP}],
              controllers=["none"], t_end=T_END)
    sc.pop("quick", None)
    d.update(scenarios=[sc], figures=[], claims=[])
    d["controllers"]["compare"] = sc["controllers"]
    d.pop("sweep", None)
    d.setdefault("simulation", {})["engine"] = engine
    return study_from_dict(d, source=source)


def _run(engine):
    from weakgrid.study.runner import Run, run_scenario

    st = _study(engine)
    return run_scenario(st, Run.of(st, st.scenarios(False)[0], "none"))


def test_line_trip_study_runs_in_dpsim_like_the_phasor_engine():
    recs = {e: _run(e) for e in ("phasor", "dpsim-dp", "dpsim-emt")}
    ph = recs["phasor"]
    dev = {e: r.metrics["speed_peak_dev_pu"] for e, r in recs.items()}
    assert dev["phasor"] > 1e-4, dev                                   # the trip acted
    for e in ("dpsim-dp", "dpsim-emt"):
        r = recs[e]
        assert not r.metrics["failed"], e
        assert r.info["sim"]["engine"] == e
        assert dev[e] == pytest.approx(dev["phasor"], rel=0.03), dev
        pre = r.series["t"] < T_TRIP - 1e-9                            # the same operating point
        assert np.max(np.abs(r.series["shunt_bus_v"][pre] - ph.series["shunt_bus_v"][0])) < 1e-4
        # after the trip the UPQC bus sags as in the phasor engine (the weaker grid)
        late = r.series["t"] > T_END - 0.1
        late_ph = ph.series["t"] > T_END - 0.1
        assert np.mean(r.series["shunt_bus_v"][late]) == pytest.approx(
            np.mean(ph.series["shunt_bus_v"][late_ph]), abs=3e-3)
