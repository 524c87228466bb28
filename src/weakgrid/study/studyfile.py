"""Study files: a grid, a controlled machine, a UPQC, design settings, controllers, scenarios.

A study is a TOML file (or a dict: :func:`study_from_dict`), validated when read; every error
names the field (as a dotted path), the value and the fix. Any field can be addressed by a
dotted path (:func:`get_path`, :func:`set_path`): ``upqc.rating``, ``design.T``,
``scenarios.c1-high-conv.events.0.xf`` (a list element by its ``id``, or by index). The shipped
studies live in ``weakgrid/data/studies/`` and can be named instead of a path.

The tables and fields (type, unit, default, allowed values) are declared once, in
:mod:`weakgrid.study.fields`, which this validation takes its keys and defaults from; the
reference page ``docs/study-file-reference.md`` and the JSON Schema
``weakgrid/data/study.schema.json`` (``weakgrid schema``) are rendered from it
(:mod:`weakgrid.study.reference`).
"""

from __future__ import annotations

import copy
import tomllib
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from ..dotted import get_path as _get, set_path as _set
from ..fileio import check_file_name, safe_name
from ..game.errors import ParameterError
from . import fields as F
from .grid_edits import EDITS, validate_edits

__all__ = ["Study", "load_study", "apply_overrides", "study_from_dict", "get_path", "set_path", "shipped_studies",
           "read_study_dict", "event_end", "EVENT_KINDS"]

# the tables, their fields and defaults: weakgrid.study.fields (the one source of the
# validation here, the reference page and the JSON Schema)
TOP = set(F.TOP)
GRID_KINDS = F.GRID_KINDS
STRUCTURES = F.STRUCTURES
EVENT_KINDS = F.EVENT_KINDS


# --------------------------------------------------------------------------- dotted paths
def _is_fault(obj) -> bool:
    return isinstance(obj, dict) and obj.get("kind") == "fault"


# a fault's end is given by t_off or by its duration (t_off = t_on + duration); a validated
# study keeps t_off only, and both are addressable: reading "duration" gives t_off − t_on,
# setting one of them drops the other (validation derives t_off from the duration and the
# event's t_on then, whatever order a sweep sets t_on and the duration in)
_FAULT_END = {"t_off": "duration", "duration": "t_off"}


def event_end(ev: dict) -> float | None:
    """When a fault event ends [s]: its ``t_off``, or ``t_on + duration`` in a study dict
    not validated again since a sweep set the duration; None for other events."""
    if "t_off" in ev:
        return float(ev["t_off"])
    if "duration" in ev:
        return float(ev.get("t_on", 0.0)) + float(ev["duration"])
    return None


def _parent(d: dict, path: str):
    """``(parent, last key)`` of dotted ``path`` (the parent looked up with
    :func:`weakgrid.dotted.get_path`; the top level for a one-part path)."""
    head, _, last = path.rpartition(".")
    return (_get(d, head) if head else d), last


def get_path(d: dict, path: str):
    """The value at dotted ``path`` in study dict ``d`` (e.g. ``"upqc.rating"``; a list element
    by its ``id`` or index), see :func:`weakgrid.dotted.get_path`; a fault's ``duration`` [s]
    is ``t_off − t_on`` when only ``t_off`` is given."""
    if path.endswith(".duration"):
        obj, last = _parent(d, path)
        if _is_fault(obj) and last not in obj and "t_off" in obj and "t_on" in obj:
            return round(float(obj["t_off"]) - float(obj["t_on"]), 12)
    return _get(d, path)


def set_path(d: dict, path: str, value) -> dict:
    """Set the value at dotted ``path`` (creating missing tables and an absent optional field;
    the study is validated afterwards); returns ``d``. Setting a fault's ``t_off`` or
    ``duration`` drops the other (validation derives ``t_off``)."""
    _set(d, path, value, create=True)
    obj, last = _parent(d, path)
    if _is_fault(obj) and last in _FAULT_END:   # the fault's end given the other way
        obj.pop(_FAULT_END[last], None)
    return d


# --------------------------------------------------------------------------- reading
def shipped_studies() -> list[str]:
    """Names of the studies shipped in ``weakgrid/data/studies``."""
    folder = resources.files("weakgrid") / "data" / "studies"
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".toml"))


def read_study_dict(src) -> tuple[dict, str]:
    """``(dict, source)`` of a study file path or a shipped study name."""
    p = Path(str(src))
    if not p.exists() and str(src) in shipped_studies():
        res = resources.files("weakgrid") / "data" / "studies" / f"{src}.toml"
        with resources.as_file(res) as rp:
            return _read(rp), f"shipped:{src}"
    if not p.exists():
        raise ParameterError("study", str(src), "no such file and no shipped study of that "
                             f"name; shipped: {shipped_studies()}")
    return _read(p), str(p)


def _read(p) -> dict:
    try:
        with open(p, "rb") as fh:
            return tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError("study", str(p), f"is not valid TOML ({exc})") from None
    except UnicodeDecodeError as exc:
        raise ParameterError("study", str(p), f"is not UTF-8 text (byte "
                             f"{exc.object[exc.start:exc.start + 1]!r} at position {exc.start}): "
                             "save the study file as UTF-8 TOML") from None


def load_study(src, overrides=()) -> "Study":
    """Read and validate a study (a path or a shipped study's name).

    Parameters
    ----------
    src : str or Path
        A study file (TOML) or the name of a shipped study.
    overrides : iterable of (str, object)
        ``(dotted path, value)`` pairs set in the file's data after reading and before
        validation (the command line's ``--set``), see :func:`apply_overrides`.
    """
    d, source = read_study_dict(src)
    base = Path(source).parent if not source.startswith("shipped:") else None
    overrides = list(overrides)
    if overrides:
        d = apply_overrides(d, overrides, source=source, base_dir=base)
    return study_from_dict(d, source=source, base_dir=base)


_PROBE = "__weakgrid_unknown_field__"


def apply_overrides(d: dict, overrides, source: str = "", base_dir=None,
                    field: str = "--set") -> dict:
    """A copy of study dict ``d`` with ``(dotted path, value)`` pairs set (not yet validated).

    A path must name a field the study has (in the file, or a default the validation fills
    in), or a field its table accepts (an optional field absent from the file; the study's
    validation then checks the value). Anything else is refused with the fields that exist
    at that level.

    Raises
    ------
    ParameterError
        Naming ``field`` (``--set``), the path and the valid keys at that level.
    """
    d = copy.deepcopy(d)
    try:
        filled = study_from_dict(d, source, base_dir).data
    except ParameterError:       # the file itself is invalid: its validation says why later
        filled = None
    for path, value in overrides:
        keys = path.split(".") if isinstance(path, str) else []
        if not _known(d, path) and not (filled is not None and _known(filled, path)):
            parent = ".".join(keys[:-1])
            ref = filled if filled is not None and _known(filled, parent) else d
            if parent and not _known(ref, parent):
                _get(ref, path, field=field)           # raises: names the missing part
            holder = _get(ref, parent, field=field) if parent else ref
            if not isinstance(holder, dict):
                _get(ref, path, field=field)
            if not _accepts_new(d, parent, source, base_dir):
                raise ParameterError(field, path, f"no field '{keys[-1]}' in "
                                     f"{parent or 'the study file'}; fields there: "
                                     f"{sorted(map(str, holder))}")
        _set(d, path, value, create=True, field=field)
    return d


def _known(d, path) -> bool:
    try:
        _get(d, path)
        return True
    except ParameterError:
        return False


def _accepts_new(d, parent, source, base_dir) -> bool:
    """Does the validation check the keys of the table ``parent`` (an unknown one refused)?"""
    trial = copy.deepcopy(d)
    try:
        _set(trial, f"{parent}.{_PROBE}" if parent else _PROBE, 0, create=True)
        study_from_dict(trial, source, base_dir)
    except ParameterError as exc:
        return _PROBE in str(exc)
    return False


# --------------------------------------------------------------------------- validation
def _need(d, key, where, types=None):
    if not isinstance(d, dict) or key not in d:
        raise ParameterError(f"{where}.{key}", None, "missing; give it in the study file")
    v = d[key]
    if types is not None and not isinstance(v, types):
        raise ParameterError(f"{where}.{key}", v, f"must be of type {_tn(types)}")
    return v


def _tn(types):
    types = types if isinstance(types, tuple) else (types,)
    return " or ".join({"str": "string", "int": "integer", "float": "number", "dict": "table",
                        "list": "list", "bool": "true/false"}.get(t.__name__, t.__name__)
                       for t in types)


def _num(d, key, where, default=None, positive=False, nonneg=False):
    if key not in d:
        if default is None:
            raise ParameterError(f"{where}.{key}", None, "missing; give a number")
        return default
    v = d[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ParameterError(f"{where}.{key}", v, "must be a number")
    v = float(v)
    if v != v or v in (float("inf"), float("-inf")):
        raise ParameterError(f"{where}.{key}", v, "must be finite")
    if positive and v <= 0:
        raise ParameterError(f"{where}.{key}", v, "must be > 0")
    if nonneg and v < 0:
        raise ParameterError(f"{where}.{key}", v, "must be ≥ 0")
    return v


def _keys(d, allowed, where):
    if not isinstance(d, dict):
        raise ParameterError(where, d, "must be a table")
    for k in d:
        if k not in allowed:
            raise ParameterError(f"{where}.{k}", d[k], f"unknown field; allowed: {sorted(allowed)}")


def _choice(d, key, where, choices, default=None):
    v = d.get(key, default)
    if v not in choices:
        raise ParameterError(f"{where}.{key}", v, f"choose one of {list(choices)}")
    return v


@dataclass
class Study:
    """A validated study.

    Attributes
    ----------
    data : dict
        The study with defaults filled in (what runs; ``get_path``/``set_path`` address it).
    source : str
        Where it was read from.
    base_dir : Path or None
        Folder relative file names are resolved against.
    """

    data: dict
    source: str = ""
    base_dir: Path | None = None

    @property
    def name(self) -> str:
        return self.data["study"]["name"]

    def get(self, path):
        return get_path(self.data, path)

    def with_values(self, **paths) -> "Study":
        """A copy with dotted-path fields replaced, validated again (``{"upqc.rating": 0.3}``)."""
        d = copy.deepcopy(self.data)
        for p, v in paths.items():
            set_path(d, p, v)
        return study_from_dict(d, self.source, self.base_dir)

    def resolve(self, name) -> Path:
        p = Path(name)
        return p if p.is_absolute() or self.base_dir is None else self.base_dir / p

    @property
    def loads(self) -> list[str]:
        g = self.data["grid"]
        if g["kind"] == "inline":
            return list(g.get("loads", {})) or ["base"]
        return list(g.get("loads", {}).get("levels", {})) or ["base"]

    @property
    def controllers(self) -> list[str]:
        return list(self.data["controllers"]["compare"])

    def scenarios(self, quick: bool = False) -> list[dict]:
        """Scenarios (dicts, with their defaults) of a full or a quick run; quick uses each
        scenario's ``quick`` settings and leaves out scenarios without them."""
        out = []
        for sc in self.data["scenarios"]:
            if "bypass" not in sc:
                sc = dict(sc, bypass=[[e["t_on"], e["t_off"]] for e in sc["events"]
                                      if e["kind"] == "fault"])
            if quick:
                q = sc.get("quick")
                if not q:
                    continue
                sc = dict(sc, t_end=q.get("t_end", sc["t_end"]),
                          controllers=q.get("controllers", sc["controllers"]))
            out.append(sc)
        return out

    def runs(self, quick: bool = False) -> list[tuple[dict, str]]:
        """Every ``(scenario, controller)`` pair; run id = ``"<scenario id>-<controller>"``."""
        return [(sc, c) for sc in self.scenarios(quick) for c in sc["controllers"]]


def study_from_dict(d: dict, source: str = "", base_dir=None) -> Study:
    """Validate a study dict and fill in its defaults (the input is not modified)."""
    d = copy.deepcopy(d)
    _keys(d, TOP, "study file")
    st = d.setdefault("study", {})
    _keys(st, F.keys("study"), "study")
    if "name" in st:
        check_file_name(st["name"], "study.name")
    st.setdefault("name", safe_name(Path(source).stem if source else "study", "study"))
    for k in ("title", "reproduce", "notes"):
        st.setdefault(k, F.default("study", k))
    g = _need(d, "grid", "study file", dict)
    _choice(g, "kind", "grid", GRID_KINDS)
    _keys(g, F.grid_keys(g["kind"]) | set(EDITS), "grid")   # edits: validate_edits says more
    if g["kind"] == "inline":
        for k in ("bus", "branch", "gen"):
            _need(g, k, "grid", list)
        _num(g, "Sb_mva", "grid", 100.0, positive=True)
        g.setdefault("Sb_mva", 100.0)
        g.setdefault("f_hz", 60.0)
        _inline_grid(g)
    elif g["kind"] == "pandapower":
        _need(g, "network", "grid", str)
        if g["network"] == "from_json":
            v = _need(g, "file", "grid", str)
            if not v.lower().endswith(".json"):
                raise ParameterError("grid.file", v, "give the .json file written by "
                                     "pandapower.to_json (path relative to the study file)")
        elif "file" in g:
            raise ParameterError("grid.file", g["file"], 'a file is read with network = '
                                 '"from_json"; else network names a function of '
                                 "pandapower.networks")
    elif g["kind"] == "psse":
        for k in ("raw", "dyr"):
            if k in g or k == "raw":
                v = _need(g, k, "grid", str)
                ext = "." + k
                if not v.lower().endswith(ext):
                    raise ParameterError(f"grid.{k}", v, f"give the PSS/E {ext} file (path relative "
                                         "to the study file)")
    else:
        _need(g, "file", "grid", str)
    if "f_hz" in g:
        _num(g, "f_hz", "grid", positive=True)
    for level in _load_levels(g):
        check_file_name(level, f"grid.loads.{level}")
    validate_edits(g, _load_levels(g))
    dyn = d.setdefault("dynamics", {})
    _keys(dyn, F.keys("dynamics"), "dynamics")
    names = []
    for i, gen in enumerate(dyn.setdefault("generator", [])):
        w = f"dynamics.generator.{i}"
        _keys(gen, F.keys("dynamics.generator"), w)
        names.append(_need(gen, "name", w, str))
        _need(gen, "bus", w, (int, str))
        _need(_need(gen, "machine", w, dict), "model", f"{w}.machine", str)
        for part in ("exciter", "governor", "pss"):
            if part in gen:
                _need(_need(gen, part, w, dict), "model", f"{w}.{part}", str)
    for i, gt in enumerate(dyn.setdefault("gti", [])):
        w = f"dynamics.gti.{i}"
        _keys(gt, F.keys("dynamics.gti"), w)
        names.append(_need(gt, "name", w, str))
        _need(gt, "bus", w, (int, str))
        _choice(gt, "mode", w, ("energy", "pq"), F.default("dynamics.gti", "mode"))
        for k in ("C", "B", "tau", "Vc0"):
            _num(gt, k, w, positive=k != "tau")
    m = _need(d, "machine", "study file", dict)
    _keys(m, F.keys("machine"), "machine")
    if _need(m, "name", "machine", str) not in names and g["kind"] not in ("andes", "psse"):
        raise ParameterError("machine.name", m["name"], f"no generator or GTI of that name in "
                             f"[dynamics]; choose one of {names}")
    up = _need(d, "upqc", "study file", dict)
    _keys(up, F.keys("upqc"), "upqc")
    _choice(up, "side", "upqc", ("from", "to"), F.default("upqc", "side"))
    up.setdefault("name", F.default("upqc", "name"))
    up["structure"] = _choice(up, "structure", "upqc", STRUCTURES,
                              F.default("upqc", "structure"))
    up["rating"] = _num(up, "rating", "upqc", F.default("upqc", "rating"), positive=True)
    if up["rating"] > MAX_RATING:
        raise ParameterError("upqc.rating", up["rating"], f"a series voltage above {MAX_RATING:g} "
                             "pu (the line's nominal voltage) is more than the series "
                             "transformer and the line can carry; give the UPQC's largest "
                             "series-voltage magnitude in pu, at most 1.0 (typically 0.1-0.5)")
    _device_fields(up)
    if ("branch" in up) == ("insert" in up):
        raise ParameterError("upqc.branch", up.get("branch"), "give either upqc.branch (an "
                             "existing series branch, from = shunt bus) or upqc.insert (a new "
                             "series branch put into an existing branch)")
    if "insert" in up:
        ins = up["insert"]
        _keys(ins, F.keys("upqc.insert"), "upqc.insert")
        _choice(ins, "side", "upqc.insert", ("from", "to"))
        _num(ins, "x", "upqc.insert", positive=True)
        ins.setdefault("r", F.default("upqc.insert", "r"))
    ds = _need(d, "design", "study file", dict)
    _keys(ds, F.keys("design"), "design")
    _num(ds, "T", "design", positive=True)
    from ..design.derive import GRID_MODELS

    _choice(ds, "grid_model", "design", GRID_MODELS,
            default=F.default("design", "grid_model"))   # not set: the key of
    # every cached run stays as it was
    ds.setdefault("settings", F.default("design", "settings"))
    from ..models import preset_names

    if ds["settings"] not in preset_names():
        raise ParameterError("design.settings", ds["settings"],
                             f"choose a preset for Q, R, P, γ, Ω, mesh, basis, initial policy: "
                             f"{preset_names()}")
    sim = d.get("simulation")
    if sim is not None:
        _keys(sim, F.keys("simulation"), "simulation")
        rec = sim.get("record")
        if rec is not None and not (isinstance(rec, list) and rec and all(
                isinstance(r, str) and r.strip() for r in rec)):
            raise ParameterError("simulation.record", rec, "give a list of signal names or "
                                 "fnmatch patterns, e.g. [\"*.omega\", \"*.delta\", "
                                 "\"bus*.v\"] (omit it to record every signal)")
        if "dt" in sim:
            _num(sim, "dt", "simulation", positive=True)
            if sim["dt"] > ds["T"]:
                raise ParameterError("simulation.dt", sim["dt"], f"the integration step must not "
                                     f"be longer than the controller's sampling period design.T "
                                     f"({ds['T']:g} s); give dt ≤ T (omit it for dt = T)")
        if "engine" in sim:    # not set: "phasor", and the key of every cached run stays
            from ..sim.emt import ENGINES

            _choice(sim, "engine", "simulation", ENGINES)
        if "gti_power" in sim:
            _choice(sim, "gti_power", "simulation", ("measured", "model"))
        if "dpsim_dt_max" in sim:
            _num(sim, "dpsim_dt_max", "simulation", positive=True)
            if sim["dpsim_dt_max"] > 1e-3:
                raise ParameterError("simulation.dpsim_dt_max", sim["dpsim_dt_max"], "give a "
                                     "DPsim step of at most 1e-3 s (EMT needs a step well "
                                     "below the 50/60 Hz period; 1e-4 s is the default)")
        if "drop_saturation" in sim and not isinstance(sim["drop_saturation"], bool):
            raise ParameterError("simulation.drop_saturation", sim["drop_saturation"],
                                 "give true (run saturated machines unsaturated in DPsim) or "
                                 "false (refuse them)")
        if "tol" in sim:
            _num(sim, "tol", "simulation", positive=True)
            if not 1e-13 <= sim["tol"] <= 1e-4:
                raise ParameterError("simulation.tol", sim["tol"], "give a Newton tolerance "
                                     "between 1e-13 and 1e-4 pu (omit it for the simulator's "
                                     "default, scaled with the step)")
    ct = d.setdefault("controllers", {})
    ct.setdefault("compare", F.default("controllers", "compare"))
    from .controllers import CONTROLLER_KINDS

    if not isinstance(ct["compare"], list) or not ct["compare"]:
        raise ParameterError("controllers.compare", ct["compare"], "give a list of controllers")
    for c in ct["compare"]:
        check_file_name(c, "controllers.compare")
        kind = ct.get(c, {}).get("kind", c) if isinstance(ct.get(c), dict) else c
        if kind not in CONTROLLER_KINDS:
            raise ParameterError("controllers.compare", c, f"unknown controller; choose from "
                                 f"{sorted(CONTROLLER_KINDS)} or define [controllers.{c}] "
                                 "with kind = \"file\", path = …")
    scs = _need(d, "scenarios", "study file", list)
    seen = set()
    loads = Study(d, source, base_dir).loads
    for i, sc in enumerate(scs):
        w = f"scenarios.{i}"
        _keys(sc, F.keys("scenarios"), w)
        sid = check_file_name(_need(sc, "id", w, str), f"{w}.id")
        if sid in seen:
            raise ParameterError(f"{w}.id", sid, "scenario ids must be unique")
        seen.add(sid)
        w = f"scenarios.{sid}"
        sc.setdefault("load", loads[0])
        if sc["load"] not in loads:
            raise ParameterError(f"{w}.load", sc["load"], f"choose one of {loads}")
        sc["upqc"] = _choice(sc, "upqc", w, STRUCTURES, up["structure"])
        if "design_load" in sc and sc["design_load"] not in loads:
            raise ParameterError(f"{w}.design_load", sc["design_load"], f"choose one of {loads} "
                                 "(the load the controllers are designed at)")
        sc["t_end"] = _num(sc, "t_end", w, positive=True)
        step = "simulation.dt" if sim and "dt" in sim else "design.T"
        dt = (sim or {}).get("dt", ds["T"])
        if dt >= sc["t_end"]:
            raise ParameterError(f"{w}.t_end", sc["t_end"], f"the run is not longer than one "
                                 f"integration step ({step} = {dt:g} s); give t_end > {dt:g} s")
        sc.setdefault("controllers", list(ct["compare"]))
        for c in sc["controllers"]:
            if c not in ct["compare"]:
                raise ParameterError(f"{w}.controllers", c, f"not in controllers.compare "
                                     f"{ct['compare']}; add it there")
        evs = sc.setdefault("events", [])
        for j, ev in enumerate(evs):
            _event(ev, f"{w}.events.{j}", sc["t_end"])
        _events_together(evs, w, up, m["name"])
        # bypass: default = the fault windows, computed when used (so that it follows the
        # faults when a field is changed later), see Study.scenarios
        for j, b in enumerate(sc.get("bypass", [])):
            if not (isinstance(b, list) and len(b) == 2 and b[0] < b[1]):
                raise ParameterError(f"{w}.bypass.{j}", b, "give [t_start, t_end] with "
                                     "t_start < t_end (s)")
        q = sc.get("quick")
        if q:
            _keys(q, F.keys("scenarios.quick"), f"{w}.quick")
            if "t_end" in q:
                _num(q, "t_end", f"{w}.quick", positive=True)
            for c in q.get("controllers", []):
                if c not in sc["controllers"]:
                    raise ParameterError(f"{w}.quick.controllers", c, f"not among the "
                                         f"scenario's controllers {sc['controllers']}")
    rp = d.setdefault("report", {})
    _keys(rp, F.keys("report"), "report")
    rp.setdefault("notes", F.default("report", "notes"))
    gens = [gen["name"] for gen in dyn["generator"]]
    if rp.get("speed_of") and g["kind"] not in ("andes", "psse") and rp["speed_of"] not in gens:
        raise ParameterError("report.speed_of", rp["speed_of"], f"no synchronous machine of "
                             f"that name in [[dynamics.generator]]; choose one of {gens} or "
                             "\"\" for no speed panel")
    st = Study(d, source, base_dir)
    _figures(d, st)
    _claims(d)
    _file_controllers(d, st, g, m["name"])
    from .sweep import validate_sweep

    validate_sweep(d, st)
    return st


# the UPQC as a physical device (weakgrid.sim.upqc): power rating, losses, dc link


def _device_fields(up: dict) -> None:
    """Check the ``[upqc]`` device fields (defaults are filled in by the build, which knows the
    structure and the controlled GTI): ``s_rating`` [MVA] > 0, ``chi`` ≥ 0, ``h_dc`` [s] > 0,
    ``t_dc`` [s] > 0, ``r_shunt`` [pu on s_rating] ≥ 0."""
    fixes = {
        "s_rating": ("> 0", "the converters' apparent-power rating in MVA (series and shunt "
                     "each), e.g. the series transformer's rating"),
        "chi": ("≥ 0", "the series converter's loss factor χ of (15), e.g. 0.02"),
        "h_dc": ("> 0", "the dc-link energy at its set-point in seconds of s_rating, e.g. 0.01"),
        "t_dc": ("> 0", "the dc-voltage loop's time constant in s, e.g. 0.02"),
        "r_shunt": ("≥ 0", "the shunt converter's loss resistance in pu on s_rating, e.g. 0.01"),
    }
    for k, (rule, what) in fixes.items():
        if k not in up:
            continue
        v = up[k]
        ok = not isinstance(v, bool) and isinstance(v, (int, float)) and v == v \
            and abs(v) != float("inf") and (v > 0 if rule == "> 0" else v >= 0)
        if not ok:
            raise ParameterError(f"upqc.{k}", v, f"must be a finite number {rule}: {what}")
        up[k] = float(v)


MAX_RATING = 1.0   # pu: the largest series-voltage rating a UPQC can have (the line's voltage)
FIGURE_KEYS = F.keys("figures")


def _load_levels(g) -> list:
    loads = g.get("loads") or {}
    if g["kind"] != "inline":
        loads = loads.get("levels") or {} if isinstance(loads, dict) else {}
    return list(loads) if isinstance(loads, dict) else []


def _figures(d, study):
    """``[[figures]]``: known keys, a file-name id, known panels and runs of this study."""
    from .figures import PANELS

    figs = d.setdefault("figures", [])
    if not isinstance(figs, list):
        raise ParameterError("figures", figs, "give [[figures]] tables")
    runs = {f"{sc['id']}-{c}" for sc in d["scenarios"] for c in sc["controllers"]}
    seen = set()
    for i, f in enumerate(figs):
        w = f"figures.{i}"
        _keys(f, FIGURE_KEYS, w)
        fid = check_file_name(_need(f, "id", w, str), f"{w}.id")
        if fid in seen:
            raise ParameterError(f"{w}.id", fid, "figure ids must be unique (each is a file "
                                 "name)")
        seen.add(fid)
        _need(f, "title", w, str)
        for k in _need(f, "panels", w, list):
            if k not in PANELS:
                raise ParameterError(f"{w}.panels", k, f"no such panel; choose from "
                                     f"{sorted(PANELS)}")
        for j, r in enumerate(_need(f, "runs", w, list)):
            if not (isinstance(r, list) and len(r) == 2 and all(isinstance(x, str) for x in r)):
                raise ParameterError(f"{w}.runs.{j}", r, "give [run id, legend label]")
            if r[0] not in runs:
                raise ParameterError(f"{w}.runs.{j}", r[0], f"no run of that id in this study "
                                     f"(run id = scenario id-controller); runs: {sorted(runs)}")


def _claims(d):
    """``[[claims]]``: a known judge with exactly the parameters it takes."""
    import inspect

    from .claims import RULES

    claims = d.setdefault("claims", [])
    if not isinstance(claims, list):
        raise ParameterError("claims", claims, "give [[claims]] tables")
    for i, c in enumerate(claims):
        w = f"claims.{i}"
        if not isinstance(c, dict):
            raise ParameterError(w, c, "must be a table [[claims]]")
        judge = _choice(c, "judge", w, sorted(RULES))
        for k in ("id", "paper", "rule"):
            _need(c, k, w, str)
        params = inspect.signature(RULES[judge]).parameters
        _keys(c, F.keys("claims") | (set(params) - {"m", "step_unc"}), w)
        for k, p in params.items():
            if k not in ("m", "step_unc") and p.default is inspect.Parameter.empty and k not in c:
                raise ParameterError(f"{w}.{k}", None, f"missing; the judge '{judge}' needs it")


def _file_controllers(d, study, g, machine):
    """Controllers of kind ``file``: the file exists and was trained for this kind of machine."""
    ct = d["controllers"]
    kinds = {gen["name"]: "sg" for gen in d["dynamics"]["generator"]}
    kinds.update({gt["name"]: "gti" for gt in d["dynamics"]["gti"]})
    for c in ct["compare"]:
        o = ct.get(c)
        if not (isinstance(o, dict) and o.get("kind") == "file"):
            continue
        path = _need(o, "path", f"controllers.{c}", str)
        from ..models import load_controller

        p = study.resolve(path)
        if not p.is_file() and study.base_dir is None:
            continue     # a study made in Python: the path is read when the controller is built
        if not p.is_file():
            raise ParameterError(f"controllers.{c}.path", path, f"no such file ({p}); give a "
                                 "controller file written by `weakgrid train` or `design`")
        ctl = load_controller(p)
        theirs = getattr(ctl.system, "machine", None)
        ours = kinds.get(machine)
        if theirs and ours and theirs != ours:
            raise ParameterError(f"controllers.{c}.path", path, f"the controller was trained for "
                                 f"a {theirs.upper()} but machine.name = '{machine}' is a "
                                 f"{ours.upper()}; train one for this study (`weakgrid design`)")


def _events_together(evs, w, up, machine=None):
    """Events of one scenario: no two faults at one bus at the same time, no trip of the
    UPQC's own branch, no trip of the controlled ``machine``."""
    faults = sorted((ev["t_on"], ev["t_off"], j, ev["bus"]) for j, ev in enumerate(evs)
                    if ev["kind"] == "fault")
    for a, (t0, t1, j, bus) in enumerate(faults):
        for u0, u1, k, bus2 in faults[a + 1:]:
            if bus2 == bus and u0 < t1:
                raise ParameterError(f"{w}.events.{max(j, k)}.t_on", u0, f"overlaps the fault "
                                     f"events.{min(j, k)} at bus {bus} ({t0:g}-{t1:g} s); give "
                                     "one fault, or let the second start after the first "
                                     "is cleared")
    own = {v for v in (up.get("branch"), (up.get("insert") or {}).get("name"), up.get("name"))
           if isinstance(v, (str, int)) and not isinstance(v, bool)}
    for j, ev in enumerate(evs):
        if ev["kind"] == "gen_trip" and ev["machine"] == machine:
            raise ParameterError(f"{w}.events.{j}.machine", ev["machine"], "is the study's "
                                 "controlled machine (machine.name): its controller would act "
                                 "on a disconnected unit; trip another machine")
        if ev["kind"] == "line_trip" and (ev["branch"] == up.get("branch") or (
                isinstance(ev["branch"], (str, int)) and ev["branch"] in own)):
            raise ParameterError(f"{w}.events.{j}.branch", ev["branch"], "is the UPQC's own "
                                 "series branch: tripping it disconnects the UPQC; trip "
                                 "another branch")


def _event(ev, w, t_end):
    kind = _choice(ev, "kind", w, EVENT_KINDS)
    if kind == "fault":
        _keys(ev, F.keys("events.fault"), w)
        _need(ev, "bus", w, (int, str))
        t_on = _num(ev, "t_on", w, nonneg=True)
        if "duration" in ev and "t_off" in ev:
            raise ParameterError(f"{w}.duration", ev["duration"], f"t_off ({ev['t_off']!r}) is "
                                 "given too; give t_off or duration, not both")
        if "duration" in ev:      # t_off from the duration (the duration is not kept)
            ev["t_off"] = t_on + _num(ev, "duration", w, positive=True)
            del ev["duration"]
        t_off = _num(ev, "t_off", w)
        if not t_on < t_off <= t_end:
            raise ParameterError(f"{w}.t_off", t_off, f"need t_on ({t_on}) < t_off ≤ t_end "
                                 f"({t_end})")
        ev["rf"] = _num(ev, "rf", w, F.default("events.fault", "rf"), nonneg=True)
        ev["xf"] = _num(ev, "xf", w, F.default("events.fault", "xf"), nonneg=True)
        if ev["rf"] == 0 and ev["xf"] == 0:
            raise ParameterError(f"{w}.xf", 0.0, "a fault needs a non-zero impedance (rf or xf)")
    elif kind == "line_trip":
        _keys(ev, F.keys("events.line_trip"), w)
        _need(ev, "branch", w, (int, str, dict))
        _num(ev, "t", w, nonneg=True)
        if ev["t"] >= t_end:
            raise ParameterError(f"{w}.t", ev["t"], f"after the run's end (t_end = {t_end}); "
                                 "give t < t_end")
    elif kind == "gen_trip":
        _keys(ev, F.keys("events.gen_trip"), w)
        _need(ev, "machine", w, str)
        _num(ev, "t", w, nonneg=True)
        if ev["t"] >= t_end:
            raise ParameterError(f"{w}.t", ev["t"], f"after the run's end (t_end = {t_end}); "
                                 "give t < t_end")
    else:
        _keys(ev, F.keys("events.load_step"), w)
        _need(ev, "bus", w, (int, str))
        _num(ev, "t", w, nonneg=True)
        if ev["t"] >= t_end:
            raise ParameterError(f"{w}.t", ev["t"], f"after the run's end (t_end = {t_end}); "
                                 "give t < t_end")
        ev["dP"] = _num(ev, "dP", w, F.default("events.load_step", "dP"))
        ev["dQ"] = _num(ev, "dQ", w, F.default("events.load_step", "dQ"))


def _inline_grid(g):
    """Types and ranges of an inline grid's tables (the simulator checks the physics)."""
    def whole(d, key, w, lo=None):
        v = _need(d, key, w)
        if isinstance(v, bool) or not isinstance(v, int) or (lo is not None and v < lo):
            raise ParameterError(f"{w}.{key}", v, "must be a whole number"
                                 + (f" ≥ {lo}" if lo is not None else ""))
        return v

    def ref(d, key, w):
        v = _need(d, key, w)
        if isinstance(v, bool) or not isinstance(v, (int, str)):
            raise ParameterError(f"{w}.{key}", v, "give a bus number or a bus name")

    for i, b in enumerate(g["bus"]):
        w = f"grid.bus.{i}"
        if not isinstance(b, dict):
            raise ParameterError(w, b, "must be a table [[grid.bus]] with id, type, base_kv")
        whole(b, "id", w, lo=0)
        if b.get("type", 1) not in (1, 2, 3):
            raise ParameterError(f"{w}.type", b.get("type"), "1 (PQ), 2 (PV) or 3 (slack)")
        _num(b, "base_kv", w, 1.0, positive=True)
    for level, table in (g.get("loads") or {}).items():
        if not isinstance(table, dict):
            raise ParameterError(f"grid.loads.{level}", table, "must be a table: "
                                 "BUS = [P_MW, Q_Mvar]")
        for bus, pq in table.items():
            w = f"grid.loads.{level}.{bus}"
            if not (isinstance(pq, list) and len(pq) == 2):
                raise ParameterError(w, pq, "give [P_MW, Q_Mvar]")
            for k, v in enumerate(pq):
                _num({"PQ"[k]: v}, "PQ"[k], w)
    for i, gg in enumerate(g["gen"]):
        w = f"grid.gen.{i}"
        if not isinstance(gg, dict):
            raise ParameterError(w, gg, "must be a table [[grid.gen]]")
        ref(gg, "bus", w)
        for k in ("P_mw", "Q_mvar"):
            _num(gg, k, w, 0.0)
        _num(gg, "V_set", w, 1.0, positive=True)
        _num(gg, "Mbase", w, 100.0, positive=True)
    for i, br in enumerate(g["branch"]):
        w = f"grid.branch.{i}"
        if not isinstance(br, dict):
            raise ParameterError(w, br, "must be a table [[grid.branch]]")
        for k in ("from", "to"):
            whole(br, k, w, lo=0)
        for k in ("r", "x"):
            _num(br, k, w)
        for k in ("b", "tap", "shift"):
            _num(br, k, w, 0.0)
