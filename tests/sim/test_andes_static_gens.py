"""Static generators (ANDES ``Slack``/``PV``) that no machine or converter replaces.

ANDES 2.0 keeps their power-flow equations in the time domain: a Slack holds its bus voltage
and angle (an infinite bus), a PV its active power and voltage magnitude. weakgrid imports
them as :class:`~weakgrid.sim.sources.InfiniteBus` / :class:`~weakgrid.sim.sources.PVSource`
with a note (before: the case was refused).

``kundur_islands`` (lines 7-8 open: two islands; in island 2 the static generator PV 3 is off
and Slack 5 at bus 3 has no machine). ANDES keeps GENROU 3 in service although its static
generator is off (it then initializes it from that generator's ``p0`` and reports a failed
initialization, 7 pu at bus 3); weakgrid skips such a machine with a note. The peer comparison
therefore switches GENROU 3 and its controls off in both tools, and faults bus 9 (island 2,
next to the infinite bus). Measured (h = 1/120 s, 10 s): island-2 machine speed 4.4e-6 pu,
absolute angle 0.038 deg (the infinite bus fixes the angle frame); island 1 undisturbed in both.

``ieee14_conn`` is refused for another reason, now named: its bus 15 (with PV 6) is out of
service (u = 0), which ANDES handles by disconnecting the bus.
"""

import numpy as np
import pytest

andes = pytest.importorskip("andes")

from weakgrid.sim.errors import DataError  # noqa: E402
from weakgrid.sim.io.andes import from_andes  # noqa: E402
from weakgrid.sim.peer.andes_case import interp_to, load_case, run_andes_ss, run_weakgrid_ss  # noqa: E402

pytestmark = pytest.mark.andes

H = 1 / 120


@pytest.mark.parametrize("path", ["kundur/kundur_islands.xlsx", "kundur/kundur_islands.json"])
def test_bare_slack_imports_as_infinite_bus(path):
    system, _ = from_andes(load_case(path))
    assert any("Slack 5" in n and "InfiniteBus" in n and "infinite inertia" in n for n in system.import_notes)
    system.setup()   # the initial point solves the DAE with the source holding bus 3
    ib = system.components["InfiniteBus"]
    assert ib.n == 1 and system.network.bus_ids[ib.bus[0]] == system.andes_bus_id[3]
    with pytest.raises(DataError, match="Slack 5"):
        from_andes(load_case(path), static_gens="refuse")


def test_off_bus_is_named():
    with pytest.raises(DataError, match=r"buses \[15\] are out of service"):
        from_andes(load_case("ieee14/ieee14_conn.xlsx"))


def _gen3_off(ss):
    """GENROU 3 (whose static generator PV 3 is off) and its controls out of service."""
    ss.GENROU.u.v[list(ss.GENROU.idx.v).index(3)] = 0
    for m in ss.models.values():
        if m.n and "syn" in m.params:
            for k, s in enumerate(m.syn.v):
                if s == 3:
                    m.u.v[k] = 0


@pytest.mark.slow
def test_kundur_islands_infinite_bus_matches_andes():
    tf = 10.0
    case = ("kundur/kundur_islands.xlsx",)
    w = run_weakgrid_ss(load_case(*case, fault=(9, 1.0, 1.05), modify=_gen3_off), tf, H)
    a = run_andes_ss(load_case(*case, fault=(9, 1.0, 1.05), modify=_gen3_off), tf, H)
    # ANDES's exit code flags its initialization: it checks the residual of the switched-off
    # TGOV1 3 too (7.56, an out-of-service device). Its grid starts in equilibrium all the same:
    assert w["ok"] and a["t"][-1] == pytest.approx(tf)
    pre = a["t"] < 0.99
    assert np.max(np.abs(a["omega"][pre] - 1)) < 1e-9
    assert sorted(a["names"]) == sorted(w["names"]) == ["GENROU_1", "GENROU_2", "GENROU_4"]
    tg = np.linspace(0, tf, 4001)
    A = {k: interp_to(tg, a["t"], a[k]) for k in ("omega", "delta")}
    W = {k: interp_to(tg, w["t"], w[k]) for k in ("omega", "delta")}
    ia = [a["names"].index(n) for n in w["names"]]
    dw = np.max(np.abs(A["omega"][:, ia] - W["omega"]))
    dd = np.degrees(np.max(np.abs(A["delta"][:, ia] - W["delta"])))   # absolute: the infinite bus is the frame
    swing = np.max(np.abs(W["omega"][:, 2] - 1))
    P = w["res"]["Slack_5.P"]
    print(f"kundur_islands: speed {dw:.3g} pu, angle {dd:.3g} deg, GENROU_4 swing {swing:.3g} pu, "
          f"infinite bus P {P.min():.3f}..{P.max():.3f} pu")
    assert swing > 1e-3                       # the fault is felt in the island of the infinite bus
    assert P.max() - P.min() > 1.0            # ... and the infinite bus supplies it
    assert dw < 2e-5 and dd < 0.5
