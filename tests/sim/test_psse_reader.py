"""The native PSS/E reader (weakgrid.sim.io.psse): .raw v29-35, .dyr, PSS/E conventions, errors.

Oracles: the solved voltages stored in each PSS/E-saved .raw (the power flow of the read case must
reproduce them), PSS/E's own rotor-angle result of the GENROU benchmark (PowerSimulationsDynamics.jl,
BSD-3, vendored in tests/data/psse_reader with its licence), invariances (SBASE rescaling, v33 vs
v35 layout, a three-winding transformer with an open winding = a two-winding one). Regression tests
for the silent changes of issue 26 made by the ANDES route.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from weakgrid.sim.errors import DataError
from weakgrid.sim.io.psse import from_psse, read_dyr, read_raw
from weakgrid.sim.io.psse.network import build_case
from weakgrid.sim.io.psse.tokens import split_line
from weakgrid.sim.network import Network
from weakgrid.sim.system import _registry

DATA = Path(__file__).resolve().parents[1] / "data" / "psse_reader"
RAWS = sorted((DATA / "raw").glob("*.raw"))
GENROU_RAW = DATA / "raw" / "GENROU__ThreeBusMulti.raw"
TVC_RAW = DATA / "raw" / "ESST1A__TVC_System_32.raw"


def _net(path_or_case):
    raw = read_raw(path_or_case)
    case, maps = build_case(raw)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return raw, Network(case, raw.basfrq), maps


def _raw_voltages(raw, net):
    vref = {b["i"]: b["vm"] * np.exp(1j * np.radians(b["va"])) for b in raw.buses}
    k = [i for i, b in enumerate(net.bus_ids) if b in vref]
    return k, np.array([vref[net.bus_ids[i]] for i in k])


def _raw_mismatch(raw, net):
    """Largest bus power mismatch [pu] of the .raw's own stored voltages (a solved case: ~0)."""
    k, Vr = _raw_voltages(raw, net)
    V = np.ones(net.nb, complex)
    V[k] = Vr
    S = V * np.conj(net.ybus() @ V)
    Sg = np.zeros(net.nb, complex)
    for g in net.gen:
        if g[7] > 0:
            Sg[net.index_of(int(g[0]))] += (g[1] + 1j * g[2]) / net.Sb
    mis = S - Sg + (net.bus[:, 2] + 1j * net.bus[:, 3]) / net.Sb
    slack = net.bus[:, 1] == 3
    mis[slack] = 0          # its generator's stored output is rounded
    # relative to the bus's admittance row: VM, VA are printed to 5 digits, and across a short
    # branch (large |Y|) that rounding alone makes a large power mismatch
    scale = np.asarray(np.abs(net.ybus()).sum(axis=1)).ravel()
    return float(np.max(np.abs(mis[k]) / scale[k]))


# --------------------------------------------------------------------------- tokenizer
def test_tokenizer_quotes_commas_blanks_and_comment():
    f, slash = split_line("  101,'BUS 1, A/B', 138.0,,3 / comment, 'x'")
    assert [x.text for x in f] == ["101", "BUS 1, A/B", "138.0", None, "3"]
    assert [x.quoted for x in f] == [False, True, False, False, False]
    assert slash
    f, slash = split_line("102 'GENROU' EG  8.0  0.03")
    assert [x.text for x in f] == ["102", "GENROU", "EG", "8.0", "0.03"] and not slash


# --------------------------------------------------------------------------- .raw
@pytest.mark.parametrize("path", RAWS, ids=lambda p: p.stem)
def test_every_psid_raw_reads_and_solves(path):
    raw, net, _ = _net(path)
    assert raw.version in (32, 33)
    assert net.nb >= len([b for b in raw.buses if b["ide"] != 4])
    net.solve_power_flow()


#: PSS/E-saved (solved) cases among them; the others were edited by hand after the solve
SOLVED = ["GENROU__ThreeBusMulti", "AC1A__ThreeBusMulti", "ESST1A__TVC_System_32", "GAST__14bus",
          "MultiGen__FourBusMulti", "Test01__OMIB", "WSCC_9_bus", "240busWECC_2018_PSS32_fixed_shunts"]


@pytest.mark.parametrize("path", RAWS, ids=lambda p: p.stem)
def test_power_flow_reproduces_the_raw_solved_voltages(path):
    raw, net, _ = _net(path)
    solved = _raw_mismatch(raw, net) < 1e-3     # [pu voltage]: a solved case is ~1e-5
    if path.stem in SOLVED:
        assert solved, "a PSS/E-solved case must satisfy its own stored voltages"
    if not solved:
        pytest.skip("hand-edited after PSS/E's solve: its stored voltages are not a solution")
    pf = net.solve_power_flow()
    k, Vr = _raw_voltages(raw, net)
    V = pf.V[k]
    # PSS/E solves to 0.1 MW/Mvar (its default tolerance), and prints VM to 1e-5 pu, VA to 1e-4 deg
    assert np.max(np.abs(np.abs(V) - np.abs(Vr))) < 5e-5
    assert np.max(np.abs(np.degrees(np.angle(V / Vr)))) < 1e-2


def test_240_bus_wecc_reads_with_transformers_and_switched_shunts():
    raw, net, maps = _net(DATA / "raw" / "240busWECC_2018_PSS32_fixed_shunts.raw")
    assert len(raw.buses) == 243 and len(raw.transformers) == 122 and len(raw.switched_shunts) == 7
    assert net.nl == len(raw.branches) + len(raw.transformers)
    assert maps.bus_name[1001] == raw.buses[0]["name"]


def test_v32_transformer_with_off_nominal_winding2():
    """TVC: WINDV2 = 1.04 on the step-up transformer; TAP = t1/t2, Z·t2² (PSS/E's model)."""
    raw, net, maps = _net(TVC_RAW)
    t = [x for x in raw.transformers if (x["i"], x["j"]) == (2, 4)][0]
    assert t["windv2"] == pytest.approx(1.04)
    row = maps.transformer_rows[(2, 4, 0, "1")][0]
    assert net.branch[row, 8] == pytest.approx(1.0 / 1.04)
    # CZ = 2: X = 0.088 pu on SBASE1-2 = 550 MVA
    assert net.branch[row, 3] == pytest.approx(0.088 * 100 / 550 * 1.04 ** 2)


def _rewrite(src: Path, dst: Path, fn):
    lines = src.read_text().splitlines()
    dst.write_text("\n".join(fn(lines)) + "\n")
    return dst


def test_sbase_not_100_is_a_change_of_base_only(tmp_path):
    """SBASE = 200 with every pu impedance doubled (admittances halved), powers in MW unchanged:
    the same case, so the same solved voltages."""
    def scale(lines):
        out = []
        for k, s in enumerate(lines):
            if k == 0:
                s = s.replace("100.00", "200.00", 1)
            elif re.match(r"\s+10[123],\s+10[123],'1 '", s):
                f = s.split(",")
                f[3] = f"{2 * float(f[3]):.6E}"
                f[4] = f"{2 * float(f[4]):.6E}"
                f[5] = f"{float(f[5]) / 2:.6f}"
                s = ",".join(f)
            out.append(s)
        return out
    p = _rewrite(GENROU_RAW, tmp_path / "sb200.raw", scale)
    raw1, net1, _ = _net(GENROU_RAW)
    raw2, net2, _ = _net(p)
    assert raw2.sbase == 200.0
    V1 = net1.solve_power_flow().V
    V2 = net2.solve_power_flow().V
    np.testing.assert_allclose(V2, V1, atol=1e-10)


def _v35_from_v33_genrou(path: Path):
    """The GENROU three-bus case written in the v35 layout (system-wide data, NREG, NAME and 12
    ratings in branch records, @! comment lines)."""
    raw = read_raw(GENROU_RAW)
    L = ["0, 100.00, 35, 0, 0, 60.00 / PSS(R)E 35 RAW, written by the test", "title 1", "title 2",
         "GENERAL, THRSHZ=0.0001, PQBRAK=0.7, BLOWUP=5.0",
         'RATING, 1, "RATE1 ", "RATING SET 1 "',
         "0 / END OF SYSTEM-WIDE DATA, BEGIN BUS DATA",
         "@!   I,'NAME        ', BASKV, IDE,AREA,ZONE,OWNER, VM,        VA,    NVHI,   NVLO,   EVHI,   EVLO"]
    for b in raw.buses:
        L.append(f"{b['i']},'{b['name']}', {b['baskv']}, {b['ide']}, 1, 1, 1, {b['vm']}, {b['va']}, 1.1, 0.9, 1.1, 0.9")
    L.append("0 / END OF BUS DATA, BEGIN LOAD DATA")
    for d in raw.loads:
        L.append(f"{d['i']},'{d['id']}', 1, 1, 1, {d['pl']}, {d['ql']}, 0, 0, 0, 0, 1, 1, 0, 0.0, 0.0, 0, 'LDTYPE'")
    L.append("0 / END OF LOAD DATA, BEGIN FIXED SHUNT DATA")
    L.append("0 / END OF FIXED SHUNT DATA, BEGIN GENERATOR DATA")
    for g in raw.generators:
        L.append(f"{g['i']},'{g['id']}', {g['pg']}, {g['qg']}, {g['qt']}, {g['qb']}, {g['vs']}, 0, 0, "
                 f"{g['mbase']}, {g['zr']}, {g['zx']}, 0, 0, 1, 1, 100.0, {g['pt']}, {g['pb']}, 0, 1, 1.0, "
                 "0, 1.0, 0, 1.0, 0, 1.0, 0, 1.0")
    L.append("0 / END OF GENERATOR DATA, BEGIN BRANCH DATA")
    for br in raw.branches:
        L.append(f"{br['i']}, {br['j']},'{br['ckt']}', {br['r']}, {br['x']}, {br['b']}, 'LINE', "
                 + ", ".join(["250.0"] * 12) + ", 0, 0, 0, 0, 1, 1, 0.0, 1, 1.0")
    L.append("0 / END OF BRANCH DATA, BEGIN SYSTEM SWITCHING DEVICE DATA")
    for sec in ("SYSTEM SWITCHING DEVICE", "TRANSFORMER", "AREA", "TWO-TERMINAL DC", "VSC DC",
                "IMPEDANCE CORRECTION", "MULTI-TERMINAL DC", "MULTI-SECTION LINE", "ZONE",
                "INTER-AREA TRANSFER", "OWNER", "FACTS DEVICE", "SWITCHED SHUNT", "GNE",
                "INDUCTION MACHINE"):
        L.append(f"0 / END OF {sec} DATA, BEGIN NEXT DATA")
    L[-1] = "0 / END OF INDUCTION MACHINE DATA, BEGIN SUBSTATION DATA"
    L.append("0 / END OF SUBSTATION DATA")
    L.append("Q")
    path.write_text("\n".join(L) + "\n")
    return path


def test_v35_layout_reads_as_the_v33_case(tmp_path):
    p = _v35_from_v33_genrou(tmp_path / "genrou35.raw")
    raw35, net35, _ = _net(p)
    raw33, net33, _ = _net(GENROU_RAW)
    assert raw35.version == 35
    np.testing.assert_array_equal(net35.gen[:, :10], net33.gen[:, :10])
    np.testing.assert_allclose(net35.branch[:, :5], net33.branch[:, :5])
    np.testing.assert_allclose(net35.solve_power_flow().V, net33.solve_power_flow().V, atol=1e-12)


def test_three_winding_with_open_winding_equals_two_winding(tmp_path):
    """A star whose winding 3 is open (STAT = 3) carries Z1 + Z2 = Z12 between buses 1 and 2."""
    def three(lines):
        out, k = [], 0
        while k < len(lines):
            s = lines[k]
            if s.startswith("     2,     4,     0,'1 '"):
                out.append("     2,     4,     3,'1 ',1,1,1, 0.00000E+0, 0.00000E+0,2,'T3W',3,   1,1.0000")
                out.append(" 0.00000E+0, 1.60000E-2, 100.0, 0.0, 0.05, 100.0, 0.0, 0.07, 100.0, 1.0, 0.0")
                out.append("1.00000,  13.800,   0.000,   550.00,   550.00,     0.00, 0,      4, 1.1, 0.9, 1.1, 0.9,  33, 0, 0.0, 0.0, 0.0")
                out.append("1.04000, 230.000,   0.000,   550.00,   550.00,     0.00, 0,      4, 1.1, 0.9, 1.1, 0.9,  33, 0, 0.0, 0.0, 0.0")
                out.append("1.00000,  34.500,   0.000,   550.00,   550.00,     0.00, 0,      4, 1.1, 0.9, 1.1, 0.9,  33, 0, 0.0, 0.0, 0.0")
                k += 4
                continue
            out.append(s)
            k += 1
        return out
    p = _rewrite(TVC_RAW, tmp_path / "t3w.raw", three)
    raw3, net3, maps = _net(p)
    star = maps.star_bus[(2, 4, 3, "1")]
    rows = maps.transformer_rows[(2, 4, 3, "1")]
    assert net3.branch[rows[2], 10] == 0 and net3.branch[rows[0], 10] == 1   # winding 3 open
    z1, z2 = net3.branch[rows[0], 3], net3.branch[rows[1], 3]
    # Z12 = 0.016 pu (CZ = 1): Z1 = (0.016 + 0.07 - 0.05)/2, Z2 = (0.016 + 0.05 - 0.07)/2
    assert z1 + z2 == pytest.approx(0.016)
    # two-winding reference, same ratios: t1 = 1.0, t2 = 1.04 -> TAP = t1/t2, Z·t2²
    def two(lines):
        return [s.replace(" 0.00000E+0, 8.80000E-2,   550.00", " 0.00000E+0, 1.60000E-2,   100.00") for s in lines]
    p2 = _rewrite(TVC_RAW, tmp_path / "t2w.raw", two)
    _, net2, _ = _net(p2)
    # the star adds a bus: compare the voltages of the common buses after solving both
    V3 = net3.solve_power_flow().V
    V2 = net2.solve_power_flow().V
    ids3 = list(net3.bus_ids)
    for k, b in enumerate(net2.bus_ids):
        assert V3[ids3.index(b)] == pytest.approx(V2[k], abs=1e-9)
    assert star not in net2.bus_ids


# --------------------------------------------------------------------------- .dyr
def test_dyr_records_span_lines_and_take_text_ids():
    recs = read_dyr(DATA / "240busWECC_2018_PSS.dyr")
    eg = [r for r in recs if r.id == "EG"]
    assert eg and {r.model for r in eg} >= {"GENROU", "SEXS"}
    g = [r for r in recs if r.model == "GENROU"][0]
    assert len(g.values) == 14                      # spans 4 lines
    rep = [r for r in recs if r.model == "REPCA1"][0]
    assert "0 " in rep.values                      # the quoted branch-id ICON stays text


def test_text_field_eg_parses(tmp_path):
    """Issue 26: a .dyr with a text field ('EG') crashed ANDES's parser."""
    d = tmp_path / "eg.dyr"
    d.write_text("101 'GENCLS' 1 0.0 0.0 /\n102 'GENROU' 'EG' 8.0 0.03 0.4 0.05 6.175 0.05 1.8 1.7 0.3\n"
                 " 0.55 0.25 0.2 0.1 0.8 /\n")
    r = tmp_path / "eg.raw"
    r.write_text(GENROU_RAW.read_text().replace("   102,'1 ',   100.000", "   102,'EG',   100.000"))
    system, _ = from_psse(r, d)
    assert system.psse_machine[(102, "EG")] == "GENROU_102_EG"
    system.setup()


# --------------------------------------------------------------------------- conventions
def test_gencls_h0_is_an_infinite_bus_not_a_machine():
    """Issue 26: ANDES's route made the H = 0 GENCLS a machine with M = 6 s."""
    system, events = from_psse(GENROU_RAW, DATA / "ThreeBus_GENROU.dyr")
    assert events == []
    assert "GENCLS" not in system.components
    src = system.components["InfiniteBus"]
    assert src.names == ["GENCLS_101_1"]
    assert any("H = 0" in n and "InfiniteBus" in n for n in system.import_notes)
    assert system.psse_machine[(101, "1")] == "GENCLS_101_1"


def test_gencls_with_inertia_is_a_machine():
    system, _ = from_psse(GENROU_RAW, DATA / "ThreeBus_GENCLS.dyr")
    g = system.components["GENCLS"]
    assert g.names == ["GENCLS_102_1"]
    v = g._values[0]
    assert v["M"] == pytest.approx(2 * 6.175) and v["D"] == pytest.approx(0.05)
    assert v["xd1"] == pytest.approx(0.25)          # ZSORCE of the generator record
    assert v["Sn"] == 100.0 and v["Vn"] == 138.0 and v["fn"] == 60.0


def test_genrou_fields_bases_and_zsorce():
    system, _ = from_psse(GENROU_RAW, DATA / "ThreeBus_GENROU.dyr")
    v = system.components["GENROU"]._values[0]
    expect = dict(Td10=8.0, Td20=0.03, Tq10=0.4, Tq20=0.05, M=2 * 6.175, D=0.05, xd=1.8, xq=1.7,
                  xd1=0.3, xq1=0.55, xd2=0.25, xq2=0.25, xl=0.2, S10=0.1, S12=0.8, ra=0.0,
                  Sn=100.0, Vn=138.0)
    for k, x in expect.items():
        assert v[k] == pytest.approx(x), k


def test_esac1a_fields_land_on_their_parameters():
    """Issue 26: ANDES read ESAC1A as TR, TB, TC, VAMAX, ... (KA is PSS/E's 4th CON)."""
    system, _ = from_psse(GENROU_RAW, DATA / "ThreeBus_ESAC1A.dyr")
    v = system.components["ESAC1A"]._values[0]
    expect = dict(TR=0.01, TB=0.1, TC=0.0, KA=200.0, TA=0.05, VAMAX=7.0, VAMIN=-7.0, TE=1.333,
                  KF=0.02, TF=0.8, KC=0.0, KD=0.0, KE=1.0, E1=0.0, SE1=0.0, E2=0.0, SE2=0.0,
                  VRMAX=10.0, VRMIN=-10.0)
    for k, x in expect.items():
        assert v[k] == pytest.approx(x), k
    system.setup()


def test_gensal_is_never_replaced_by_genrou():
    """Issue 26: ANDES replaced GENSAL by GENROU with invented xq1, Tq10."""
    dyr = DATA / "ThreeBus_GENSAL.dyr"
    cls = _registry().get("GENSAL")
    if cls is not None and getattr(cls, "psse_record", None) is not None:
        system, _ = from_psse(GENROU_RAW, dyr)
        assert "GENSAL" in system.components and "GENROU" not in system.components
        return
    with pytest.raises(DataError) as e:
        from_psse(GENROU_RAW, dyr)
    msg = str(e.value)
    assert "GENSAL at bus 102 id '1'" in msg and "ThreeBus_GENSAL.dyr line 2" in msg
    assert "GENROU" not in msg


def test_every_unsupported_record_listed_in_one_error(tmp_path):
    d = tmp_path / "many.dyr"
    # models no branch of weakgrid has (GENTPJ, ESST5B, PSS3B): each listed, none dropped
    d.write_text("101 'GENCLS' 1 0 0 /\n102 'GENTPJ' 1 1 2 3 /\n102 'ESST5B' 1 1 2 /\n"
                 "102 'PSS3B' 1 1 /\n")
    with pytest.raises(DataError) as e:
        from_psse(GENROU_RAW, d)
    msg = str(e.value)
    for what in ("GENTPJ at bus 102 id '1' (many.dyr line 2)",
                 "ESST5B at bus 102 id '1' (many.dyr line 3)",
                 "PSS3B at bus 102 id '1' (many.dyr line 4)"):
        assert what in msg


def test_remote_bus_zero_is_local(tmp_path):
    """IEEEST's remote-bus ICON: 0 (and the machine's own bus) = local sensing; another bus is
    refused naming file, line and field."""
    base = (DATA / "ThreeBus_IEEEST.dyr").read_text()
    system, _ = from_psse(GENROU_RAW, DATA / "ThreeBus_IEEEST.dyr")
    assert system.components["IEEEST"].names == ["IEEEST_102_1"]
    own = tmp_path / "own.dyr"
    own.write_text(base.replace("'IEEEST' 1  1  0 ", "'IEEEST' 1  1  102 "))
    from_psse(GENROU_RAW, own)
    far = tmp_path / "far.dyr"
    far.write_text(base.replace("'IEEEST' 1  1  0 ", "'IEEEST' 1  1  103 "))
    with pytest.raises(DataError) as e:
        from_psse(GENROU_RAW, far)
    assert "far.dyr line 6" in str(e.value) and "BUSR" in str(e.value) and "103" in str(e.value)


def test_negative_branch_resistance_accepted_with_a_note(tmp_path):
    """Issue 26: negative R (network equivalents) was refused."""
    p = _rewrite(GENROU_RAW, tmp_path / "negr.raw",
                 lambda ls: [s.replace("   102,   103,'1 ', 1.00000E-2", "   102,   103,'1 ', -1.00000E-3")
                             for s in ls])
    system, _ = from_psse(p, DATA / "ThreeBus_GENROU.dyr")
    row = system.psse_branch_row[(102, 103, "1")]
    assert system.network.branch[row, 2] == pytest.approx(-1e-3)
    assert any("negative resistance" in n and "102-103" in n for n in system.import_notes)
    system.setup()


def test_static_generators_without_dyr():
    system, _ = from_psse(GENROU_RAW)
    assert system.components["InfiniteBus"].names == ["InfiniteBus_101_1"]
    assert system.components["PVSource"].names == ["PVSource_102_1"]
    with pytest.raises(DataError, match="no machine record"):
        from_psse(GENROU_RAW, static_gens="refuse")


#: PSID benchmark cases on the GENROU three-bus network (trip of line 101-102 at 1 s): dyr,
#: PSS/E's CSV (every 10th row), {CSV column: quantity}, PSID's own tolerance per quantity
PSSE_CASES = [
    ("ThreeBus_TGOV1.dyr", "GENROU__ThreeBusMulti.raw", "TEST_TGOV1_every10.csv", {1: "delta"}),
    ("ThreeBus_GAST.dyr", "GAST__ThreeBusMulti.raw", "GAST_TEST_every10.csv", {1: "delta"}),
    ("ThreeBus_HYGOV.dyr", "HYGOV__ThreeBusMulti.raw", "HYGOV_RESULTS_every10.csv", {1: "V", 2: "delta"}),
    ("ThreeBus_IEEEST.dyr", "GENROU__ThreeBusMulti.raw", "IEEEST_SEXS_RESULTS_NOFILT_every10.csv", {1: "vf"}),
    ("ThreeBus_SEXS.dyr", "GENROU__ThreeBusMulti.raw", "SEXS_RESULTS_every10.csv", {1: "V", 2: "vf"}),
]
#: PSID's tolerances: rotor angle 1e-2 rad, voltage 1e-3 pu (HYGOV) / 1e-2 (SEXS), field voltage 1e-2 pu
TOL = {"delta": np.degrees(1e-2), "V": 1e-3, "vf": 1e-2}


@pytest.mark.psse
@pytest.mark.parametrize("dyr, raw, csv, cols", PSSE_CASES, ids=[c[0][9:-4] for c in PSSE_CASES])
def test_field_orders_against_psse_results(dyr, raw, csv, cols):
    """The PSS/E field orders of TGOV1, GAST (with ESAC1A), HYGOV, IEEEST and SEXS, checked by
    PSS/E's own results: within PSID's tolerance and 5 % of PSS/E's swing of each quantity."""
    from weakgrid.sim.events import LineTrip
    from weakgrid.sim.integrate import simulate

    system, _ = from_psse(DATA / "raw" / raw, DATA / dyr)
    res = simulate(system, 20.0, events=[LineTrip(system.psse_branch_row[(101, 102, "1")], 1.0)])
    ref = np.loadtxt(DATA / csv, delimiter=",")
    series = {"delta": np.degrees(res["GENROU_102_1.delta"]), "V": res["bus102.v"],
              "vf": res["GENROU_102_1.vf"]}
    for c, q in cols.items():
        y = series[q]
        err = np.max(np.abs(np.interp(ref[:, 0], res.t, y) - ref[:, c]))
        assert err < TOL[q] and err < 0.05 * np.ptp(ref[:, c]), (q, err)


def test_genrou_case_matches_psse_rotor_angle():
    """PSS/E's own result (PSID benchmark GENROU, trip of line 101-102 at 1 s): the rotor angle
    within 0.1 deg and 5 % of its swing (4.3 deg)."""
    from weakgrid.sim.events import LineTrip
    from weakgrid.sim.integrate import simulate

    system, _ = from_psse(GENROU_RAW, DATA / "ThreeBus_GENROU.dyr")
    res = simulate(system, 20.0, events=[LineTrip(system.psse_branch_row[(101, 102, "1")], 1.0)])
    ref = np.loadtxt(DATA / "TEST_GENROU_every10.csv", delimiter=",")
    d = np.interp(ref[:, 0], res.t, np.degrees(res["GENROU_102_1.delta"]))
    err = np.max(np.abs(d - ref[:, 1]))
    assert err < 0.1 and err < 0.05 * np.ptp(ref[:, 1])


# --------------------------------------------------------------------------- bad files
def _check(e, *parts):
    msg = str(e.value)
    for p in parts:
        assert p in msg, (p, msg)


def test_wrong_version(tmp_path):
    p = _rewrite(GENROU_RAW, tmp_path / "v26.raw", lambda ls: [ls[0].replace(" 33,", " 26,")] + ls[1:])
    with pytest.raises(DataError) as e:
        read_raw(p)
    _check(e, "v26.raw line 1", "REV", "29 to 35")


def test_truncated_raw_record(tmp_path):
    lines = TVC_RAW.read_text().splitlines()
    k = lines.index(next(s for s in lines if "STEPUP" in s))
    p = _rewrite(TVC_RAW, tmp_path / "cut.raw", lambda ls: ls[:k + 2])    # 2 of its 4 lines
    with pytest.raises(DataError) as e:
        read_raw(p)
    _check(e, f"cut.raw line {k + 1}", "transformer record", "ends inside", "'WINDV1'", "2 of its 4 lines")
    assert e.value.field == "WINDV1"        # the first missing field (line 3 of the record)
    p = _rewrite(TVC_RAW, tmp_path / "cut2.raw", lambda ls: ls[:k])       # ends in a section
    with pytest.raises(DataError) as e:
        read_raw(p)
    _check(e, "cut2.raw", "ends inside the transformer section")


def test_truncated_dyr_record(tmp_path):
    d = tmp_path / "cut.dyr"
    d.write_text((DATA / "ThreeBus_GENROU.dyr").read_text().rsplit("/", 1)[0])
    with pytest.raises(DataError) as e:
        read_dyr(d)
    _check(e, "cut.dyr line 2", "GENROU", "not ended by '/'")


def test_wrong_field_count(tmp_path):
    d = tmp_path / "short.dyr"
    d.write_text("101 'GENCLS' 1 0 0 /\n102 'GENROU' 1 8.0 0.03 0.4 0.05 6.175 0.05 1.8 1.7 0.3\n"
                 " 0.55 0.25 0.2 0.1 /\n")
    with pytest.raises(DataError) as e:
        from_psse(GENROU_RAW, d)
    _check(e, "short.dyr line 2", "GENROU at bus 102 id '1'", "'S12'", "13 values", "takes 14")
    d.write_text("101 'GENCLS' 1 0 0 /\n102 'SEXS' 1 0.4 5 20 1 -50 50 7 /\n")
    with pytest.raises(DataError) as e:
        from_psse(GENROU_RAW, d)
    _check(e, "line 2", "SEXS", "value 7", "takes 6")


def test_non_numeric_fields(tmp_path):
    d = tmp_path / "nan.dyr"
    d.write_text("101 'GENCLS' 1 0 0 /\n102 'GENROU' 1 8.0 0.03 0.4 0.05 6.175 0.05 1.8 1.7 0.3\n"
                 " 0.55 0.25 0.2 x0.1 0.8 /\n")
    with pytest.raises(DataError) as e:
        read_dyr(d)
    _check(e, "nan.dyr line 3", "GENROU at bus 102", "value 13", "x0.1")
    p = _rewrite(GENROU_RAW, tmp_path / "nan.raw",
                 lambda ls: [s.replace("1.00000E-2, 1.20000E-1", "1.00000E-2, 1.2O000E-1", 1) for s in ls])
    with pytest.raises(DataError) as e:
        read_raw(p)
    _check(e, "nan.raw line 14", "non-transformer branch record", "'X'", "1.2O000E-1")


def test_unknown_model_and_missing_generator(tmp_path):
    d = tmp_path / "unk.dyr"
    d.write_text("101 'GENCLS' 1 0 0 /\n102 'NOSUCH' 1 1 2 /\n")
    with pytest.raises(DataError) as e:
        from_psse(GENROU_RAW, d)
    _check(e, "NOSUCH at bus 102 id '1' (unk.dyr line 2)")
    d.write_text("101 'GENCLS' 1 0 0 /\n103 'GENCLS' 1 3 0 /\n")
    with pytest.raises(DataError) as e:
        from_psse(GENROU_RAW, d)
    _check(e, "unk.dyr line 2", "no generator at bus 103")


def test_in_service_dc_and_facts_refused_in_one_message(tmp_path):
    def add(lines):
        out = []
        for s in lines:
            out.append(s)
            if "Begin FACTS device data" in s:
                out.append(" 'FACTS 1',   103,     0,1,     0.000,     0.000,1.00000,  9999.000,  9999.000,"
                           "0.90000,1.10000,  9999.000, 0.00000E+0,     0.000,     0.000,  9999.000,   1, 100.0,'1 '")
        return out
    p = _rewrite(GENROU_RAW, tmp_path / "facts.raw", add)
    with pytest.raises(DataError) as e:
        from_psse(p)
    _check(e, "facts.raw", "facts 'FACTS 1' (bus 103) (line 28)", "status to 0")


# --------------------------------------------------------------------------- ANDES beside
@pytest.mark.andes
def test_andes_route_differs_where_issue_26_says():
    """The ANDES route makes the H = 0 GENCLS a machine (M from its defaults); ours an infinite
    bus. Both read the same network: same power flow."""
    andes = pytest.importorskip("andes")
    import logging

    from weakgrid.sim.io.andes import from_andes

    logging.getLogger("andes").setLevel(logging.ERROR)
    ss = andes.load(str(GENROU_RAW), addfile=str(DATA / "ThreeBus_GENROU.dyr"), setup=False,
                    no_output=True, default_config=True)
    sa, _ = from_andes(ss)
    sp, _ = from_psse(GENROU_RAW, DATA / "ThreeBus_GENROU.dyr")
    assert "GENCLS" in sa.components and "GENCLS" not in sp.components
    Va = sa.network.solve_power_flow().V
    Vp = sp.network.solve_power_flow().V
    np.testing.assert_allclose(np.abs(Va), np.abs(Vp), atol=1e-8)


def test_gencls_h0_behind_a_source_impedance_keeps_it(tmp_path):
    """H = 0 with ZSORCE = 0.25 pu (not negligible): infinite inertia, constant voltage behind
    ZSORCE, as PSS/E; not an ideal source at the terminal."""
    d = tmp_path / "h0.dyr"
    d.write_text("101 'GENCLS' 1 0 0 /\n102 'GENCLS' 1 0.0 0.0 /\n")
    system, _ = from_psse(GENROU_RAW, d)
    g = system.components["GENCLS"]
    assert g.names == ["GENCLS_102_1"] and g._values[0]["M"] >= 1e9
    assert g._values[0]["xd1"] == pytest.approx(0.25)
    assert system.components["InfiniteBus"].names == ["GENCLS_101_1"]


@pytest.mark.andes
@pytest.mark.parametrize("case", ["ieee14/ieee14.raw", "npcc/npcc.raw", "wecc/wecc.raw", "wscc9/wscc9.raw"])
def test_power_flow_reproduces_andes_shipped_solved_raws(case):
    """PSS/E cases shipped with ANDES (read from its installed package, not vendored): 14 to 179
    buses, up to 60 transformers, switched shunts, series capacitors."""
    andes = pytest.importorskip("andes")
    raw, net, _ = _net(andes.get_case(case))
    assert _raw_mismatch(raw, net) < 1e-3
    pf = net.solve_power_flow()
    k, Vr = _raw_voltages(raw, net)
    assert np.max(np.abs(np.abs(pf.V[k]) - np.abs(Vr))) < 5e-5
    assert np.max(np.abs(np.degrees(np.angle(pf.V[k] / Vr)))) < 1e-2


def test_load_parts(tmp_path):
    """P part -> bus load (constant impedance in time), I part -> constant current (ZIP share at
    the solved voltage), Y part -> shunt; the power flow still reproduces the solved case when
    the same 250 MW + 30 Mvar are split into the three parts at the solved voltage VM."""
    raw0 = read_raw(GENROU_RAW)
    vm = [b for b in raw0.buses if b["i"] == 103][0]["vm"]
    # 250 = 100 (P) + IP*vm (I) + YP*vm^2 (Y);  30 = 10 + IQ*vm + (-YQ)*vm^2
    ip, yp, iq, yq = 100 / vm, 50 / vm ** 2, 10 / vm, -10 / vm ** 2
    line = (f"   103,'1 ',1,   1,   1,   100.000,    10.000,  {ip:.9f},  {iq:.9f},  {yp:.9f},"
            f"  {yq:.9f},   1,1,0")
    p = _rewrite(GENROU_RAW, tmp_path / "zip.raw",
                 lambda ls: [line if s.startswith("   103,'1 ',1") else s for s in ls])
    raw, net, _ = _net(p)
    k, Vr = _raw_voltages(raw, net)
    pf = net.solve_power_flow()
    assert np.max(np.abs(pf.V[k] - Vr)) < 1e-4
    i = net.index_of(103)
    assert net.bus[i, 2] == pytest.approx(100 + ip * vm) and net.bus[i, 4] == pytest.approx(yp)
    assert net.bus[i, 5] == pytest.approx(yq)
    system, _ = from_psse(p, DATA / "ThreeBus_GENROU.dyr")
    z = system.components["ZIP"]
    v = z._values[0]
    assert z.names == ["ZIP_103"]
    assert v["kpi"] == pytest.approx(100 * (ip * vm) / (100 + ip * vm)) and v["kpp"] == 0.0
    assert v["kqi"] == pytest.approx(100 * (iq * vm) / (10 + iq * vm))
    system.setup()
    F, _ = system.residual(0.0, system.z0)
    assert np.max(np.abs(F)) < 1e-8          # the initial point is an equilibrium
    # the ZIP's current part: at 0.9 of the initial voltage the I share scales by 0.9, Z by 0.81
    zc = system.components["ZIP"]
    P = zc.cp[0] + zc.cp[1] * 0.9 + zc.cp[2] * 0.81
    assert P[0] * net.Sb == pytest.approx(ip * vm * 0.9 + 100 * 0.81)


def _write_version(path: Path, v: int, comments: bool = True):
    """The GENROU three-bus case, plus a fixed shunt, a switched shunt (BINIT) and a multi-section
    line grouping, written in the record layouts of PSS/E version ``v`` (29-35)."""
    from weakgrid.sim.io.psse.raw import section_order

    raw = read_raw(GENROU_RAW)
    rec = {k: [] for k in section_order(v)}
    for b in raw.buses:
        gl_bl = ", 3.0, 20.0" if (v <= 30 and b["i"] == 103) else (", 0.0, 0.0" if v <= 30 else "")
        tail = ", 1, 1, 1" if v > 30 else ", 1, 1"
        head = f"{b['i']},'{b['name']}', {b['baskv']}, {b['ide']}{gl_bl}{tail}"
        if v <= 30:
            rec["bus"].append(f"{head}, {b['vm']}, {b['va']}, 1")
        else:
            rec["bus"].append(f"{head}, {b['vm']}, {b['va']}" + (", 1.1, 0.9, 1.1, 0.9" if v >= 33 else ""))
    for d in raw.loads:
        extra = {29: "", 30: "", 31: ", 1", 32: ", 1", 33: ", 1, 0"}.get(v, ", 1, 0, 0.0, 0.0, 0")
        rec["load"].append(f"{d['i']},'{d['id']}', 1, 1, 1, {d['pl']}, {d['ql']}, 0, 0, 0, 0, 1{extra}")
    if v > 30:
        rec["fixed shunt"].append("103,'1 ', 1, 3.0, 20.0")
    for g in raw.generators:
        nreg = ", 0" if v >= 34 else ""
        baslod = ", 0" if v >= 34 else ""
        rec["generator"].append(
            f"{g['i']},'{g['id']}', {g['pg']}, {g['qg']}, {g['qt']}, {g['qb']}, {g['vs']}, 0{nreg}, "
            f"{g['mbase']}, {g['zr']}, {g['zx']}, 0, 0, 1, 1, 100.0, {g['pt']}, {g['pb']}{baslod}, 1, 1.0")
    for br in raw.branches:
        if v >= 34:
            rates = "'LINE', " + ", ".join(["250.0"] * 12)
        else:
            rates = "250.0, 250.0, 250.0"
        met = ", 1" if v >= 31 else ""
        rec["branch"].append(f"{br['i']}, {br['j']},'{br['ckt']}', {br['r']}, {br['x']}, {br['b']}, {rates}, "
                             f"0, 0, 0, 0, 1{met}, 0.0, 1, 1.0")
    rec["multi-section line"].append("101, 102, '&1', 1, 103")
    sw = {29: "103, 0, 1.1, 0.9, 0, 100.0, '        ', 15.0, 1, 15.0",
          30: "103, 0, 1.1, 0.9, 0, 100.0, '        ', 15.0, 1, 15.0",
          34: "103, 0, 0, 1, 1.1, 0.9, 0, 0, 100.0, '        ', 15.0, 1, 1, 15.0",
          35: "103, '1 ', 0, 0, 1, 1.1, 0.9, 0, 0, 100.0, '        ', 15.0, 1, 1, 15.0"}
    rec["switched shunt"].append(sw.get(v, "103, 0, 0, 1, 1.1, 0.9, 0, 100.0, '        ', 15.0, 1, 15.0"))
    L = [f"0, 100.00, {v}, 0, 0, 60.00 / written by the test", "title 1", "title 2"]
    if v >= 34:
        L += ["@! system-wide data", "GENERAL, THRSHZ=0.0001", "0 / END OF SYSTEM-WIDE DATA, BEGIN BUS DATA"]
    order = section_order(v)
    for k, sec in enumerate(order):
        L += rec[sec]
        nxt = order[k + 1].upper() if k + 1 < len(order) else ""
        L.append(f"0 / END OF {sec.upper()} DATA" + (f", BEGIN {nxt} DATA" if nxt else "") if comments else "0")
    L.append("Q")
    path.write_text("\n".join(L) + "\n")
    return path


@pytest.mark.parametrize("v", range(29, 36))
@pytest.mark.parametrize("comments", [True, False], ids=["comments", "bare-0"])
def test_every_version_layout_reads_the_same_case(tmp_path, v, comments):
    """One case written in each version's layout reads to the same network (sections found by
    their comments, or by the version's order without them)."""
    ref_raw, ref, _ = _net(_write_version(tmp_path / "ref33.raw", 33))
    raw, net, maps = _net(_write_version(tmp_path / f"v{v}.raw", v, comments))
    assert raw.version == v
    np.testing.assert_allclose(net.bus[:, :10], ref.bus[:, :10])   # GS, BS: fixed + switched shunt
    i = net.index_of(103)
    assert net.bus[i, 4] == pytest.approx(3.0) and net.bus[i, 5] == pytest.approx(35.0)
    np.testing.assert_allclose(net.gen[:, :10], ref.gen[:, :10])
    np.testing.assert_allclose(net.branch, ref.branch)
    assert any("multi-section" in n for n in maps.notes)


def test_model_parameter_errors_name_the_record(tmp_path):
    d = tmp_path / "bad.dyr"
    d.write_text("101 'GENCLS' 1 0 0 /\n102 'GENROU' 1 8.0 0.03 0.4 0.05 6.175 0.05 1.8 1.7 0.3\n"
                 " 0.55 0.25 0.2 0.1 0.8 /\n102 'SEXS' 1 0.4 -5 20 1 -50 50 /\n")
    with pytest.raises(DataError) as e:
        from_psse(GENROU_RAW, d)
    _check(e, "bad.dyr line 4, SEXS at bus 102 id '1'", "'TB'", "-5")
    d.write_text("101 'GENCLS' 1 0 0 /\n102 'GENCLS' 1 3 0 /\n102 'SEXS' 1 0.4 5 20 1 -50 50 /\n"
                 "102 'SEXS' 1 0.4 5 20 1 -50 50 /\n")
    with pytest.raises(DataError) as e:
        from_psse(GENROU_RAW, d)
    _check(e, "bad.dyr line 4", "already has a exciter")


def test_240_bus_wecc_dyr_lists_every_record_weakgrid_lacks():
    """The 240-bus WECC case (448 records): the records of models this library has no PSS/E
    record layout for are all listed, none dropped (GENROU, SEXS, GAST, TGOV1, HYGOV, IEEEST read)."""
    recs = read_dyr(DATA / "240busWECC_2018_PSS.dyr")
    reg = _registry()
    lacking = [r for r in recs if getattr(reg.get(r.model), "psse_record", None) is None]
    if not lacking:
        system, _ = from_psse(DATA / "raw" / "240busWECC_2018_PSS32_fixed_shunts.raw",
                              DATA / "240busWECC_2018_PSS.dyr")
        skipped = sum("skipped" in n for n in system.import_notes)
        assert len(system.psse_device) + skipped >= len(recs) - sum(r.model == "GENCLS" for r in recs)
        return
    with pytest.raises(DataError) as e:
        from_psse(DATA / "raw" / "240busWECC_2018_PSS32_fixed_shunts.raw", DATA / "240busWECC_2018_PSS.dyr")
    msg = str(e.value)
    assert f"({len(lacking)})" in msg
    for r in lacking:
        assert f"{r.model} at bus {r.bus} id '{r.id}' ({r.file} line {r.line})" in msg


def test_swing_bus_without_generator_refused(tmp_path):
    p = _rewrite(GENROU_RAW, tmp_path / "noswing.raw",
                 lambda ls: [s.replace("1.00000,1,  100.0,   318.000", "1.00000,0,  100.0,   318.000", 1)
                             if s.startswith("   101,'1 '") else s for s in ls])
    with pytest.raises(DataError) as e:
        from_psse(p)
    _check(e, "noswing.raw, bus 101", "IDE", "no in-service generator")


def test_isolated_bus_dropped_with_its_devices(tmp_path):
    def add(lines):
        out = []
        for s in lines:
            if s.startswith(" 0 /End of Bus data"):
                out.append("   104,'BUS 4', 138.0000,4,   1,   1,   1,1.00000,   0.0000,1.1,0.9,1.1,0.9")
            if s.startswith(" 0 /End of Load data"):
                out.append("   104,'1 ',1,   1,   1,   10.000,    3.000,     0.000,     0.000,     0.000,     0.000,   1,1,0")
            if s.startswith(" 0 /End of Branch data"):
                out.append("   103,   104,'1 ', 1.0E-2, 1.2E-1,   0.00000,  250.00,  250.00,  250.00,  0.0,  0.0,"
                           "  0.0,  0.0,1,1,   0.00,   1,1.0000")
            out.append(s)
        return out
    p = _rewrite(GENROU_RAW, tmp_path / "iso.raw", add)
    system, _ = from_psse(p, DATA / "ThreeBus_GENROU.dyr")
    assert 104 not in system.network.bus_ids and system.network.nl == 3
    assert any("IDE = 4" in n for n in system.import_notes)
    assert any("load at bus 104" in n and "isolated" in n for n in system.import_notes)
    assert any("branch 103-104" in n and "isolated" in n for n in system.import_notes)


def test_system_wide_data_end_within_the_title_lines(tmp_path):
    """A v35 file whose second line already ends the (empty) system-wide data section: the bus
    data follow at once (one title line)."""
    p = _v35_from_v33_genrou(tmp_path / "full.raw")
    lines = p.read_text().splitlines()
    short = [lines[0], lines[1], "0 / END OF SYSTEM-WIDE DATA, BEGIN BUS DATA"] + lines[6:]
    q = tmp_path / "short.raw"
    q.write_text("\n".join(short) + "\n")
    raw = read_raw(q)
    assert raw.title == ["title 1"] and len(raw.buses) == 3 and len(raw.branches) == 3


def test_the_readme_lists_every_model_with_a_psse_record():
    """The sim README's list of models the .dyr reader reads is the registry's, not a copy."""
    text = (Path(__file__).resolve().parents[2] / "src" / "weakgrid" / "sim" / "README.md").read_text()
    part = text[text.index("Models with a PSS/E record"):text.index("Without one")]
    listed = set(re.findall(r"\b[A-Z][A-Z0-9]{2,}\b", part)) - {"PSS", "PAG"}
    have = {n for n, c in _registry().items() if getattr(c, "psse_record", None)}
    assert listed == have


def test_units_sharing_a_bus_keep_their_own_solved_q():
    """Eight units on bus 102 of PSID's MultiGen case: PSS/E initializes each from its own solved
    QG (its CSV's VARS at t = 0, [Mvar / 100]), not from an equal share of the bus's Q."""
    mg = Path(__file__).resolve().parents[1] / "data" / "psid" / "MultiGen"
    system, _ = from_psse(mg / "FourBusMulti.raw", mg / "FourBus_multigen.dyr")
    system.setup()
    first = np.genfromtxt(mg / "gen_trip_results.csv", delimiter=",", max_rows=1)
    ids = ["1", "EG", "ND", "RG", "S", "SG", "SH", "SW", "WG"]   # the CSV's machine order
    pf = system.network.pf
    for k, gid in enumerate(ids):
        row = system.psse_gen_row[(101 if gid == "1" else 102, gid)]
        assert pf.Qg[row] == pytest.approx(first[3 + 5 * k], abs=1e-4), gid
        assert pf.Pg[row] == pytest.approx(first[2 + 5 * k], abs=1e-4), gid
    # an equal split (the default of a MATPOWER case) gives the condenser 'ND' (QG = 0) the
    # same Q as the others
    net = system.network
    net.gen_split = "equal"
    net.solve_power_flow()
    assert net.pf.Qg[system.psse_gen_row[(102, "ND")]] > 0.3


def test_basfrq_override_is_the_runs_base_frequency():
    """PSS/E's base frequency is a setting of the run (psspy.base_frequency): ``basfrq`` replaces
    the file's BASFRQ everywhere (network, machines), with a note; PSID's STAB1 .raw says 50 Hz."""
    folder = Path(__file__).resolve().parents[1] / "data" / "psid" / "STAB1"
    raw, dyr = folder / "OMIB_SSS.raw", folder / "OMIB_SSS.dyr"
    s50, _ = from_psse(raw, dyr)
    s60, _ = from_psse(raw, dyr, basfrq=60.0)
    assert s50.network.f_hz == 50.0 and s60.network.f_hz == 60.0
    fn = lambda s: s.components["GENROU"]._values[0]["fn"]   # noqa: E731
    assert fn(s50) == 50.0 and fn(s60) == 60.0
    assert any("60 Hz (basfrq), not the file's BASFRQ = 50 Hz" in n for n in s60.import_notes)
    assert not any("basfrq" in n for n in s50.import_notes)
    with pytest.raises(DataError) as e:
        from_psse(raw, dyr, basfrq=0.0)
    assert e.value.field == "basfrq"


def test_static_generators_sharing_a_bus_are_one_source(tmp_path):
    """Two generators without a machine record on one bus (ACTIVSg2000's bus 1090 has two):
    one ideal source holds the bus (a bus takes one voltage constraint) and carries both
    units' active power; both are noted. Before, setup refused the second PVSource ("bus
    already held") and ACTIVSg2000 could not be set up."""
    def split(lines):
        out = []
        for s in lines:
            if s.lstrip().startswith("102,'1 ',   100.000"):
                out.append(s.replace("102,'1 ',   100.000,    -3.247", "102,'1 ',    60.000,    -2.000"))
                out.append(s.replace("102,'1 ',   100.000,    -3.247", "102,'2 ',    40.000,    -1.247"))
            else:
                out.append(s)
        return out
    p = _rewrite(GENROU_RAW, tmp_path / "two.raw", split)
    system, _ = from_psse(p)
    src = system.components["PVSource"]
    assert src.names == ["PVSource_102_1"]
    assert sum("PVSource_102_1 with its bus's other units" in n for n in system.import_notes) == 1
    assert system.psse_machine[(102, "2")] == "PVSource_102_1"
    system.setup()                          # an equilibrium (checked by setup) at the .raw's point
    assert src.p0[0] * system.Sb == pytest.approx(100.0, abs=1e-6)
    from weakgrid.sim.integrate import Simulator

    res = Simulator(system, dt=0.01, record=["PVSource_102_1.P"]).run(0.5)
    assert res.ok
    assert np.allclose(res["PVSource_102_1.P"], 1.0, atol=1e-6)
