"""Every scenario of every shipped study can run: its events address buses and branches that
exist in the study's grid (a scenario the quick protocol skips is checked too).

Regression: ``ieee9-sg-upqc`` shipped a line trip between pandapower buses "5" and "7", which
case9 does not connect; ``weakgrid run`` stopped there, ``--quick`` (which skips the scenario)
never showed it.
"""

import pytest
from shipped import shipped_params, skip_without_andes

from weakgrid.study.build import build_setup
from weakgrid.study.runner import Run, make_events
from weakgrid.study.studyfile import load_study


@pytest.mark.parametrize("name", shipped_params())
def test_every_scenario_builds_its_events(name):
    skip_without_andes(name)
    st = load_study(name)
    setups = {}
    for sc in st.scenarios(False):
        key = (sc["load"], sc["upqc"])
        if key not in setups:
            setups[key] = build_setup(st, *key)
        run = Run.of(st, sc, sc["controllers"][0])
        events = make_events(setups[key], run)
        assert len(events) == len(sc["events"]), sc["id"]
