"""The shipped example studies on grids weakgrid does not ship (ANDES's ieee39 with a UPQC in a
generator's step-up; pandapower's case14 with a PV plant as a GTI behind a reduced UPQC; the
CIGRE MV grid with two GTIs, one controlled): every run starts at equilibrium (nothing moves
before the first event), and `weakgrid run --quick` runs each end to end."""

import numpy as np
import pandas as pd
import pytest
from shipped import skip_without_andes
from test_baselines import pre_event_drift, worst

from weakgrid.cli.main import main
from weakgrid.study.controllers import controller_kind
from weakgrid.study.studyfile import load_study

EXAMPLES = {"ieee39-g3-upqc": [pytest.mark.andes, pytest.mark.slow],
            "case14-pv-gti": [], "cigre-mv-two-gti": []}

# largest change of any recorded variable before the first event [pu, rad]: the runs' Newton
# tolerance is ~1e-10 at these steps; measured worst 1.7e-11 (ieee39, GENROU_9.Id), 1.3e-15
# (case14), 1.8e-13 (CIGRE two GTIs)
FLAT = 1e-9
TRAINED = ("hji", "hji-bounded", "file")   # trained controllers: the slow test of test_baselines


def _example(name):
    skip_without_andes(name)
    return load_study(name)


def drift_cases():
    """Every (study, scenario, untrained controller) of the examples (a study file is read
    without its grid: no ANDES needed to list the runs)."""
    out = []
    for name, marks in EXAMPLES.items():
        st = load_study(name)
        out += [pytest.param(name, sc["id"], c, id=f"{name}-{sc['id']}-{c}",
                             marks=[m for m in marks if m.name != "slow"])
                for sc, c in st.runs() if controller_kind(st, c) not in TRAINED]
    return out


@pytest.mark.parametrize("name, scenario, controller", drift_cases())
def test_no_drift_before_the_first_event(name, scenario, controller, monkeypatch):
    st = _example(name)
    sc = next(s for s in st.scenarios() if s["id"] == scenario)
    t0 = min(e.get("t_on", e.get("t")) for e in sc["events"])
    t1 = max(e.get("t_off", e.get("t")) for e in sc["events"])
    sc = dict(sc, t_end=t1 + 0.02)                  # the run up to just after the events
    rec, drift = pre_event_drift(st, sc, controller, monkeypatch)
    assert not rec.metrics["failed"]
    k, d = worst(drift)
    assert np.isfinite(d) and d < FLAT, (k, d)


@pytest.mark.parametrize("name", [pytest.param(n, marks=m) for n, m in EXAMPLES.items()])
def test_quick_run_end_to_end(name, tmp_path):
    st = _example(name)
    out = tmp_path / "run"
    assert main(["run", name, "--quick", "-o", str(out)]) == 0
    df = pd.read_csv(out / "metrics.csv")
    assert sorted(df["id"]) == sorted(f"{sc['id']}-{c}" for sc, c in st.runs(quick=True))
    assert not df["failed"].any()
    html = (out / "report.html").read_text(encoding="utf-8")
    for sc in st.scenarios(quick=True):
        assert sc["id"] in html
    # no hji in these quick runs: no design recorded, said in words (was an empty table)
    assert "<h2>Design models derived from the grids</h2>\n<p>None recorded" in html
