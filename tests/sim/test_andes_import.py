"""The ANDES importer: which models it accepts, what it skips, how it refuses (no simulation)."""

import numpy as np
import pytest

andes = pytest.importorskip("andes")

from weakgrid.sim.errors import DataError  # noqa: E402
from weakgrid.sim.io.andes import _supported, device_name, from_andes  # noqa: E402
from weakgrid.sim.peer.andes_case import load_case  # noqa: E402

pytestmark = pytest.mark.andes

KUNDUR = "kundur/kundur_full.xlsx"


def test_all_unsupported_models_listed_in_one_message():
    ss = load_case("kundur/kundur_vsc.xlsx", keep_events=True)
    expected = sorted(n for n, m in ss.models.items() if m.n and n not in _supported())
    assert len(expected) >= 3
    with pytest.raises(DataError) as e:
        from_andes(ss)
    assert e.value.field == "models" and e.value.value == expected
    for name in expected:
        assert name in str(e.value)


def test_every_registered_model_is_accepted_hygov():
    def swap(ss):   # governor of machine 1: TGOV1 off, HYGOV on (ANDES parameter names)
        ss.TGOV1.u.v[0] = 0
        ss.add("HYGOV", {"idx": "H1", "syn": ss.TGOV1.syn.v[0], "R": 0.05, "r": 0.5, "Tr": 5.0,
                         "Tf": 0.05, "Tg": 0.5, "VELM": 0.2, "GMAX": 1.0, "GMIN": 0.0, "Tw": 1.0,
                         "At": 1.2, "qNL": 0.08})
    system, _ = from_andes(load_case(KUNDUR, modify=swap))
    assert system.components["HYGOV"].names == ["HYGOV_H1"]
    assert system.components["HYGOV"]._values[0]["r"] == 0.5
    assert len(system.components["TGOV1"].names) == 3
    assert any("TGOV1" in n and "u = 0" in n for n in system.import_notes)
    system.setup()
    F, _ = system.residual(0.0, system.z0)
    assert np.max(np.abs(F)) < 1e-6


@pytest.mark.parametrize("case, model", [("kundur/kundur_coi.xlsx", "COI"),
                                         ("kundur/kundur_freq.xlsx", "BusROCOF"),
                                         ("ieee14/ieee14_freqdiv.xlsx", "FreqDiv"),
                                         ("ieee14/ieee14_pll1.xlsx", "PLL1")])
def test_measurement_models_ignored_with_a_note(case, model):
    ss = load_case(case)
    assert ss.models[model].n > 0
    system, _ = from_andes(ss)
    assert any(n.startswith(f"{model} ({ss.models[model].n}): measurement-only")
               for n in system.import_notes)


def test_machine_of_out_of_service_generator_skipped():
    def off(ss):                         # PV 2 out of service: its GENROU (and controls) go too
        ss.PV.u.v[list(ss.PV.idx.v).index(2)] = 0
    system, events = from_andes(load_case(KUNDUR, modify=off))
    assert "GENROU_2" not in system.machine_names and len(system.machine_names) == 3
    assert any("GENROU 2" in n for n in system.import_notes)
    assert len(system.components["TGOV1"].names) == 3


def test_static_generator_without_dynamic_model_refused_by_name():
    # kundur_islands: a second Slack (idx 5, bus 3) whose machine sits on an out-of-service PV;
    # accepted by default as an infinite bus (test_andes_static_gens), refused on request
    with pytest.raises(DataError, match="Slack 5") as e:
        from_andes(load_case("kundur/kundur_islands.xlsx", keep_events=True), static_gens="refuse")
    assert "no in-service dynamic model" in str(e.value)


def test_island_without_slack_refused_naming_its_buses():
    def cut(ss):
        for k in range(ss.Line.n):
            if 8 in (ss.Line.bus1.v[k], ss.Line.bus2.v[k]):
                ss.Line.u.v[k] = 0
    with pytest.raises(DataError, match="without a slack") as e:
        from_andes(load_case(KUNDUR, modify=cut))
    assert [8] in e.value.value and [3, 4, 9, 10] in e.value.value   # every slack-less island, by bus


def test_psse_raw_dyr_through_andes_parser_equals_xlsx():
    xl, _ = from_andes(load_case(KUNDUR))
    rd, _ = from_andes(load_case(andes.get_case("kundur/kundur.raw"),
                                 addfile=andes.get_case("kundur/kundur_full.dyr")))
    assert np.allclose(xl.network.ybus(), rd.network.ybus(), atol=1e-9)
    assert len(xl.machine_names) == len(rd.machine_names) == 4
    a, b = xl.components["GENROU"]._values, rd.components["GENROU"]._values
    for va, vb in zip(a, b):
        if va["S10"] == 0:          # no saturation: S12 is unused (the .dyr reader fills in 1.0)
            va, vb = {**va, "S12": 0.0}, {**vb, "S12": 0.0}
        assert va == pytest.approx(vb)
    assert sorted(xl.components) == sorted(rd.components)


def test_zip_loads_of_a_case_not_set_up():
    """ANDES's ieee14_zip.json, read with setup=False as the importer expects: the ZIP load
    imports with the powers of the PQ load it replaces (before the fix: TypeError, the PQ
    parameters have no input copy ``vin`` before ANDES's setup). Its shares of P sum to 90 %
    (ANDES warns and starts off equilibrium): refused at setup, naming the field."""
    ss = load_case("ieee14/ieee14_zip.json")
    system, _ = from_andes(ss)
    zip_ = system.components["ZIP"]
    assert len(zip_.names) == ss.ZIP.n > 0
    k = list(ss.PQ.idx.v).index(ss.ZIP.pq.v[0])
    assert zip_.links[0]["P0"] == pytest.approx(ss.PQ.p0.v[k]) and zip_.links[0]["P0"] != 0
    with pytest.raises(DataError, match="kpp.*sum to 100") as e:
        system.setup()
    assert "= 90 %" in str(e.value)


def test_ieeevc_links_to_the_machine_of_its_exciter():
    # ANDES 2.0 fails to initialize this case (its exciters' input starts at the bus voltage);
    # weakgrid's initial point includes the compensation and solves the DAE
    ss = load_case("ieee14/ieee14_ieeevc2.xlsx")
    avr_syn = {}
    for name in ("IEEET1", "ESST3A"):
        avr_syn.update(zip(ss.models[name].idx.v, ss.models[name].syn.v))
    system, _ = from_andes(ss, conventions="andes")
    vc = system.components["IEEEVC"]
    assert vc.names == [device_name("IEEEVC", i) for i in ss.IEEEVC.idx.v]
    assert [lk["machine"] for lk in vc.links] == [device_name("GENROU", avr_syn[a])
                                                  for a in ss.IEEEVC.avr.v]
    assert [v["on_Sb"] for v in vc._values] == [1.0, 1.0]
    system.setup()
    F, _ = system.residual(0.0, system.z0)
    assert np.max(np.abs(F)) < 1e-6
    m = vc.mach
    assert np.all(np.abs(system.sig_defaults["Ecomp0"][m] - system.sig_defaults["Vt0"][m]) > 0.02)
