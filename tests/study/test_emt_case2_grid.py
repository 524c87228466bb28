"""The paper's case 2 grid in DPsim: every model it uses is represented (weakgrid.sim.emt).

Case 2 (``case2-lv-microgrid``): a GENROU with stator resistance and saturation, SEXS, TGOV1,
IEEEST, four GENCLS renewables, LV lines and loads, the UPQC series impedance, a conventional
UPQC. Oracles: with saturation the run is refused naming ``S10`` and the option; with the
saturation dropped (DPsim's unsaturated machine, its own field voltage) the grid starts at the
power flow and stays there (every model initialized consistently, the controls at rest).
"""

import numpy as np
import pytest

from weakgrid.sim.errors import DataError
from weakgrid.study.build import build_setup
from weakgrid.study.studyfile import load_study

pytest.importorskip("dpsimpy")
from weakgrid.sim.emt import simulate_dpsim  # noqa: E402

pytestmark = pytest.mark.emt


@pytest.fixture(scope="module")
def system():
    return build_setup(load_study("case2-lv-microgrid"), "high").system


def test_saturated_machine_is_refused_by_default(system):
    with pytest.raises(DataError, match="SG: GENROU S10 = 0.05.*drop_saturation"):
        simulate_dpsim(system, 0.01, engine="dpsim-dp", dt=1e-4)


@pytest.mark.parametrize("engine", ["dpsim-dp", "dpsim-emt"])
def test_case2_grid_starts_and_stays_at_the_power_flow(system, engine):
    r = simulate_dpsim(system, 0.1, engine=engine, dt=1e-4, drop_saturation=True)
    V0 = system.network.pf.V
    for b, bid in enumerate(system.network.bus_ids):
        assert r[f"bus{bid}.v"][0] == pytest.approx(abs(V0[b]), abs=1e-9)
        assert np.max(np.abs(r[f"bus{bid}.v"] - abs(V0[b]))) < 1e-4
    for nm in system.machine_names:
        assert np.max(np.abs(r[f"{nm}.omega"] - 1.0)) < 1e-6, nm
    assert np.max(np.abs(r["SG.vf"] - r["SG.vf"][0])) < 1e-4
    assert np.max(np.abs(r["SG.tm"] - r["SG.tm"][0])) < 1e-6
