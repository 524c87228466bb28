"""PSS/E power-flow records -> the MATPOWER case weakgrid's :class:`~weakgrid.sim.network.Network` takes.

Buses keep their PSS/E numbers. Conversions (all to per unit on ``SBASE`` at the bus base voltages):

* **loads** (in service): the constant-power part ``PL + jQL`` and the constant-current part
  ``(IP + jIQ)·VM`` (at the solved voltage ``VM`` of the ``.raw``) become the bus load
  ``PD + jQD`` [MW, Mvar]. In the time domain the constant-power part becomes a constant
  impedance at the power-flow voltage (as PSS/E's ``CONL`` with 100 % admittance, which the
  PowerSimulationsDynamics.jl benchmarks apply, and as ANDES's ``PQ``); a constant-current part
  stays a constant current (a :class:`~weakgrid.sim.loads.ZIP` on the bus, added by
  :func:`~.build.from_psse`). The constant-admittance part ``YP + jYQ`` [MW, Mvar at 1 pu;
  ``YQ`` < 0 inductive] is a bus shunt ``GS += YP``, ``BS += YQ``.
* **fixed shunts**, **switched shunts** (at ``BINIT``, their solved value), **line shunts**
  ``GI + jBI``, ``GJ + jBJ`` of branches and transformer **magnetizing** admittances (at the
  winding-1 bus): bus shunts ``GS``, ``BS`` [MW, Mvar at 1 pu]. A shunt stays on its bus when
  its branch is switched (noted when non-zero).
* **generators**: rows of the gen table (``MBASE``, ``PT``/``PB``, ``QT``/``QB``); the voltage set
  point is the *solved* voltage ``VM`` of the bus (equal to ``VS`` unless the machine regulated a
  remote bus or sat at a reactive limit in the solved case: noted). Generators sharing a bus keep
  their own solved ``QG`` (and ``PG`` at the swing bus) of the file, as PSS/E initializes its
  machines (``gen_split = "case"`` of the network; only the difference between the re-solved
  total and their sum is shared equally), not an equal share.
* **two-winding transformers**: PSS/E's model ``bus I — t1:1 — Z — 1:t2 — bus J`` (``t1``, ``t2``
  the winding ratios in pu of the bus base voltages from ``CW``; ``Z`` on ``SBASE`` from ``CZ``) is
  MATPOWER's branch with ``TAP = t1/t2``, ``SHIFT = ANG1`` and series impedance ``Z·t2²``.
* **three-winding transformers**: a star bus (numbered above the case's largest bus number, at
  ``VMSTAR``, ``ANSTAR``) and one branch per winding ``bus k — tk:1 — Zk — star`` with the star
  impedances ``Z1 = (Z12 + Z31 - Z23)/2`` (and cyclic); ``STAT`` 2, 3, 4 open winding 2, 3, 1.
* **system switching devices** (v34+): branches of reactance ``X``.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import DataError
from .raw import RawCase


#: PSS/E's default zero-impedance line threshold THRSHZ [pu]: smaller star impedances become ties
ZERO_Z = 1e-4


@dataclass
class CaseMaps:
    """PSS/E identifiers of the case's rows.

    Attributes
    ----------
    bus_name : dict
        PSS/E bus number -> bus name.
    kv : dict
        PSS/E bus number -> base voltage [kV].
    gen_row : dict
        ``(bus, id)`` -> row of the gen table (in-service and out-of-service generators).
    gen : dict
        ``(bus, id)`` -> the generator record (dict of :class:`~.raw.RawCase`).
    branch_row : dict
        ``(i, j, ckt)`` -> branch row of a non-transformer branch or switching device.
    transformer_rows : dict
        ``(i, j, k, ckt)`` -> branch rows of a transformer (one, or three for a star).
    star_bus : dict
        ``(i, j, k, ckt)`` -> bus number of a three-winding transformer's star bus.
    load_parts : dict
        PSS/E bus number -> ``[PL, QL, IP·VM, IQ·VM]`` [MW, Mvar] of its in-service loads.
    notes : list of str
    """

    bus_name: dict = field(default_factory=dict)
    kv: dict = field(default_factory=dict)
    gen_row: dict = field(default_factory=dict)
    gen: dict = field(default_factory=dict)
    branch_row: dict = field(default_factory=dict)
    transformer_rows: dict = field(default_factory=dict)
    star_bus: dict = field(default_factory=dict)
    load_parts: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)


def _ratio(cw, windv, nomv, vb):
    """Winding ratio [pu of the bus base voltage] from PSS/E's ``CW`` code."""
    if cw == 1:
        return windv
    if cw == 2:
        return windv / vb
    return windv * (nomv if nomv > 0 else vb) / vb


def _z_sys(cz, r, x, sb, sbase, where, fld):
    """Winding impedance [pu on SBASE] from PSS/E's ``CZ`` code."""
    if cz == 1:
        return complex(r, x)
    if not sb > 0:
        raise DataError(where, f"SBASE{fld}", sb, f"with CZ = {cz} the winding base MVA must be > 0")
    if cz == 2:
        return complex(r, x) * sbase / sb
    rw = r / 1e6 / sb                # load loss [W] -> pu on the winding base
    if abs(x) < rw:
        raise DataError(where, f"X{fld}", x, f"with CZ = 3, |Z| = X{fld} must be >= the resistance "
                        f"from the load loss ({rw:.4g} pu)")
    xw = np.sqrt(x * x - rw * rw) * (1 if x >= 0 else -1)
    return complex(rw, xw) * sbase / sb


def build_case(raw: RawCase):
    """MATPOWER case dict and identifier maps of a :class:`~.raw.RawCase`.

    Returns
    -------
    case : dict
        ``baseMVA``, ``bus``, ``gen``, ``branch`` and the rows ``series_capacitors`` (X < 0) and
        ``negative_resistance`` (R < 0) accepted on purpose.
    maps : CaseMaps
    """
    fname = raw.path.rsplit("/", 1)[-1]
    Sb = raw.sbase
    maps = CaseMaps()
    notes = maps.notes

    def where(rec, what):
        return f"{fname} line {rec['line']}, {what}"

    buses = {}
    for b in raw.buses:
        if b["i"] in buses:
            raise DataError(where(b, "bus record"), "I", b["i"], "bus numbers must be unique")
        buses[b["i"]] = b
    live = {i for i, b in buses.items() if b["ide"] != 4}
    dead = sorted(set(buses) - live)
    if dead:
        notes.append(f"buses {dead}: isolated (IDE = 4), dropped with everything on them")
    for i, b in buses.items():
        if i in live and not b["baskv"] > 0:
            raise DataError(where(b, f"bus record {i}"), "BASKV", b["baskv"], "give the bus base voltage in kV (> 0)")
    order = [i for i in buses if i in live]
    pos = {i: k for k, i in enumerate(order)}
    nb = len(order)
    next_bus = (max(buses) if buses else 0) + 1
    star_rows = []      # extra bus rows (star buses)
    B = np.zeros((nb, 13))
    for k, i in enumerate(order):
        b = buses[i]
        B[k, :] = [i, {1: 1, 2: 2, 3: 3}.get(b["ide"], 1), 0, 0, b["gl"], b["bl"], 1, b["vm"], b["va"],
                   b["baskv"], 1, 1.1, 0.9]
        maps.bus_name[i] = b["name"]
        maps.kv[i] = b["baskv"]
    shunt = {}          # bus -> complex MW + j Mvar at 1 pu, added at the end

    def add_shunt(i, s):
        shunt[i] = shunt.get(i, 0j) + s

    def on_dead(rec, what, *bs):
        missing = [x for x in bs if x not in buses]
        if missing:
            raise DataError(where(rec, what), "bus", missing[0],
                            f"no bus {missing[0]} in the bus data: correct the bus number")
        if any(x not in live for x in bs):
            notes.append(f"{what} ({where(rec, 'record')}): on an isolated bus, dropped")
            return True
        return False

    n_i = 0
    for ld in raw.loads:
        what = f"load at bus {ld['i']} id '{ld['id']}'"
        if on_dead(ld, what, ld["i"]) or ld["status"] == 0:
            continue
        k = pos[ld["i"]]
        vm = B[k, 7]
        B[k, 2] += ld["pl"] + ld["ip"] * vm
        B[k, 3] += ld["ql"] + ld["iq"] * vm
        add_shunt(ld["i"], complex(ld["yp"], ld["yq"]))
        parts = maps.load_parts.setdefault(ld["i"], [0.0, 0.0, 0.0, 0.0])
        for j, v in enumerate((ld["pl"], ld["ql"], ld["ip"] * vm, ld["iq"] * vm)):
            parts[j] += v
        n_i += bool(ld["ip"] or ld["iq"])
    if n_i:
        notes.append(f"{n_i} loads with a constant-current part (IP, IQ): in the power flow at the "
                     "solved voltage VM of the .raw; in the time domain constant current (ZIP)")
    for sh in raw.fixed_shunts:
        if not on_dead(sh, f"fixed shunt at bus {sh['i']} id '{sh['id']}'", sh["i"]) and sh["status"]:
            add_shunt(sh["i"], complex(sh["gl"], sh["bl"]))
    n_sw = 0
    for sh in raw.switched_shunts:
        if not on_dead(sh, f"switched shunt at bus {sh['i']}", sh["i"]) and sh["stat"]:
            add_shunt(sh["i"], complex(0.0, sh["binit"]))
            n_sw += 1
    if n_sw:
        notes.append(f"{n_sw} switched shunts at their solved susceptance BINIT (no switching in time)")
    # generators
    G = []
    for g in raw.generators:
        key = (g["i"], g["id"])
        what = f"generator at bus {g['i']} id '{g['id']}'"
        if key in maps.gen:
            raise DataError(where(g, what), "ID", g["id"], "two generators at one bus need different ids")
        if on_dead(g, what, g["i"]):
            continue
        k = pos[g["i"]]
        if g["stat"] and B[k, 1] in (2, 3) and abs(g["vs"] - B[k, 7]) > 1e-4:
            notes.append(f"{what}: VS = {g['vs']:g} pu differs from the solved VM = {B[k, 7]:g} pu of its "
                         "bus (remote regulation or a reactive limit in the solved case); the power flow "
                         "holds the solved VM")
        if g["rt"] or g["xt"]:
            notes.append(f"{what}: the step-up transformer data RT, XT of the generator record are not "
                         "modelled (as in PSS/E's power flow); represent it as a transformer branch")
        if not g["mbase"] > 0:
            raise DataError(where(g, what), "MBASE", g["mbase"], "the machine base must be > 0 MVA")
        maps.gen_row[key] = len(G)
        maps.gen[key] = g
        G.append([g["i"], g["pg"], g["qg"], g["qt"], g["qb"], B[k, 7], g["mbase"],
                  1 if g["stat"] else 0, g["pt"], g["pb"]])
    L = []
    series_caps, neg_r = [], []

    def add_branch(rec, what, i, j, z, b, tap, shift, st):
        row = len(L)
        if z.real < 0:
            neg_r.append(row)
            notes.append(f"{what} ({where(rec, 'record')}): negative resistance R = {z.real:.6g} pu "
                         "accepted (network equivalents have them)")
        if z.imag < 0:
            series_caps.append(row)
            notes.append(f"{what} ({where(rec, 'record')}): negative reactance X = {z.imag:.6g} pu "
                         "taken as a series capacitor")
        L.append([i, j, z.real, z.imag, b, 0, 0, 0, tap, shift, 1 if st else 0, -360, 360])
        return row

    n_ls = 0
    for br in raw.branches:
        what = f"branch {br['i']}-{br['j']} ckt '{br['ckt']}'"
        if on_dead(br, what, br["i"], br["j"]):
            continue
        maps.branch_row[(br["i"], br["j"], br["ckt"])] = add_branch(
            br, what, br["i"], br["j"], complex(br["r"], br["x"]), br["b"], 0.0, 0.0, br["st"])
        if br["st"] and any(br[k] for k in ("gi", "bi", "gj", "bj")):
            add_shunt(br["i"], complex(br["gi"], br["bi"]) * Sb)
            add_shunt(br["j"], complex(br["gj"], br["bj"]) * Sb)
            n_ls += 1
    if n_ls:
        notes.append(f"{n_ls} branches with line shunts (GI, BI, GJ, BJ): bus shunts at their ends")
    for sd in raw.switching_devices:
        what = f"switching device {sd['i']}-{sd['j']} ckt '{sd['ckt']}'"
        if on_dead(sd, what, sd["i"], sd["j"]):
            continue
        x = sd["x"] if sd["x"] != 0 else 1e-4
        maps.branch_row[(sd["i"], sd["j"], sd["ckt"])] = add_branch(
            sd, what, sd["i"], sd["j"], complex(0.0, x), 0.0, 0.0, 0.0, sd["stat"])
    if raw.multi_section:
        notes.append(f"{len(raw.multi_section)} multi-section line groupings: their sections are "
                     "ordinary branches (read as such)")
    n_mag = 0
    tabs = set(raw.impedance_tables)
    for t in raw.transformers:
        three = t["k"] != 0
        key = (t["i"], t["j"], t["k"], t["ckt"])
        ends = (t["i"], t["j"], t["k"]) if three else (t["i"], t["j"])
        what = (f"transformer {'-'.join(map(str, ends))} ckt '{t['ckt']}'"
                + (f" '{t['name']}'" if t["name"] else ""))
        if on_dead(t, what, *ends):
            continue
        wh = where(t, what)
        vb = [buses[x]["baskv"] for x in ends]
        ratio = [_ratio(t["cw"], t[f"windv{w + 1}"], t[f"nomv{w + 1}"], vb[w]) for w in range(len(ends))]
        for w in range(len(ends)):
            if not ratio[w] > 0:
                raise DataError(wh, f"WINDV{w + 1}", t[f"windv{w + 1}"], "the winding ratio must be > 0")
            if t.get(f"tab{w + 1}") and int(t[f"tab{w + 1}"]) in tabs:
                notes.append(f"{what}: impedance correction table {int(t[f'tab{w + 1}'])} not applied "
                             "(the impedance is taken as written)")
        if t["cz"] != 1 and any(t[f"nomv{w + 1}"] > 0 and abs(t[f"nomv{w + 1}"] - vb[w]) > 1e-6 * vb[w]
                                for w in range(len(ends))):
            notes.append(f"{what}: winding nominal voltage NOMV differs from the bus base voltage; "
                         "its impedance is taken on the bus base voltage")
        z12 = _z_sys(t["cz"], t["r12"], t["x12"], t["sb12"], Sb, wh, "1-2")
        if t["cm"] == 1:
            ymag = complex(t["mag1"], t["mag2"])
        else:
            g = t["mag1"] / 1e6 / Sb
            if not t["sb12"] > 0:
                raise DataError(wh, "SBASE1-2", t["sb12"], "with CM = 2 the winding base MVA must be > 0")
            y = t["mag2"] * t["sb12"] / Sb
            ymag = complex(g, -np.sqrt(max(y * y - g * g, 0.0)))
        st = t["stat"]
        if ymag != 0 and st:
            add_shunt(t["i"], ymag * Sb)
            n_mag += 1
        if not three:
            t2 = ratio[1]
            maps.transformer_rows[key] = [add_branch(t, what, t["i"], t["j"], z12 * t2 * t2, 0.0,
                                                     ratio[0] / t2, t["ang1"], st != 0)]
            continue
        z23 = _z_sys(t["cz"], t["r23"], t["x23"], t["sb23"], Sb, wh, "2-3")
        z31 = _z_sys(t["cz"], t["r31"], t["x31"], t["sb31"], Sb, wh, "3-1")
        zs = [(z12 + z31 - z23) / 2, (z12 + z23 - z31) / 2, (z23 + z31 - z12) / 2]
        star = next_bus
        next_bus += 1
        maps.star_bus[key] = star
        star_rows.append([star, 1, 0, 0, 0, 0, 1, t["vmstar"] or 1.0, t["anstar"], vb[0], 1, 1.1, 0.9])
        maps.bus_name[star] = f"star of {what}"
        maps.kv[star] = vb[0]
        on_w = [st == 1 or (st == 2 and w != 1) or (st == 3 and w != 2) or (st == 4 and w != 0)
                for w in range(3)]
        rows = []
        for w in range(3):
            z = zs[w]
            if abs(z) < ZERO_Z:      # PSS/E's zero-impedance threshold (THRSHZ): a bus tie
                notes.append(f"{what} winding {w + 1}: star impedance {z:.3g} pu below {ZERO_Z:g} "
                             f"pu, taken as a bus tie of reactance {ZERO_Z:g} pu")
                z = complex(0.0, ZERO_Z)
            rows.append(add_branch(t, f"{what} winding {w + 1}", ends[w], star, z, 0.0, ratio[w],
                                   t[f"ang{w + 1}"], on_w[w]))
        maps.transformer_rows[key] = rows
        notes.append(f"{what}: three-winding, star bus {star}")
    if n_mag:
        notes.append(f"{n_mag} transformers with magnetizing admittance: bus shunts at their winding-1 "
                     "bus (stay connected when the transformer is switched)")
    if star_rows:
        B = np.vstack([B, np.array(star_rows)])
        pos.update({int(r[0]): nb + k for k, r in enumerate(star_rows)})
    for i, s in shunt.items():
        B[pos[i], 4] += s.real
        B[pos[i], 5] += s.imag
    if not np.any(B[:, 1] == 3):
        raise DataError(f"{fname}", "IDE", "no 3", "the case has no swing bus (IDE = 3)")
    case = {"baseMVA": Sb, "bus": B, "gen": np.array(G, dtype=float).reshape(-1, 10),
            "branch": np.array(L, dtype=float).reshape(-1, 13),
            "series_capacitors": series_caps, "negative_resistance": neg_r,
            # generators sharing a bus keep their own solved PG (swing bus) and QG: PSS/E's split
            "gen_split": "case"}
    return case, maps
