"""PSS/E's own results as the peer: PSID's PSS/E benchmark cases, run in weakgrid and in ANDES.

PowerSimulationsDynamics.jl (PSID, BSD-3) ships PSS/E ``.raw`` + ``.dyr`` cases with PSS/E's
simulation results (``test/benchmarks/psse``); they are vendored unedited under
``tests/data/psid`` and described, one entry per case and ``.dyr`` variant, in
``tests/data/psid/cases.toml`` (event in PSS/E terms, compared quantities, CSV columns and units,
PSID's tolerance and norm, PSID's load conversion, the PSID test file and lines).

This module turns an entry into a run and a comparison:

* :func:`build_weakgrid` reads the files exactly as shipped with weakgrid's PSS/E reader
  (:func:`weakgrid.sim.io.psse.from_psse`), converts the loads as PSID does, and maps the
  entry's event onto :mod:`weakgrid.sim.events`;
* :func:`run_weakgrid` simulates to the entry's ``tend``;
* :func:`compare_case` compares every quantity with PSS/E's CSV: PSID's own norm and
  tolerance, and the largest difference as a share of PSS/E's swing of the quantity
  (``max - min`` over the run);
* :func:`run_andes` runs the same files in ANDES (``andes.load(raw, addfile=dyr)``, ANDES's own
  time-domain simulation, the same event) for the benchmark table (ANDES is imported, never
  copied).

Samples: PSS/E's CSV repeats the time stamp of an event (before and after); as PSID
(``clean_extra_timestep!``) the first, pre-event sample is kept, and so for the simulators'
results. A simulator's trajectory is interpolated linearly onto PSS/E's sample times.
"""

from __future__ import annotations

import math
import re
import time
import tomllib
from pathlib import Path

import numpy as np

from ..errors import DataError
from ..events import Event, GeneratorTrip, LineTrip
from ..network import BR_B, BR_R, BR_X, F_BUS, PD, QD, T_BUS

#: folder of the vendored PSID cases in a source checkout (``tests/data/psid``); an installed
#: wheel has no tests folder, so callers there pass the ``cases.toml`` path to :func:`load_cases`
#: (each entry then remembers its folder as ``root``)
DATA = Path(__file__).resolve().parents[4] / "tests" / "data" / "psid"

#: default simulation step [s] (PSS/E's CSVs are sampled at 5 ms; 1/240 s is weakgrid's usual
#: half of 1/120 s); an entry may set ``dt``
DT = 1 / 240

#: a case passes when it is within PSID's tolerance and within this share of PSS/E's swing
SWING_SHARE = 0.05


# ------------------------------------------------------------------------------ the table
def load_cases(path=None) -> list[dict]:
    """The entries of ``cases.toml`` (list of dicts; ``run`` defaults to True, ``root`` is the
    folder of ``path``, against which the entry's files are read)."""
    path = Path(path) if path is not None else DATA / "cases.toml"
    if not path.is_file():
        raise FileNotFoundError(
            f"PSID case table {path} not found: pass the path of tests/data/psid/cases.toml of a "
            "weakgrid source checkout (an installed wheel carries no test data)")
    with open(path, "rb") as f:
        cases = tomllib.load(f)["case"]
    for c in cases:
        c.setdefault("run", True)
        c.setdefault("compare", [])
        c.setdefault("results_from", "PSS/E")   # whose simulation the CSV holds (PSID's DEGOV: PowerWorld)
        c.setdefault("root", str(path.parent))
    return cases


def case_by_id(case_id, path=None) -> dict:
    """The entry ``case_id`` of ``cases.toml`` (:func:`load_cases`); KeyError if there is none."""
    for c in load_cases(path):
        if c["id"] == case_id:
            return c
    raise KeyError(case_id)


def data_path(rel, root=None) -> str:
    """Path of the vendored PSID file ``rel`` (relative to ``root``, default ``tests/data/psid``)."""
    return str((Path(root) if root is not None else DATA) / rel)


def case_file(case, key, root=None) -> str:
    """Path of the entry's file ``case[key]`` (``root``, else the entry's own ``root``, else
    :data:`DATA`)."""
    return data_path(case[key], root if root is not None else case.get("root"))


def dedupe(t, *ys):
    """Keep the first sample of each repeated time stamp (PSID's ``clean_extra_timestep!``)."""
    t = np.asarray(t, dtype=float)
    keep = np.ones(len(t), dtype=bool)
    keep[1:] = np.diff(t) > 1e-9
    return (t[keep],) + tuple(np.asarray(y)[keep] for y in ys)


def read_psse_csv(case, root=None):
    """PSS/E's results of ``case``: ``(t, M)`` with repeated time stamps removed; ``M[:, j]`` is
    the CSV's 1-based column ``j + 1`` (column 1 is the time)."""
    M = np.genfromtxt(case_file(case, "csv", root), delimiter=",", skip_header=int(case.get("csv_header", 0)))
    t, M = dedupe(M[:, 0], M)
    return t, M


def psse_series(case, cmp, t, M, sbase=100.0):
    """PSS/E's values of compared quantity ``cmp`` in its tolerance unit (``cmp["tol_unit"]``)."""
    y = M[:, int(cmp["csv_column"]) - 1].astype(float)
    unit, tu = cmp["csv_unit"], cmp["tol_unit"]
    if unit == "pu deviation":
        y = y + 1.0
    elif unit in ("MW", "Mvar"):
        y = y / sbase
    if unit == "deg" and tu == "rad":
        y = np.radians(y)
    return y


# ------------------------------------------------------------------------------ naming
def _strip_id(i) -> str:
    return str(i).strip().strip("'\"").strip()


class Names:
    """Finds weakgrid's names of a case's elements (PSS/E bus numbers and ids).

    With :func:`weakgrid.sim.io.psse.from_psse` buses keep their PSS/E numbers and machines are
    named ``"<MODEL>_<bus>_<id>"`` (the contract of the reader). ``andes_ss`` (the ANDES system a
    system was imported from with :func:`weakgrid.sim.io.andes.from_andes`) maps the ANDES route's
    names instead (ANDES's bus idx are the PSS/E numbers; machines ``"<MODEL>_<ANDES idx>"``).
    """

    def __init__(self, system, andes_ss=None):
        self.sys = system
        self.ss = andes_ss

    def bus(self, bus) -> int:
        """weakgrid bus id of PSS/E bus ``bus``."""
        if self.ss is not None:
            return int(self.sys.andes_bus_id[bus])
        return int(bus)

    def machine(self, bus, gid) -> str:
        gid = _strip_id(gid)
        names = list(self.sys.machine_names)
        table = getattr(self.sys, "psse_machine", None)   # the reader's {(bus, id): name}
        if self.ss is None and table:
            hits = [n for (b, i), n in table.items() if int(b) == int(bus) and _strip_id(i) == gid]
        elif self.ss is None:
            pat = re.compile(rf"^[A-Za-z0-9]+_{int(bus)}_{re.escape(gid)}$")
            hits = [n for n in names if pat.match(n)]
        else:   # ANDES route: ANDES's names carry no PSS/E id; match by bus
            hits = []
            for (model, idx), n in self.sys.andes_device.items():
                mdl = self.ss.models.get(model)
                if n in names and int(mdl.bus.v[mdl.idx.v.index(idx)]) == int(bus):
                    hits.append(n)
        if len(hits) != 1:
            raise DataError(f"machine ({bus}, '{gid}')", "name", hits,
                            f"expected one machine of PSS/E bus {bus} id '{gid}' among {names}")
        return hits[0]

    def gen_row(self, bus, gid) -> int:
        """0-based gen-table row of PSS/E unit (bus, id) (weakgrid's PSS/E reader only)."""
        if self.ss is not None:
            raise Unsupported(f"unit ({bus}, '{gid}'): the ANDES route's names carry no PSS/E id")
        table = getattr(self.sys, "psse_gen_row", None)
        gid = _strip_id(gid)
        hits = [r for (b, i), r in (table or {}).items() if int(b) == int(bus) and _strip_id(i) == gid]
        if len(hits) != 1:
            raise DataError(f"unit ({bus}, '{gid}')", "gen row", hits,
                            f"expected one generator of PSS/E bus {bus} id '{gid}' in the reader's "
                            f"psse_gen_row {sorted(table or {})}")
        return int(hits[0])

    def component(self, kind, bus, gid):
        """(component, position) of the ``kind`` control ("exciter", ...) of machine (bus, id)."""
        m = self.machine(bus, gid)
        for c in self.sys.components.values():
            if c.kind == kind:
                for k, lk in enumerate(c.links):
                    if lk.get("machine") == m:
                        return c, k
        raise DataError(f"machine {m}", kind, None, f"the machine has no {kind}")

    def branch_rows(self, f, t, ckt):
        """0-based rows of the network branch table for PSS/E branch (f, t, ckt)."""
        net = self.sys.network
        fb, tb = self.bus(f), self.bus(t)
        rows = [k for k in range(net.nl)
                if {int(net.branch[k, F_BUS]), int(net.branch[k, T_BUS])} == {fb, tb}]
        ckt = _strip_id(ckt)
        table = getattr(self.sys, "psse_branch_row", None)   # the reader's {(i, j, ckt): row}
        if self.ss is None and table:
            hit = [int(r) for (i, j, c), r in table.items()
                   if {int(i), int(j)} == {int(f), int(t)} and _strip_id(c) == ckt]
            if len(hit) == 1:
                return hit
            raise DataError(f"branch {f}-{t} '{ckt}'", "ckt", ckt,
                            f"no such branch in the .raw; branches: {sorted(table)}")
        ids = _branch_ckts(self.sys)
        if ids is not None:
            hit = [k for k in rows if _strip_id(ids[k]) == ckt]
            if len(hit) == 1:
                return hit
        if len(rows) == 1:
            return rows
        if rows and all(np.allclose(net.branch[k, [BR_R, BR_X, BR_B]], net.branch[rows[0], [BR_R, BR_X, BR_B]])
                        for k in rows):
            # parallel circuits with identical data: tripping any one is the same network
            return rows[:1]
        raise DataError(f"branch {f}-{t} '{ckt}'", "ckt", ckt,
                        f"rows {rows} join these buses and the system does not say which is circuit '{ckt}'")


def _branch_ckts(system):
    """Circuit ids of the branch rows, if the reader recorded them (else None)."""
    for owner in (system, system.network):
        for attr in ("branch_ckt", "branch_ckts", "psse_branch_ckt"):
            v = getattr(owner, attr, None)
            if v is not None:
                return list(v)
        ids = getattr(owner, "psse_branches", None)   # list of (from, to, ckt) per row
        if ids is not None:
            return [i[2] for i in ids]
    return None


# ------------------------------------------------------------------------------ events
class ReferenceChange(Event):
    """Set the voltage reference of an exciter to ``value`` [pu] at ``t`` [s] (PSID's
    ``ControlReferenceChange(t, gen, :V_ref, value)``; PSS/E: a change of the exciter's VREF)."""

    def __init__(self, comp, k, t, value):
        self.comp, self.k, self.t, self.value = comp, int(k), float(t), float(value)

    def validate(self, system):
        Event.validate(self, system)
        if not hasattr(self.comp, "vref0"):
            raise DataError(repr(self), "vref0", None, f"{self.comp.type_name} has no voltage reference vref0")

    def apply(self, sim):
        self.comp.vref0 = np.array(self.comp.vref0, dtype=float)
        self.comp.vref0[self.k] = self.value

    def __repr__(self):
        return f"ReferenceChange({self.comp.type_name}[{self.k}], t={self.t}, vref={self.value})"


class Unsupported(Exception):
    """The case needs something weakgrid has not (a model, an event kind); ``str`` says what."""


def weakgrid_events(case, system, names):
    """weakgrid events of the entry's ``[case.event]``."""
    ev = case["event"]
    kind = ev["kind"]
    if kind == "branch trip":
        return [LineTrip(int(r), ev["t"]) for r in names.branch_rows(ev["from_bus"], ev["to_bus"], ev["ckt"])]
    if kind == "gen trip":
        return [GeneratorTrip(names.gen_row(ev["bus"], ev["id"]), ev["t"])]
    if kind == "source change" and ev.get("signal") == "vref":
        comp, k = names.component(ev["model"], ev["bus"], ev["id"])
        return [ReferenceChange(comp, k, ev["t"], ev["value"])]
    raise Unsupported(f"event kind '{kind}' ({ev.get('psid', '')}): weakgrid.sim.events has no such event")


# ------------------------------------------------------------------------------ loads
def convert_loads(system, kind):
    """Convert every load as PSID's ``transform_load_to_constant_*`` does (before setup).

    weakgrid's bus loads (``PD + jQD`` of the network) are constant impedances in the time domain;
    a :class:`~weakgrid.sim.loads.ZIP` replaces a share ``P0 + jQ0`` of its bus load with a
    polynomial. ``kind`` = ``"constant impedance"``, ``"constant power"`` or ``"constant
    current"``: ZIPs the reader made get those shares, and the rest of each bus load gets a ZIP
    with them too (none needed for constant impedance)."""
    shares = {"constant impedance": dict(kpp=0.0, kpi=0.0, kpz=100.0, kqp=0.0, kqi=0.0, kqz=100.0),
              "constant power": dict(kpp=100.0, kpi=0.0, kpz=0.0, kqp=100.0, kqi=0.0, kqz=0.0),
              "constant current": dict(kpp=0.0, kpi=100.0, kpz=0.0, kqp=0.0, kqi=100.0, kqz=0.0)}[kind]
    net = system.network
    Sb = net.Sb
    rest = {b: complex(net.bus[b, PD], net.bus[b, QD]) / Sb for b in range(net.nb)}
    zip_ = system.components.get("ZIP")
    if zip_ is not None:
        for i, lk in enumerate(zip_.links):
            zip_._values[i].update(shares)
            rest[int(lk["bus"])] -= complex(lk["P0"], lk["Q0"])
    if kind == "constant impedance":
        return
    zip_ = system._component("ZIP", "device")
    for b, s in rest.items():
        if abs(s) > 1e-12:
            zip_.add_zip(f"ZIP_psid_{net.bus_ids[b]}", b, s.real, s.imag, **shares)


# ------------------------------------------------------------------------------ weakgrid
def read_psse(case, root=None):
    """``from_psse(raw, dyr)`` of the entry's files, exactly as shipped: ``(system, events)``; an
    entry's ``basfrq`` [Hz] is the frequency PSS/E's results were computed at, where it differs
    from the file's BASFRQ (``from_psse(..., basfrq=)``, PSS/E's ``base_frequency`` setting)."""
    from ..io.psse import from_psse

    dyr = case_file(case, "dyr", root) if case.get("dyr") else None
    return from_psse(case_file(case, "raw", root), dyr, basfrq=case.get("basfrq"))


def build_weakgrid(case, root=None, route="psse"):
    """System and events of the entry. ``route="psse"``: weakgrid's PSS/E reader;
    ``route="andes"``: ANDES's parser then :func:`weakgrid.sim.io.andes.from_andes` (the
    route the reader replaces; for comparison only)."""
    if route == "psse":
        system, file_events = read_psse(case, root)
        names = Names(system)
    else:
        from ..io.andes import from_andes

        ss = _andes_load(case, root)
        system, file_events = from_andes(ss)
        names = Names(system, andes_ss=ss)
    convert_loads(system, case["loads"])
    events = list(file_events) + weakgrid_events(case, system, names)
    return system, events, names


def run_weakgrid(case, root=None, route="psse", dt=None, **kw):
    """Build and simulate the entry to ``tend``: dict with ``res``, ``system``, ``names``, ``wall``."""
    from ..integrate import Simulator

    system, events, names = build_weakgrid(case, root, route)
    system.setup()
    sim = Simulator(system, dt=dt or case.get("dt", DT), **kw)
    t0 = time.perf_counter()
    res = sim.run(case["tend"], events=events, on_failure="return")
    return {"res": res, "system": system, "names": names, "wall": time.perf_counter() - t0}


def _branch_flow(case, system, res, names, cmp):
    net = system.network
    k = names.branch_rows(cmp["from_bus"], cmp["to_bus"], cmp["ckt"])[0]
    ev = case["event"]
    if ev["kind"] == "branch trip" and {ev["from_bus"], ev["to_bus"]} == {cmp["from_bus"], cmp["to_bus"]}:
        raise Unsupported("the flow of the tripped branch itself is not computed by the harness")
    f, t, Yff, Yft, Ytf, Ytt = net.branch_admittances()
    bf, bt = net.bus_ids[f[k]], net.bus_ids[t[k]]
    Vf = res[f"bus{bf}.Vr"] + 1j * res[f"bus{bf}.Vi"]
    Vt = res[f"bus{bt}.Vr"] + 1j * res[f"bus{bt}.Vi"]
    at_from = int(net.branch[k, F_BUS]) == names.bus(cmp["from_bus"])
    if (cmp["end"] == "from") == at_from:
        S = Vf * np.conj(Yff[k] * Vf + Yft[k] * Vt)
    else:
        S = Vt * np.conj(Ytf[k] * Vf + Ytt[k] * Vt)
    return S.real if cmp["quantity"] == "branch P" else S.imag


def weakgrid_series(case, cmp, run):
    """weakgrid's trajectory of compared quantity ``cmp``: ``(t, y)`` in ``cmp["tol_unit"]``,
    repeated time stamps removed."""
    res, system, names = run["res"], run["system"], run["names"]
    q = cmp["quantity"]
    if q in ("rotor angle", "speed", "field voltage", "mechanical torque", "active power", "reactive power"):
        m = names.machine(cmp["bus"], cmp["id"])
        key = {"rotor angle": "delta", "speed": "omega", "field voltage": "vf", "mechanical torque": "tm",
               "active power": "Pe", "reactive power": "Qe"}[q]
        y = np.asarray(res[f"{m}.{key}"], dtype=float)
        if q == "mechanical torque":   # weakgrid: system base; PSS/E PMECH: machine base (MBASE)
            y = y * system.Sb / _machine_param(system, m, "Sn")
        if q == "rotor angle" and cmp["tol_unit"] == "deg":
            y = np.degrees(y)
    elif q == "bus voltage":
        y = np.asarray(res[f"bus{names.bus(cmp['bus'])}.v"], dtype=float)
    elif q == "bus angle":
        y = np.asarray(res[f"bus{names.bus(cmp['bus'])}.a"], dtype=float)
    elif q == "bus angle difference":
        y = np.asarray(res[f"bus{names.bus(cmp['bus'])}.a"] - res[f"bus{names.bus(cmp['ref_bus'])}.a"], dtype=float)
    elif q in ("branch P", "branch Q"):
        y = _branch_flow(case, system, res, names, cmp)
    else:
        raise Unsupported(f"quantity '{q}'")
    return dedupe(res.t, y)


def _machine_param(system, name, p):
    for c in system.components.values():
        if name in getattr(c, "names", ()):
            return float(np.atleast_1d(c.p[p])[list(c.names).index(name)])
    raise KeyError(name)


# ------------------------------------------------------------------------------ comparison
def compare_series(cmp, t_ref, y_ref, t, y):
    """Differences of ``(t, y)`` from PSS/E's ``(t_ref, y_ref)`` at PSS/E's samples up to the
    simulated time (PSID's norm, the largest difference, PSS/E's swing, the pass verdict)."""
    # PSS/E's time stamps carry a rounding (5.00007 s for the last sample of a 5-s run): PSID
    # rounds them to 1 ms, so a sample within 1 ms past the end is the end's
    sel = t_ref <= t[-1] + 1e-3
    tr, yr = t_ref[sel], y_ref[sel]
    yi = np.interp(tr, t, y)
    err = yi - yr
    psid_norm = float(np.max(np.abs(err))) if cmp["norm"] == "inf" else float(np.linalg.norm(err, 2))
    swing = float(np.max(y_ref) - np.min(y_ref))
    max_abs = float(np.max(np.abs(err)))
    # a quantity PSS/E holds constant (e.g. the torque of a machine without governor) has no
    # swing: only PSID's tolerance applies to it
    share = max_abs / swing if swing > 0 else math.nan
    within_swing = bool(share <= SWING_SHARE) if swing > 0 else True
    complete = bool(sel.all())
    within_tol = psid_norm <= float(cmp["tol"])
    return {"quantity": _label(cmp), "unit": cmp["tol_unit"], "norm": cmp["norm"], "tol": float(cmp["tol"]),
            "psid_norm": psid_norm, "max_abs": max_abs, "swing": swing, "share_of_swing": share,
            "complete": complete, "within_tol": within_tol, "within_swing": within_swing,
            "ok": complete and within_tol and within_swing}


def _label(cmp):
    q = cmp["quantity"]
    if "from_bus" in cmp:
        return f"{q} {cmp['from_bus']}-{cmp['to_bus']} at {cmp['end']}"
    if "ref_bus" in cmp:
        return f"{q} {cmp['bus']}-{cmp['ref_bus']}"
    if "id" in cmp:
        return f"{q} ({cmp['bus']}, '{cmp['id']}')"
    return f"{q} {cmp['bus']}"


def compare_case(case, run, root=None):
    """Every compared quantity of the entry: list of :func:`compare_series` dicts."""
    t_ref, M = read_psse_csv(case, root)
    sb = run["system"].Sb if "system" in run else 100.0
    out = []
    for cmp in case["compare"]:
        y_ref = psse_series(case, cmp, t_ref, M, sbase=sb)
        t, y = run["series"](cmp) if "series" in run else weakgrid_series(case, cmp, run)
        out.append(compare_series(cmp, t_ref, y_ref, t, y))
    return out


# ------------------------------------------------------------------------------ ANDES
def _andes_load(case, root=None):
    from .andes_case import load_case

    dyr = case_file(case, "dyr", root) if case.get("dyr") else None
    ss = load_case(case_file(case, "raw", root), addfile=dyr)
    return ss


def run_andes(case, root=None, h=None, tol=1e-8):
    """The entry in ANDES: its parser, its time-domain simulation, the same event.

    Returns a dict with ``series(cmp) -> (t, y)`` (as :func:`weakgrid_series`), or raises
    :class:`Unsupported` naming what ANDES cannot do with the case."""
    from .andes_case import run_andes_ss

    ss = _andes_load(case, root)
    notes = andes_data_changes(ss)
    ev = case["event"]
    if case["loads"] != "constant impedance":
        cfg = ss.PQ.config
        cfg.p2z, cfg.q2z = 0.0, 0.0
        if case["loads"] == "constant power":
            cfg.p2p, cfg.q2q = 1.0, 1.0
        else:
            cfg.p2i, cfg.q2i = 1.0, 1.0
    if ev["kind"] == "branch trip":
        lines = _andes_lines(ss, ev["from_bus"], ev["to_bus"])
        if not lines:
            raise Unsupported(f"ANDES has no line {ev['from_bus']}-{ev['to_bus']}")
        ss.add("Toggle", {"model": "Line", "dev": lines[0], "t": float(ev["t"])})
    else:
        raise Unsupported(f"event kind '{ev['kind']}' not mapped to ANDES in this harness")
    out = run_andes_ss(ss, case["tend"], h or case.get("dt", DT), tol=tol)
    if not out.get("ok"):
        raise Unsupported(f"ANDES run failed: {out.get('error')}")
    ts = ss.dae.ts
    t = np.asarray(ts.t)

    def series(cmp):
        q = cmp["quantity"]
        if q in ("rotor angle", "speed", "field voltage"):
            mdl, k = _andes_machine(ss, cmp["bus"], cmp["id"])
            var = {"rotor angle": mdl.delta, "speed": mdl.omega, "field voltage": mdl.vf}[q]
            arr = ts.x if var in mdl.states.values() else ts.y
            y = np.asarray(arr[:, var.a[k]])
        elif q in ("bus voltage", "bus angle", "bus angle difference"):
            k = list(ss.Bus.idx.v).index(cmp["bus"])
            if q == "bus voltage":
                y = np.asarray(ts.y[:, ss.Bus.v.a[k]])
            else:
                y = np.asarray(ts.y[:, ss.Bus.a.a[k]])
                if q == "bus angle difference":
                    kr = list(ss.Bus.idx.v).index(cmp["ref_bus"])
                    y = y - np.asarray(ts.y[:, ss.Bus.a.a[kr]])
        elif q == "mechanical torque":   # ANDES: system base; PSS/E PMECH: machine base
            mdl, k = _andes_machine(ss, cmp["bus"], cmp["id"])
            y = np.asarray(ts.y[:, mdl.tm.a[k]]) * ss.config.mva / float(mdl.Sn.v[k])
        elif q in ("branch P", "branch Q"):
            y = _andes_branch_flow(ss, ts, cmp, ev)
        else:
            raise Unsupported(f"quantity '{q}' not read from ANDES in this harness")
        return dedupe(t, y)

    return {"series": series, "ss": ss, "wall": out["wall"], "notes": notes}


def andes_data_changes(ss):
    """What ANDES's PSS/E parser did to the case's ``.dyr``: models it dropped, and models it
    read as another model (``andes/io/psse-dyr.yaml``'s ``destination``), e.g. GENSAL as GENROU."""
    import os

    import yaml
    from andes.io import psse

    from ..io.andes import psse_dyr_dropped

    with open(os.path.join(os.path.dirname(psse.__file__), "psse-dyr.yaml")) as f:
        table = yaml.safe_load(f) or {}
    out = [f"{m} dropped ({n})" for m, n in sorted(psse_dyr_dropped(ss).items())]
    for m in sorted(getattr(ss, "dyr_dict", None) or {}):
        dest = (table.get(m) or {}).get("destination")
        if dest and dest != m:
            out.append(f"{m} read as {dest}")
    return out


def _andes_branch_flow(ss, ts, cmp, ev):
    """P or Q [pu, system base] at one end of an in-service ANDES ``Line`` (its pi model: series
    ``1/(r + jx)``, shunts ``g/2 + g1 + j(b/2 + b1)`` and ``g/2 + g2 + j(b/2 + b2)``, tap and phase
    shift at the from end), from ANDES's bus voltages."""
    if ev["kind"] == "branch trip" and {ev["from_bus"], ev["to_bus"]} == {cmp["from_bus"], cmp["to_bus"]}:
        raise Unsupported("the flow of the tripped branch itself is not computed by the harness")
    ln = ss.Line
    lines = _andes_lines(ss, cmp["from_bus"], cmp["to_bus"])
    if len(lines) != 1:
        raise Unsupported(f"ANDES: {len(lines)} lines {cmp['from_bus']}-{cmp['to_bus']}")
    k = list(ln.idx.v).index(lines[0])
    v = lambda name: float(getattr(ln, name).v[k])  # noqa: E731
    ys = 1.0 / complex(v("r"), v("x"))
    yh = complex(v("g") / 2 + v("g1"), v("b") / 2 + v("b1"))
    yk = complex(v("g") / 2 + v("g2"), v("b") / 2 + v("b2"))
    m = v("tap") * np.exp(1j * v("phi"))
    bus = list(ss.Bus.idx.v)

    def V(b):
        j = bus.index(b)
        return ts.y[:, ss.Bus.v.a[j]] * np.exp(1j * ts.y[:, ss.Bus.a.a[j]])

    b1, b2 = ln.bus1.v[k], ln.bus2.v[k]
    V1, V2 = V(b1), V(b2)
    if (cmp["end"] == "from") == (int(b1) == int(cmp["from_bus"])):
        S = V1 * np.conj((ys + yh) / abs(m) ** 2 * V1 - ys / np.conj(m) * V2)
    else:
        S = V2 * np.conj(-ys / m * V1 + (ys + yk) * V2)
    return np.asarray(S.real if cmp["quantity"] == "branch P" else S.imag)


def _andes_lines(ss, f, t):
    out = []
    for k, ix in enumerate(ss.Line.idx.v):
        if {int(ss.Line.bus1.v[k]), int(ss.Line.bus2.v[k])} == {int(f), int(t)} and ss.Line.u.v[k] > 0:
            out.append(ix)
    return out


def _andes_machine(ss, bus, gid):
    from .andes_case import MACHINES

    hits = []
    for m in MACHINES + ("GENSAL",):
        mdl = ss.models.get(m)
        if mdl is None:
            continue
        for k in range(mdl.n):
            if int(mdl.bus.v[k]) == int(bus) and mdl.u.v[k] > 0:
                hits.append((mdl, k))
    if not hits:
        raise Unsupported(f"ANDES has no machine at bus {bus}")
    if len(hits) > 1:
        raise Unsupported(f"ANDES: {len(hits)} machines at bus {bus} (its names do not carry PSS/E's id '{gid}')")
    return hits[0]
