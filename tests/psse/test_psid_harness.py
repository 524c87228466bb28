"""The PSID/PSS/E harness's own pieces (weakgrid.sim.peer.psid), without PSS/E files or the reader:
the reference-change event, PSID's load conversions, the comparison arithmetic, the flow of a
branch."""

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "sim"))
from sim_cases import two_machine_case  # noqa: E402

from weakgrid.sim.events import LoadStep  # noqa: E402
from weakgrid.sim.integrate import simulate  # noqa: E402
from weakgrid.sim.peer import psid  # noqa: E402
from weakgrid.sim.system import System  # noqa: E402

pytestmark = pytest.mark.psse


def _smib(load_mw=0.0):
    case = two_machine_case(x_line=0.2, p=0.8)
    case["bus"][0, 2] = load_mw          # PD at bus 1 [MW]
    case["bus"][0, 3] = 0.3 * load_mw    # QD
    s = System(case)
    s.add_generator("G1", 0, ("GENROU", dict(Sn=200.0)), exciter=("SEXS", dict(K=100.0, TE=0.05)))
    s.add_generator("G2", 1, ("GENCLS", dict(Sn=1000.0, M=100.0)))
    return s


def test_reference_change_sets_the_exciter_reference():
    # SEXS: vi = vref - Vt (no PSS, no compensator), so vi + Vt is vref: the old value before the
    # event, exactly the new one after it
    s = _smib()
    s.setup()
    comp = s.components["SEXS"]
    v0 = float(comp.vref0[0])
    ev = psid.ReferenceChange(comp, 0, 0.5, v0 + 0.02)
    r = simulate(s, 3.0, dt=1 / 240, events=[ev])
    ref = r["G1.avr.vi"] + r["bus1.v"]
    t = r.t
    before, after = t < 0.5 - 1e-9, t > 0.5 + 1e-9
    assert np.max(np.abs(ref[before] - v0)) < 1e-12
    assert np.max(np.abs(ref[after] - (v0 + 0.02))) < 1e-12
    assert r["bus1.v"][-1] > r["bus1.v"][0] + 1e-3     # the terminal voltage follows


def test_reference_change_is_found_by_machine():
    s = _smib()
    names = psid.Names(s)
    s.psse_machine = {(1, "1"): "G1"}                 # the reader's table: PSS/E (bus, id) -> name
    comp, k = names.component("exciter", 1, "1")
    assert comp.type_name == "SEXS" and k == 0


@pytest.mark.parametrize("kind, shares", [("constant power", (100.0, 0.0, 0.0)),
                                          ("constant current", (0.0, 100.0, 0.0))])
def test_load_conversion_keeps_the_power_flow_and_changes_the_voltage_law(kind, shares):
    s = _smib(load_mw=40.0)
    psid.convert_loads(s, kind)
    z = s.components["ZIP"]
    assert len(z.links) == 1
    lk, v = z.links[0], z._values[0]
    assert (lk["P0"], lk["Q0"]) == pytest.approx((0.40, 0.12))      # the bus load, pu on 100 MVA
    assert (v["kpp"], v["kpi"], v["kpz"]) == shares
    s.setup()
    F, _ = s.residual(0.0, s.z0)
    assert np.max(np.abs(F)) < 1e-9                                  # still an equilibrium
    r = simulate(s, 1.0, dt=1 / 240, events=[LoadStep(bus=1, t=0.2, dP=0.0, dQ=50.0)])
    P, vb = r[f"{z.names[0]}.P"], r["bus1.v"]
    assert np.ptp(vb) > 1e-2                                         # the voltage moved ...
    expect = 0.40 * (vb / vb[0]) ** (0 if kind == "constant power" else 1)
    assert np.max(np.abs(P - expect)) < 1e-9                         # ... and P follows its law


def test_constant_impedance_conversion_adds_nothing():
    s = _smib(load_mw=40.0)
    psid.convert_loads(s, "constant impedance")
    assert "ZIP" not in s.components


def test_comparison_arithmetic():
    cmp = {"quantity": "bus voltage", "bus": 1, "tol": 0.01, "tol_unit": "pu", "norm": "inf"}
    t = np.linspace(0.0, 2.0, 401)
    ref = 1.0 - 0.1 * (t > 1.0)                                     # swing 0.1 pu
    out = psid.compare_series(cmp, t, ref, t, ref + 0.004)
    assert out["max_abs"] == pytest.approx(0.004) and out["swing"] == pytest.approx(0.1)
    assert out["share_of_swing"] == pytest.approx(0.04) and out["ok"]
    out = psid.compare_series(cmp, t, ref, t, ref + 0.006)         # 6 % of the swing
    assert out["within_tol"] and not out["within_swing"] and not out["ok"]
    out = psid.compare_series({**cmp, "norm": "2"}, t, ref, t, ref + 0.001)
    assert out["psid_norm"] == pytest.approx(0.001 * np.sqrt(401)) and not out["within_tol"]
    out = psid.compare_series(cmp, t, ref, t[:200], ref[:200])       # a run that stopped early
    assert not out["complete"] and not out["ok"]
    flat = psid.compare_series(cmp, t, np.ones_like(t), t, np.ones_like(t) + 1e-3)
    assert flat["swing"] == 0 and flat["ok"]                         # no swing: PSID's tolerance


def test_dedupe_keeps_the_first_sample_of_an_event():
    t = np.array([0.0, 0.5, 1.0, 1.0, 1.5])
    y = np.array([1.0, 1.0, 1.0, 0.5, 0.5])
    td, yd = psid.dedupe(t, y)
    assert list(td) == [0.0, 0.5, 1.0, 1.5] and list(yd) == [1.0, 1.0, 1.0, 0.5]


def test_branch_flow_equals_the_power_flow():
    # at t = 0 the flow of the line from bus 1 is the machine's electrical power (lossless line,
    # no load at bus 1)
    s = _smib()
    s.psse_branch_row = {(1, 2, "1"): 0}
    s.setup()
    r = simulate(s, 0.1, dt=1 / 240)
    run = {"res": r, "system": s, "names": psid.Names(s)}
    case = {"event": {"kind": "none"}}
    for end, sign in (("from", 1.0), ("to", -1.0)):
        cmp = {"quantity": "branch P", "from_bus": 1, "to_bus": 2, "ckt": "1", "end": end, "tol_unit": "pu"}
        _, P = psid.weakgrid_series(case, cmp, run)
        assert P[0] == pytest.approx(sign * 0.8, abs=1e-6)
