"""``from_psse``: a PSS/E ``.raw`` (+ ``.dyr``) pair as a weakgrid :class:`~weakgrid.sim.system.System`.

Each ``.dyr`` record ``IBUS 'MODEL' ID values /`` is read by the registry class named ``MODEL``
through its ``psse_record`` (field order, PSS/E's ICONs then CONs) and ``psse_params``
(conversions, e.g. ``M = 2H``); see :class:`~weakgrid.sim.component.Component`. A record of a
model weakgrid lacks (no registry class, or one without ``psse_record``) is never dropped nor
replaced: all of them are listed, by bus, id and model, in one :class:`DataError`. Controls
(exciters, compensators, stabilizers, governors) attach to the machine at ``(IBUS, ID)`` by their
class's ``kind``; a ``device`` model (a converter) declares ``psse_link(values, ctx)`` returning
its link (e.g. ``{"gen": ctx.gen_row}``), with ``ctx`` (:class:`PsseContext`) carrying the
generator's row, the names of the records already built at it and a branch look-up; devices
are built in the registry's order (REGCA1, then REECA1/REECB1, then REPCA1).

PSS/E conventions kept:

* a ``GENCLS`` with ``H = 0`` is PSS/E's infinite bus (infinite inertia, constant internal
  voltage behind ``ZSORCE``): with a negligible ``|ZSORCE|`` (<= 1e-3 pu on SBASE) it becomes an
  :class:`~weakgrid.sim.sources.InfiniteBus` (fixed terminal voltage and angle), else a GENCLS
  with an inertia of 1e9 s (its internal voltage and angle then stay constant); noted;
* machines: ``Sn = MBASE``, ``Vn`` = bus base voltage, ``fn = BASFRQ``, PSS/E's swing equation
  (``psse_shaft = 1``: the mechanical input is a power, ``M dω/dt = (Pm − D Δω)/ω − te``);
  ``ZSORCE`` is given to
  ``psse_params`` (``GENCLS``: ``ra + j xd1``; ``GENROU``: ``ra``); governors: turbine base
  ``Tn = MBASE``;
* a remote-bus ICON of 0 means the machine's own bus (each model's ``psse_params`` refuses a
  non-zero remote bus it cannot represent, naming the file and line);
* static generators without a machine record: as :func:`~weakgrid.sim.io.andes.from_andes`
  (``static_gens``).

Names: machines ``"<MODEL>_<bus>_<id>"`` (``GENROU_102_1``), controls likewise
(``SEXS_102_1``). PSS/E identifiers are kept on the system: ``system.source = "psse"``,
``psse_bus_name`` {bus: name}, ``psse_gen_row`` {(bus, id): gen row}, ``psse_machine``
{(bus, id): machine or source name}, ``psse_device`` {(model, bus, id): name},
``psse_branch_row`` {(i, j, ckt): row}, ``psse_transformer_rows`` {(i, j, k, ckt): rows},
``psse_star_bus`` {(i, j, k, ckt): bus}.
"""

from __future__ import annotations

import dataclasses
import warnings
from pathlib import Path

from ...errors import DataError, DataWarning
from ...network import Network
from ...system import System, _registry
from .context import PsseContext
from .dyr import read_dyr
from .network import build_case
from .raw import read_raw

#: ``|ZSORCE|`` [pu on SBASE] up to which an H = 0 GENCLS is an ideal voltage source at its bus
INFINITE_BUS_ZMAX = 1e-3
#: inertia M [s] of an H = 0 GENCLS behind a non-negligible ZSORCE (PSS/E: infinite)
INFINITE_M = 1e9
_CONTROL_KINDS = ("exciter", "compensator", "pss", "governor")


class _at:
    """Re-raise a model's DataError (parameter checks) naming the .dyr file, line and record."""

    def __init__(self, rec):
        self.rec = rec

    def __enter__(self):
        return self

    def __exit__(self, typ, exc, tb):
        if isinstance(exc, DataError) and not str(exc.element).startswith(self.rec.file):
            raise DataError(f"{self.rec.where} ({exc.element})", exc.field, exc.value, exc.fix) from None
        return False


def _model_class(reg, model):
    cls = reg.get(model)
    return cls if cls is not None and getattr(cls, "psse_record", None) is not None else None


def _values(rec, cls):
    """Record values by the names of ``cls.psse_record``; field-count errors name the field."""
    names = list(cls.psse_record)
    need, opt = len(names), int(getattr(cls, "psse_record_optional", 0))
    n = len(rec.values)
    if n < need - opt:
        missing = names[n]
        raise DataError(rec.where, missing, None,
                        f"the record has {n} values, {rec.model} takes {need} "
                        f"({', '.join(names)}): the value of {missing} (field {n + 1}) and after "
                        "are missing")
    if n > need:
        raise DataError(rec.where, f"value {need + 1}", rec.values[need],
                        f"the record has {n} values, {rec.model} takes {need} "
                        f"({', '.join(names)}) in PSS/E's order: remove the extra values "
                        f"(line {rec.value_lines[need]})")
    return dict(zip(names, rec.values))


def _params(rec, cls, ctx):
    vals = _values(rec, cls)
    out = cls.psse_params(vals, ctx)
    params = {}
    for k, v in out.items():
        if k.startswith("_"):
            continue
        if isinstance(v, str):
            names = list(cls.psse_record)
            fld = names.index(k) + 1 if k in names else "?"
            raise DataError(rec.where, k, v, f"field {fld} ({k}) must be a number, not text")
        params[k] = float(v)
    return params


def _current_loads(system, maps, notes):
    """Keep the constant-current parts of the loads constant current in the time domain: a ZIP
    per bus with such a part (the constant-power part becomes a constant impedance, as PSS/E's
    CONL to 100 % admittance; the admittance part is already a shunt)."""
    net = system.network
    for b, (pl, ql, ip, iq) in sorted(maps.load_parts.items()):
        if not (ip or iq):
            continue
        shares = []
        for p, i in ((pl, ip), (ql, iq)):
            tot = p + i
            if tot == 0 and i != 0:
                shares = None
                break
            ki = 100.0 * i / tot if tot else 0.0
            shares += [0.0, ki, 100.0 - ki]
        if shares is None:
            notes.append(f"bus {b}: constant-power and constant-current load parts cancel (net load 0); "
                         "the current part is simulated as constant impedance")
            continue
        k = net.index_of(b)
        system._component("ZIP", "device").add_zip(
            f"ZIP_{b}", k, (pl + ip) / net.Sb, (ql + iq) / net.Sb,
            **dict(zip(("kpp", "kpi", "kpz", "kqp", "kqi", "kqz"), shares)))


def from_psse(raw, dyr=None, *, include_events: bool = True, static_gens: str = "ideal",
              basfrq: float | None = None):
    """Build a weakgrid :class:`System` from a PSS/E ``.raw`` file and, optionally, a ``.dyr`` file.

    Parameters
    ----------
    raw : str or Path
        Power-flow data, PSS/E versions 29 to 35 (:mod:`.raw`; the solved case: its bus
        voltages ``VM``, ``VA`` start the power flow).
    dyr : str or Path, optional
        Dynamic data. Without it every in-service generator is a static generator (see
        ``static_gens``).
    include_events : bool
        Kept for symmetry with :func:`~weakgrid.sim.io.andes.from_andes`: PSS/E files hold no
        timed events (PSS/E's disturbances are commands of the run), so the event list is empty.
    static_gens : {"ideal", "refuse"}
        In-service generators without a machine record: ``"ideal"`` simulates them as
        ANDES does (the swing bus's as an :class:`~weakgrid.sim.sources.InfiniteBus`, the others
        as :class:`~weakgrid.sim.sources.PVSource`; noted), ``"refuse"`` raises
        :class:`DataError` naming them.
    basfrq : float, optional
        The base frequency of the simulation [Hz], in place of the ``.raw``'s ``BASFRQ`` (PSS/E:
        ``psspy.base_frequency``, a setting of the run; noted). For results computed at another
        frequency than the file states, e.g. PSID's STAB1 benchmark: its ``.raw`` says 50 Hz,
        PSS/E's results are at 60 Hz (PowerSimulationsDynamics.jl reads it at 60 Hz too).

    Returns
    -------
    system : System
        Not yet set up. ``system.import_notes`` lists every conversion, approximation and
        skipped item.
    events : list
        Empty (see ``include_events``).

    Raises
    ------
    DataError
        A bad file (naming file, line, record and field), devices weakgrid lacks in service
        (dc lines, FACTS, GNE, induction machines: one message listing them), ``.dyr`` records
        of models weakgrid lacks (one message listing all of them by bus, id and model).
    """
    if static_gens not in ("ideal", "refuse"):
        raise DataError("from_psse", "static_gens", static_gens,
                        "use 'ideal' (simulate them as ANDES does) or 'refuse'")
    rc = read_raw(raw)
    rname = Path(rc.path).name
    if basfrq is not None:
        if not (isinstance(basfrq, (int, float)) and basfrq > 0):
            raise DataError("from_psse", "basfrq", basfrq, "give the base frequency in Hz (> 0), or None "
                            "for the .raw's BASFRQ")
        if float(basfrq) != rc.basfrq:
            rc.notes.append(f"{rname}: base frequency {float(basfrq):g} Hz (basfrq), not the file's "
                            f"BASFRQ = {rc.basfrq:g} Hz")
        rc.basfrq = float(basfrq)
    bad = [f"{sec} {label} (line {ln})" for sec, items in rc.unsupported.items()
           for ln, on, label in items if on]
    if bad:
        raise DataError(f"{rname}", "devices", bad,
                        f"weakgrid does not model these in-service devices: {'; '.join(bad)}. "
                        "Set their status to 0 (out of service) or replace them by an equivalent")
    case, maps = build_case(rc)
    notes = list(rc.notes) + list(maps.notes)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", DataWarning)
        net = Network(case, f_hz=rc.basfrq)
    notes += [str(w.message) for w in caught if issubclass(w.category, DataWarning)]
    for k in range(net.nb):
        if net.bus[k, 1] == 3:
            b = int(net.bus_ids[k])
            if not any(int(g[0]) == b and g[7] > 0 for g in net.gen):
                raise DataError(f"{rname}, bus {b}", "IDE", 3,
                                "the swing bus has no in-service generator: add one or make "
                                "another bus (with a generator) the swing bus")
    system = System(net)
    _current_loads(system, maps, notes)
    records = read_dyr(dyr) if dyr is not None else []
    reg = _registry()
    missing = [r for r in records if _model_class(reg, r.model) is None]
    if missing:
        lst = "; ".join(f"{r.model} at bus {r.bus} id '{r.id}' ({r.file} line {r.line})" for r in missing)
        models = sorted({r.model for r in missing})
        raise DataError(f"{missing[0].file}", "models", models,
                        f"weakgrid has no model for these records ({len(missing)}): {lst}. "
                        "Nothing is substituted: remove these records (the generators then run "
                        "as static generators or without that control) or add the models")
    for r in records:      # file errors (field counts) first, for every record
        _values(r, reg[r.model])
    b = _Builder(system, rc, maps, notes)
    by_kind = {}
    for r in records:
        by_kind.setdefault(reg[r.model].kind, []).append(r)
    for r in by_kind.get("machine", []):
        b.machine(r, reg[r.model])
    for kind in _CONTROL_KINDS:
        for r in by_kind.get(kind, []):
            b.control(r, reg[r.model], kind)
    # devices in the registry's order: a converter (REGCA1) before its electrical control
    # (REECA1, REECB1), before the plant controller (REPCA1), whatever the file's order
    order = {name: k for k, name in enumerate(reg)}
    for r in sorted(by_kind.get("device", []), key=lambda r: order[r.model]):
        b.device(r, reg[r.model])
    b.static_generators(static_gens)
    b.finish(dyr)
    return system, []


class _Builder:
    """Adds the .dyr records to the system, keeping PSS/E's identifiers and the notes."""

    def __init__(self, system, rc, maps, notes):
        self.system, self.rc, self.maps, self.notes = system, rc, maps, notes
        self.rname = Path(rc.path).name
        self.machines = {}      # (bus, id) -> machine or source name (None: out of service)
        self.devices = {}       # (model, bus, id) -> name
        self.ctl_skip = set()   # generators whose controls are skipped (off / infinite bus)

    def context(self, r) -> PsseContext:
        key = (r.bus, r.id)
        if key not in self.maps.gen:
            raise DataError(r.where, "IBUS, ID", key,
                            f"no generator at bus {r.bus} with id '{r.id}' in {self.rname}: correct "
                            f"the bus number or id (generators: {sorted(self.maps.gen)[:20]})")
        g = self.maps.gen[key]
        return PsseContext(bus=r.bus, id=r.id, mbase=g["mbase"], sbase=self.rc.sbase,
                           zsorce=complex(g["zr"], g["zx"]), kv=self.maps.kv[r.bus],
                           fn=self.rc.basfrq, where=r.where)

    def machine(self, r, cls):
        """A machine record: a machine on its generator's row, or PSS/E's infinite bus (H = 0)."""
        ctx = self.context(r)
        key = (r.bus, r.id)
        if key in self.machines:
            raise DataError(r.where, "MODEL", r.model,
                            f"the generator at bus {r.bus} id '{r.id}' already has a machine model "
                            f"({self.machines[key]}): keep one")
        if not self.maps.gen[key]["stat"]:
            self.notes.append(f"{r.where}: its generator is out of service, skipped with its controls")
            self.ctl_skip.add(key)
            self.machines[key] = None
            return
        params = _params(r, cls, ctx)
        row = self.maps.gen_row[key]
        name = f"{r.model}_{r.bus}_{r.id}"
        if r.model == "GENCLS" and params.get("M", 1.0) == 0.0:
            zsys = abs(ctx.zsorce) * ctx.sbase / ctx.mbase
            if zsys <= INFINITE_BUS_ZMAX:
                self.system._component("InfiniteBus", "device").add_source(name, row)
                self.notes.append(f"{r.where}: H = 0, PSS/E's infinite bus; simulated as an ideal "
                                  f"voltage source at bus {r.bus} (InfiniteBus: fixed voltage and "
                                  f"angle; |ZSORCE| = {zsys:.3g} pu on SBASE neglected)")
                self.ctl_skip.add(key)
                self.machines[key] = name
                return
            params["M"] = INFINITE_M
            self.notes.append(f"{r.where}: H = 0, PSS/E's infinite inertia; GENCLS with M = "
                              f"{INFINITE_M:g} s (constant internal voltage behind ZSORCE = "
                              f"{ctx.zsorce:.4g} pu)")
        # PSS/E's swing equation: the mechanical input is a power, M dw/dt = (Pm - D dw)/w - te
        params.update(Sn=ctx.mbase, Vn=ctx.kv, fn=self.rc.basfrq, psse_shaft=1.0)
        with _at(r):
            self.system.add_machine(r.model, name, row, **params)
        self.machines[key] = name
        self.devices[(r.model, r.bus, r.id)] = name

    def control(self, r, cls, kind):
        """An exciter, compensator, stabilizer or governor of the machine at (IBUS, ID)."""
        ctx = self.context(r)
        key = (r.bus, r.id)
        if key in self.ctl_skip:
            self.notes.append(f"{r.where}: its machine is out of service or an infinite bus, skipped")
            return
        if self.machines.get(key) is None:
            raise DataError(r.where, "MODEL", r.model,
                            f"the generator at bus {r.bus} id '{r.id}' has no machine model in the "
                            f".dyr: add its machine record (e.g. GENROU) before its {kind}")
        params = _params(r, cls, ctx)
        if kind == "governor" and any(p.name == "Tn" for p in cls.params):
            params.setdefault("Tn", ctx.mbase)      # PSS/E: governor data on MBASE
        name = f"{r.model}_{r.bus}_{r.id}"
        add = {"exciter": self.system.add_exciter, "governor": self.system.add_governor,
               "pss": self.system.add_pss, "compensator": self.system.add_compensator}[kind]
        with _at(r):
            add(r.model, name, self.machines[key], **params)
        self.devices[(r.model, r.bus, r.id)] = name

    def device(self, r, cls):
        """A converter or other device, linked by its class's ``psse_link``."""
        ctx = self.context(r)
        key = (r.bus, r.id)
        if not self.maps.gen[key]["stat"]:
            self.notes.append(f"{r.where}: its generator is out of service, skipped")
            return
        link_fn = getattr(cls, "psse_link", None)
        if link_fn is None:
            raise DataError(r.where, "MODEL", r.model, f"{r.model} cannot be linked from a .dyr "
                            "record (its class has no psse_link)")
        names = {m: n for (m, b, i), n in self.devices.items() if (b, i) == key}
        ctx = dataclasses.replace(ctx, gen_row=self.maps.gen_row[key], names=names,
                                  branch_row=self._branch_row)
        link = link_fn(_values(r, cls), ctx)
        params = _params(r, cls, ctx)
        name = f"{r.model}_{r.bus}_{r.id}"
        with _at(r):
            self.system._component(r.model, "device").add(name, link, params)
        self.devices[(r.model, r.bus, r.id)] = name
        self.machines.setdefault(key, name)

    def _branch_row(self, i, j, ckt):
        """0-based branch row of the PSS/E branch (i, j, ckt), in either direction."""
        key = str(ckt).strip()
        for a, b in ((i, j), (j, i)):
            for (fi, fj, c), row in self.maps.branch_row.items():
                if (fi, fj) == (a, b) and str(c).strip() == key:
                    return row
        raise DataError("PSS/E case", "branch", f"{i}-{j}-{ckt}",
                        "no such branch in the .raw (give FROM, TO and the circuit id of a "
                        "non-transformer branch)")

    def static_generators(self, static_gens):
        """In-service generators without a machine or converter: as ANDES simulates them."""
        system, net = self.system, self.system.network
        used = {lk["gen"] for c in system.components.values() for lk in c.links if "gen" in lk}
        bare = [(key, row) for key, row in self.maps.gen_row.items()
                if self.maps.gen[key]["stat"] and row not in used]
        if bare and static_gens == "refuse":
            names = [f"bus {b} id '{i}'" for (b, i), _ in bare]
            raise DataError(f"{self.rname}", "generators", names,
                            f"the generators {names} have no machine record in the .dyr; add one or "
                            "set their status to 0")
        by_bus = {}
        for (b, i), row in bare:               # one ideal source per bus (one V constraint)
            by_bus.setdefault(b, []).append((i, row))
        for b, units in by_bus.items():
            (i, row), rest = units[0], units[1:]
            slack = net.bus[net.index_of(b), 1] == 3
            src = "InfiniteBus" if slack else "PVSource"
            name = f"{src}_{b}_{i}"
            system._component(src, "device").add_source(name, row, also=[r for _, r in rest])
            what = ("an ideal voltage source (infinite bus: fixed voltage and angle)" if slack else
                    "a constant-P, constant-|V| source (no inertia, unlimited reactive power)")
            for k, (j, _) in enumerate(units):
                self.machines[(b, j)] = name
                share = "" if k == 0 else f"; held by {name} with its bus's other units, P summed"
                self.notes.append(f"generator at bus {b} id '{j}': no machine record; simulated "
                                  f"as {what} ({src}){share}")

    def finish(self, dyr):
        """PSS/E identifiers and the notes, on the system."""
        s, maps = self.system, self.maps
        s.import_notes = self.notes
        s.source = "psse"
        s.psse_version = self.rc.version
        s.psse_files = (str(self.rc.path), None if dyr is None else str(dyr))
        s.psse_bus_name = dict(maps.bus_name)
        s.psse_gen_row = dict(maps.gen_row)
        s.psse_machine = {k: v for k, v in self.machines.items() if v is not None}
        s.psse_device = self.devices
        s.psse_branch_row = dict(maps.branch_row)
        s.psse_transformer_rows = dict(maps.transformer_rows)
        s.psse_star_bus = dict(maps.star_bus)
        net = s.network      # the PSS/E identifiers on the network too (printouts, studies)
        net.bus_names.update({int(b): str(n).strip() for b, n in maps.bus_name.items()
                              if str(n).strip()})
        for (i, j, c), row in maps.branch_row.items():
            net.branch_names[int(row)] = f"{i}-{j}-{c}"
        for (i, j, k, c), rows in maps.transformer_rows.items():
            for w, row in enumerate(rows, start=1):
                net.branch_names[int(row)] = (f"{i}-{j}-{c}" if k == 0 else
                                              f"{i}-{j}-{k}-{c} winding {w}")
        s.conventions = "standard"
        s.conventions_applied = {}
