"""A user's grid at several load levels is one batch (weakgrid.sim.batch, Component.batch_params).

The set-points a model's ``init`` computes from the operating point (an exciter's ``vref0``, a
governor's ``pref0``, an ideal source's ``V0`` and ``p0``, ...) are declared batchable, so the
grids of one study at different loads share a batch, each member with its own set-points.

Oracle: each member's one-by-one :class:`Simulator` run on its own grid (``test_batch._same``:
its statistics and trajectories, exact on NumPy 2). Every case checks that the grids do differ
in the declared set-points (``member_params`` names them: the model is exercised at several
operating points) and that they are one batch: on the code before the declarations each of
these grids was a batch per load level. A set-point wrongly held per member (or one not bound
per member) would move a member off its run alone, which the oracle catches
(``test_a_set_point_not_bound_per_member_is_caught``).

Grids: PowerSimulationsDynamics.jl's PSS/E benchmark files (tests/data/psid: ``.raw`` +
``.dyr``, read by weakgrid's own reader, the way a user's files are), their loads scaled and the
power flow solved again at setup, as a study's load levels are; and, for the models those files
do not hold, the same three-bus network with the model on the swing unit (whose dispatch and
field follow the load) behind a voltage compensator (IEEEVC: the exciter's input voltage then
moves with the load too).
"""

import warnings
from pathlib import Path

import numpy as np
import pytest
from test_batch import DT, _alone, _same
from test_exciters_psse import EXAC2, EXPIC1, ST6B, ST8C
from test_governors_psse import threebus

from weakgrid.sim import batch
from weakgrid.sim.batch import batch_unsupported, member_params, simulate_batch, system_fingerprint
from weakgrid.sim.events import Fault, LineTrip
from weakgrid.sim.io.psse import from_psse
from weakgrid.sim.network import PD, PG, QD
from weakgrid.sim.loads import ZIP
from weakgrid.sim.renewables import ESD1, PVD1
from weakgrid.sim.sources import InfiniteBus, PVSource
from weakgrid.sim.system import System

PSID = Path(__file__).resolve().parents[1] / "data" / "psid"

#: load levels (multipliers of every PD, QD of the case)
LEVELS = (1.0, 0.9, 1.1)
T_END = 0.5


def _scaled(system, k):
    """``system`` (not set up) with every load times ``k``, set up: a new power flow, initial
    point and set-points (what a study's load level gives)."""
    net = system.network
    for tab in (net.bus, net.case["bus"]):
        tab[:, [PD, QD]] *= k
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")      # the readers' notes on the PSID files' data
        return system.setup()


def _psse(folder, dyr, raw="ThreeBusMulti.raw"):
    def build(k):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            s, _ = from_psse(PSID / folder / raw, PSID / folder / dyr, include_events=False)
        return _scaled(s, k)
    return build


#: the swing unit (bus 101, 200 MVA) and the PV unit at bus 102 (70 MW)
G1 = dict(Sn=200, M=8.0, D=0.0, ra=0.003, xl=0.15, xd=1.8, xq=1.7, xd1=0.3, xq1=0.55, xd2=0.25,
          xq2=0.25, Td10=6.0, Td20=0.03, Tq10=0.4, Tq20=0.05, S10=0.05, S12=0.3)
SEXS = ("SEXS", dict(TATB=0.4, TB=5.0, K=20.0, TE=1.0, EMIN=-50.0, EMAX=50.0))


def _swing(exciter=SEXS, governor=None, pss=None, unit102="GENROU", zip_load=False):
    """The three-bus network of PSID's benchmarks (tests/sim/test_governors_psse.threebus: 200 MW
    at bus 103) with the studied controls on the swing unit at bus 101 (a GENROU behind a
    compensator ``xc = -0.05``) and ``unit102`` at bus 102: a GENROU with SEXS, a ``PVD1``, an
    ``ESD1`` or a ``PVSource``; ``zip_load``: a ZIP load of 0.5 + j0.1 pu of bus 103's load."""
    def build(k):
        s = System(threebus(70.0, 200.0))
        s.add_generator("G1", 0, ("GENROU", G1), exciter=exciter, governor=governor, pss=pss)
        if exciter is not None:
            s.add_compensator("IEEEVC", "G1.vc", "G1", rc=0.0, xc=-0.05)
        if unit102 == "GENROU":
            s.add_generator("G2", 1, ("GENROU", dict(G1, Sn=100)), exciter=SEXS)
        elif unit102 in ("PVD1", "ESD1"):
            s.add_component(PVD1() if unit102 == "PVD1" else ESD1()).add_pvd1("D2", gen=1, Sn=100)
        else:
            s.add_component(PVSource()).add_source("S2", 1)
        if zip_load:
            s.add_component(ZIP()).add_zip("Z3", bus=2, P0=0.5, Q0=0.1, kpp=50, kpi=30, kpz=20,
                                           kqp=10, kqi=0, kqz=90)
        return _scaled(s, k)
    return build


#: id -> (grid builder at a load level, the (model, set-point) pairs that must differ)
CASES = {
    # PSS/E files (PSID): the studied unit at PV bus 102 (its field follows the load), the
    # swing bus an infinite bus (GENCLS with H = 0: its power follows the load)
    "SEXS": (_psse("SEXS", "ThreeBus_SEXS.dyr"), {("SEXS", "vref0"), ("InfiniteBus", "p0")}),
    "SCRX": (_psse("SCRX", "ThreeBus_SCRX_withRcRfd.dyr"), {("SCRX", "vref0")}),
    # (a PI regulator's vref0 is the regulated voltage, the bus's set point: the same; its
    # initial bounds, the operating point's, are masked)
    "ST8C": (_psse("ST8C", "ThreeBus_ST8C.dyr"), {("InfiniteBus", "p0")}),
    "ESAC1A": (_psse("AC1A", "ThreeBus_ESAC1A_SAT.dyr"), {("ESAC1A", "vref0")}),
    "HYGOV": (_psse("HYGOV", "ThreeBus_HYGOV.dyr"), {("SEXS", "vref0")}),
    "GAST": (_psse("GAST", "ThreeBus_GAST.dyr"), {("ESAC1A", "vref0")}),
    "PIDGOV": (_psse("PIDGOV", "ThreeBus_PIDGOV_GateFlag.dyr"), {("SEXS", "vref0")}),
    "IEEEST": (_psse("IEEEST", "ThreeBus_IEEEST_with_filter.dyr"), {("SEXS", "vref0")}),
    "EXST1-GENSAL": (_psse("EXST1", "TVC_System.dyr", "TVC_System_32.raw"),
                     {("EXST1", "vref0")}),
    "EXAC1-GENSAL": (_psse("EXAC1", "TVC_System.dyr", "TVC_System_32.raw"), {("EXAC1", "vref0")}),
    "GENSAE": (_psse("GENSAE", "ThreeBus_GENSAE.dyr"), {("InfiniteBus", "p0")}),
    "GENROE": (_psse("GENROE", "ThreeBus_GENROE.dyr"), {("InfiniteBus", "p0")}),
    # the swing unit's controls (weakgrid's defaults, or the data of their own tests)
    "ESST1A": (_swing(("ESST1A", {})), {("ESST1A", "vref0")}),
    "ESST3A": (_swing(("ESST3A", {})), {("ESST3A", "vref0")}),
    "ESST4B": (_swing(("ESST4B", {})), {("ESST4B", "vref0")}),
    "IEEET1": (_swing(("IEEET1", {})), {("IEEET1", "vref0")}),
    "IEEET3": (_swing(("IEEET3", {})), {("IEEET3", "vref0")}),
    "ESDC1A": (_swing(("ESDC1A", {})), {("ESDC1A", "vref0"), ("ESDC1A", "_vt0")}),
    "EXAC4": (_swing(("EXAC4", {})), {("EXAC4", "vref0")}),
    "ESAC6A": (_swing(("ESAC6A", {})), {("ESAC6A", "vref0")}),
    "EXAC2": (_swing(("EXAC2", EXAC2)), {("EXAC2", "vref0")}),
    "EXPIC1": (_swing(("EXPIC1", EXPIC1)), {("EXPIC1", "vref0")}),
    "ST6B": (_swing(("ST6B", ST6B)), {("ST6B", "vref0")}),
    "ST8C-swing": (_swing(("ST8C", ST8C)), {("ST8C", "vref0")}),
    "TGOV1N": (_swing(governor=("TGOV1N", {})), {("TGOV1N", "pref0")}),
    "HYGOV-swing": (_swing(governor=("HYGOV", {})), {("HYGOV", "pref0")}),
    "GAST-swing": (_swing(governor=("GAST", {})), {("GAST", "pref0")}),
    "IEEEG1": (_swing(governor=("IEEEG1", {})), {("IEEEG1", "P0")}),
    "IEESGO": (_swing(governor=("IEESGO", {})), {("IEESGO", "pref0")}),
    "TG2": (_swing(governor=("TG2", {})), {("TG2", "pref0")}),
    "PIDGOV-swing": (_swing(governor=("PIDGOV", {})), {("PIDGOV", "pref0")}),
    "WPIDHY": (_swing(governor=("WPIDHY", {})), {("WPIDHY", "pref0")}),
    "PSS2A": (_swing(pss=("PSS2A", {})), {("SEXS", "vref0")}),
    "PSS2B": (_swing(pss=("PSS2B", {})), {("SEXS", "vref0")}),
    "ST2CUT": (_swing(pss=("ST2CUT", {})), {("SEXS", "vref0")}),
    "STAB1": (_swing(pss=("STAB1", {})), {("SEXS", "vref0")}),
    "PVD1": (_swing(unit102="PVD1"), {("PVD1", "V0"), ("PVD1", "qref0")}),
    "ESD1": (_swing(unit102="ESD1"), {("ESD1", "V0"), ("ESD1", "qref0")}),
    "PVSource": (_swing(unit102="PVSource"), {("PVSource", "V0")}),
    "ZIP": (_swing(zip_load=True), {("ZIP", "v0"), ("ZIP", "y0")}),
}


def _scenarios(grids):
    bus = int(grids[0].network.bus_ids[-1])          # a fault at the load bus
    return [{"system": g, "events": [Fault(bus, 0.1, 0.15, xf=0.1)]} for g in grids]


@pytest.mark.parametrize("case", list(CASES))
def test_a_grid_at_several_loads_is_one_batch_equal_to_its_runs_alone(case):
    build, declared = CASES[case]
    grids = [build(k) for k in LEVELS]
    assert len({system_fingerprint(g) for g in grids}) == 1
    # the set-points do differ per member, beyond round-off: in these PSS/E cases the
    # governors' units are not the slack, so their pref0 moves by 1 ulp between load levels
    # (or not at all); the *-swing cases put them on the slack
    differ = {(grids[0].comps[j].type_name, name) for j, name, v in member_params(grids)
              if np.abs(v - v[0]).max() > 1e-9 * np.abs(v).max()}
    assert declared <= differ, differ
    alone = [_alone(g, sc, T_END, dt=DT) for g, sc in zip(grids, _scenarios(grids))]
    st = {}
    got = simulate_batch(grids[0], _scenarios(grids), T_END, dt=DT, stats=st)
    assert st["batches"] == 1 and st["alone"] == 0 and st["rerun"] == 0
    for a, b in zip(alone, got):
        assert a.ok and b.ok
        _same(a, b)
    # the members are different operating points (their runs differ)
    assert np.abs(got[0].data - got[1].data).max() > 1e-3


def test_a_set_point_not_bound_per_member_is_caught(monkeypatch):
    """The guard of the oracle above: were the members evaluated with the first member's
    set-points (a set-point the batch does not hold per member), the members at other loads
    would leave their runs alone."""
    build, _ = CASES["ESST1A"]
    grids = [build(k) for k in LEVELS[:2]]
    alone = [_alone(g, sc, T_END, dt=DT) for g, sc in zip(grids, _scenarios(grids))]
    monkeypatch.setattr(batch, "member_params", lambda systems: [])
    got = simulate_batch(grids[0], _scenarios(grids), T_END, dt=DT)
    _same(alone[0], got[0])
    with pytest.raises(AssertionError):
        _same(alone[1], got[1])


def test_loads_at_an_ideal_sources_bus_keep_grids_apart():
    """An ideal source evaluates its bus's current balance from the evaluating grid's network
    rows, which hold the loads at its bus: grids whose loads differ there are not one batch
    (``bus_load``), those whose loads differ elsewhere are."""
    def at(k_source_bus, k_other):
        case = threebus(70.0, 200.0)
        case["bus"][0, [PD, QD]] = [20.0 * k_source_bus, 5.0]
        case["bus"][2, [PD, QD]] *= k_other
        s = System(case)
        s.add_generator("G2", 1, ("GENROU", dict(G1, Sn=100)), exciter=SEXS)
        s.add_component(InfiniteBus()).add_source("IB", 0)
        return s.setup()
    base = system_fingerprint(at(1.0, 1.0))
    assert system_fingerprint(at(1.0, 1.2)) == base
    assert system_fingerprint(at(1.5, 1.0)) != base


def test_an_event_at_an_ideal_sources_bus_runs_alone():
    """A member whose event changes the network rows of the infinite bus's bus (PSID's trip of
    line 101-102, a fault at bus 101) is run one by one, equal to its run alone; the batch
    evaluated the source with the pre-event rows (on the code before: 0.88 pu off its run alone
    after the trip)."""
    build, _ = CASES["SEXS"]
    grids = [build(k) for k in LEVELS[:2]]

    def scen():
        return [{"system": grids[0], "events": [LineTrip(0, 0.1)]},             # 101-102
                {"system": grids[1], "events": [Fault(101, 0.1, 0.15, xf=0.1)]},
                {"system": grids[1], "events": [Fault(103, 0.1, 0.15, xf=0.1)]},
                {"system": grids[0], "events": [LineTrip(2, 0.1)]}]              # 102-103
    alone = [_alone(sc["system"], sc, T_END, dt=DT) for sc in scen()]
    assert "InfiniteBus" in batch_unsupported(grids[0], [LineTrip(0, 0.1)])
    assert batch_unsupported(grids[0], [LineTrip(2, 0.1)]) is None
    st = {}
    got = simulate_batch(grids[0], scen(), T_END, dt=DT, stats=st)
    assert st["alone"] == 2 and st["batches"] == 1
    for a, b in zip(alone, got):
        _same(a, b)


@pytest.mark.parametrize("folder, dyr, raw", [
    ("HYGOV", "ThreeBus_HYGOV.dyr", "ThreeBusMulti.raw"),
    ("GAST", "ThreeBus_GAST.dyr", "ThreeBusMulti.raw"),
    ("PIDGOV", "ThreeBus_PIDGOV_GateFlag.dyr", "ThreeBusMulti.raw"),
    ("EXST1", "TVC_System.dyr", "TVC_System_32.raw")])
def test_a_grid_at_several_dispatches_is_one_batch_equal_to_its_runs_alone(folder, dyr, raw):
    """The studied unit's dispatch changed (its generator row's PG, a power-flow input, as a
    study's per-level ``add_gen`` does): its governor's ``pref0`` and its exciter's ``vref0``
    are the members' own; one batch (on the code before: a batch per dispatch)."""
    def at(k):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            s, _ = from_psse(PSID / folder / raw, PSID / folder / dyr, include_events=False)
        net = s.network
        pv = net.bus[[net.index_of(int(b)) for b in net.gen[:, 0]], 1] == 2
        row = int(np.argmax(np.where(pv, net.gen[:, PG], -np.inf)))     # the largest PV unit
        for tab in (net.gen, net.case["gen"]):
            tab[row, PG] *= k
        return _scaled(s, 1.0)
    grids = [at(k) for k in (1.0, 0.8, 0.9)]
    assert len({system_fingerprint(g) for g in grids}) == 1
    differ = {name for _, name, _ in member_params(grids)}
    assert {"pref0", "vref0"} <= differ, differ
    alone = [_alone(g, sc, T_END, dt=DT) for g, sc in zip(grids, _scenarios(grids))]
    st = {}
    got = simulate_batch(grids[0], _scenarios(grids), T_END, dt=DT, stats=st)
    assert st["batches"] == 1 and st["alone"] == 0
    for a, b in zip(alone, got):
        _same(a, b)
