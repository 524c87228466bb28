"""PSS/E branch data are per unit on the case's system base, also when it is not 100 MVA.

ANDES 2.0's PSS/E parser leaves ``Sn`` of non-transformer branches at the ``Line`` default
of 100 MVA while their ``R``, ``X``, ``B`` are on ``SBASE``; ANDES's stock ``nordic44``
(``SBASE`` = 1000 MVA) then has lines ten times too long and no power flow, in ANDES and in
weakgrid. The importer reads them on the system base; ANDES, given the same correction
(:func:`fix_psse_branch_base`), agrees with weakgrid's power flow.
"""

import numpy as np
import pytest

pytestmark = pytest.mark.andes

andes = pytest.importorskip("andes")

from weakgrid.sim.errors import DataError
from weakgrid.sim.io.andes import fix_psse_branch_base, from_andes
from weakgrid.sim.network import BR_B, BR_R, BR_X, F_BUS, T_BUS

RAW = "nordic44/N44_BC.raw"


def _load(addfile=None):
    andes.config_logger(40)
    return andes.load(andes.get_case(RAW), addfile=addfile, setup=False, no_output=True,
                      default_config=True)


def _nordic44_network():
    """The .raw with a classical machine on every generator (the network is the .raw's)."""
    ss = _load()
    for mname in ("Slack", "PV"):
        m = ss.models[mname]
        for k, ix in enumerate(m.idx.v):
            ss.add("GENCLS", {"bus": m.bus.v[k], "gen": ix, "Sn": m.Sn.v[k], "Vn": m.Vn.v[k],
                              "fn": 50.0, "M": 6.0, "D": 0.0, "ra": 0.0, "xd1": 0.3})
    system, _ = from_andes(ss)
    return system


def test_psse_branches_are_on_the_system_base():
    system = _nordic44_network()
    net = system.network
    assert net.Sb == 1000.0
    # N44_BC.raw, branch 3000-3115 '1': R = 0.075, X = 0.9, B = 0.5 pu on SBASE = 1000 MVA
    # and the bus base (420 kV on both ends), i.e. exactly these values in the network
    row = [k for k in range(net.nl)
           if {int(net.branch[k, F_BUS]), int(net.branch[k, T_BUS])}
           == {system.andes_bus_id[3000], system.andes_bus_id[3115]}]
    assert len(row) == 1
    np.testing.assert_allclose(net.branch[row[0], [BR_R, BR_X, BR_B]], [0.075, 0.9, 0.5], rtol=1e-12)
    assert any("system base 1000 MVA" in n for n in system.import_notes)


def test_nordic44_power_flow_matches_andes():
    system = _nordic44_network()
    pf = system.network.solve_power_flow()
    ss = _load()
    assert fix_psse_branch_base(ss)           # 67 branches rebased in ANDES's copy too
    ss.setup()
    ss.PFlow.run()
    assert ss.PFlow.converged
    Va = np.asarray(ss.Bus.v.v) * np.exp(1j * np.asarray(ss.Bus.a.v))
    order = [system.network.index_of(system.andes_bus_id[b]) for b in ss.Bus.idx.v]
    np.testing.assert_allclose(pf.V[order], Va, atol=1e-6, rtol=0)


def test_dyr_models_andes_cannot_read_are_listed():
    # N44_BC.dyr has IEEET2 exciters and STAB2A stabilizers, which ANDES's parser drops:
    # the case is refused naming them instead of running without them
    with pytest.raises(DataError) as e:
        from_andes(_load(andes.get_case("nordic44/N44_BC.dyr")))
    assert e.value.field == "models"
    assert {"IEEET2", "STAB2A"} <= set(e.value.value)
    assert "not read by ANDES" in str(e.value)


def test_fix_after_setup_is_refused():
    ss = _load()
    ss.setup()
    with pytest.raises(DataError, match="before ss.setup"):
        fix_psse_branch_base(ss)
