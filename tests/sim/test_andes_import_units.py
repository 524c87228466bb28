"""Per-unit conversions of the ANDES importer against ANDES's own (issue 8, item 4)."""

import pytest

andes = pytest.importorskip("andes")

from weakgrid.sim.io.andes import from_andes  # noqa: E402
from weakgrid.sim.peer.andes_runs import load_andes  # noqa: E402

pytestmark = pytest.mark.andes


def test_shunt_rated_at_another_voltage():
    """100 Mvar rated 220 kV on a 230-kV bus is 100 (230/220)^2 = 109.3 Mvar at 1 pu."""
    ss = load_andes("kundur/kundur_full.xlsx", disable_toggles=True)
    bus = 7
    assert ss.Bus.Vn.v[ss.Bus.idx2uid(bus)] == 230.0
    ss.add("Shunt", {"bus": bus, "Sn": 100.0, "Vn": 220.0, "b": 1.0, "g": 0.2})
    system, _ = from_andes(ss)
    net = system.network
    i = net.index_of(system.andes_bus_id[bus])
    assert net.bus[i, 5] == pytest.approx(100 * (230 / 220) ** 2, rel=1e-12)   # BS [Mvar]
    assert net.bus[i, 4] == pytest.approx(20 * (230 / 220) ** 2, rel=1e-12)    # GS [MW]
    ss.setup()                                   # ANDES's own conversion to the system base
    k = ss.Shunt.idx2uid(ss.Shunt.idx.v[-1])
    assert net.bus[i, 5] == pytest.approx(ss.Shunt.b.v[k] * ss.config.mva, rel=1e-12)
    assert net.bus[i, 4] == pytest.approx(ss.Shunt.g.v[k] * ss.config.mva, rel=1e-12)
