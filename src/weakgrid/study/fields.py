"""The study file's fields, declared once: what the validator accepts and fills in, and what the
reference page and the JSON Schema say.

Every table of a study file is a :class:`Table` of :class:`Field` s: name, JSON type, unit,
default, allowed values, meaning. The validator (:mod:`weakgrid.study.studyfile`,
:mod:`weakgrid.study.grid_edits`, :mod:`weakgrid.study.sweep`) takes each table's allowed
keys (:func:`keys`) and defaults (:func:`default`) from here;
:mod:`weakgrid.study.reference` renders the tables as ``docs/study-file-reference.md`` and
as the JSON Schema ``weakgrid/data/study.schema.json`` (``weakgrid schema``). The validator
checks more than the schema can say (cross references: a scenario's controllers among
``controllers.compare``, a bus of the grid, a fault's ``t_on < t_off ≤ t_end``); the schema
lets an editor complete and check a file's shape while it is typed.

Allowed values that come from a registry (presets, controller kinds, figure panels, claim
judges, sweep map kinds) are callables, read when asked for (:func:`choices_of`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["Field", "Table", "TABLES", "NO_DEFAULT", "keys", "default", "table", "choices_of",
           "EVENT_TABLES", "grid_keys", "Said"]


class _NoDefault:
    def __repr__(self):
        return "NO_DEFAULT"


NO_DEFAULT = _NoDefault()


class Said(str):
    """A default described in words (it depends on the rest of the study), not a value."""

S = {"type": "string"}
N = {"type": "number"}
I = {"type": "integer"}          # noqa: E741
B = {"type": "boolean"}
T = {"type": "object"}
REF = {"type": ["integer", "string"]}          # a bus: its number or its name
LS = {"type": "array", "items": S}
LN = {"type": "array", "items": N}


@dataclass(frozen=True)
class Field:
    """One field of a study-file table.

    Attributes
    ----------
    name : str
        The key in the TOML table.
    schema : dict
        Its JSON Schema (type, and ``minimum``/``exclusiveMinimum``/``maximum`` where the
        validator checks a range).
    doc : str
        What it means (one or two sentences).
    unit : str
        Its unit (``s``, ``pu``, ``MW``, ...; ``""`` for none).
    default : object
        The value the validator fills in (``NO_DEFAULT``: none; the field is optional unless
        ``required``).
    required : bool
        The validator refuses a table without it.
    choices : tuple or callable
        Allowed values (a callable: read from a registry when asked).
    kinds : tuple
        ``[grid]`` only: the grid kinds the field belongs to (empty: every kind).
    required_for : tuple
        ``[grid]`` only: the grid kinds that require it.
    more : str
        Values allowed beside ``choices`` (said in words; the schema then lists none).
    """

    name: str
    schema: dict
    doc: str
    unit: str = ""
    default: object = NO_DEFAULT
    required: bool = False
    choices: object = ()
    kinds: tuple = ()
    required_for: tuple = ()
    more: str = ""


@dataclass(frozen=True)
class Table:
    """A table of a study file: ``path`` (dotted, e.g. ``"upqc.insert"``; an array of tables
    ``[[path]]`` when ``array``), its fields, whether keys beyond them are accepted (``open``:
    their meaning is given by ``extra``), and an example (TOML)."""

    path: str
    doc: str
    fields: tuple
    array: bool = False
    open: bool = False
    extra: dict = field(default_factory=dict)     # JSON Schema of the other keys (open tables)
    example: str = ""


def _presets():
    from ..models import preset_names

    return tuple(preset_names())


def _grid_models():
    from ..design.derive import GRID_MODELS

    return GRID_MODELS


def _engines():
    from ..sim.emt import ENGINES

    return ENGINES


def _controller_kinds():
    from .controllers import CONTROLLER_KINDS

    return tuple(sorted(CONTROLLER_KINDS))


def _panels():
    from .figures import PANELS

    return tuple(sorted(PANELS))


def _judges():
    from .claims import RULES

    return tuple(sorted(RULES))


def _map_kinds():
    from .sweep_maps import MAP_KINDS

    return tuple(MAP_KINDS)


def _edits():
    from .grid_edits import EDITS

    return EDITS


def choices_of(f: Field) -> tuple:
    """The allowed values of field ``f`` (a registry read now, for a callable)."""
    return tuple(f.choices()) if callable(f.choices) else tuple(f.choices)


GRID_KINDS = ("inline", "pandapower", "matpower", "andes", "psse")
STRUCTURES = ("conventional", "reduced")
EVENT_KINDS = ("fault", "line_trip", "load_step", "gen_trip")

_EDIT_LIST = {"type": "array", "items": T}

TABLES: dict[str, Table] = {}


def _add(t: Table) -> None:
    TABLES[t.path] = t


# ------------------------------------------------------------------------------ [study]
_add(Table("study", "What the study is.", (
    Field("name", S, "The study's name (a file-name-safe word: it names output files).",
          default=Said("the file's stem")),
    Field("title", S, "A title for the report.", default=""),
    Field("reproduce", B, "Part of `weakgrid reproduce` (the paper's studies).", default=False),
    Field("notes", LS, "Paragraphs of the study's own notes (in the report).", default=[]),
    Field("description", S, "A longer description (free text)."),
), example='[study]\nname = "my-study"\ntitle = "SG 3 behind a UPQC"'))

# ------------------------------------------------------------------------------ [grid]
_add(Table("grid", "The grid: where it comes from (`kind`) and how it is edited. Fields belong "
           "to the kinds named beside them. Buses are referred to anywhere in a study by the "
           "source's number or name.", (
    Field("kind", S, "Where the grid comes from.", required=True, choices=GRID_KINDS),
    Field("network", S, "A function of `pandapower.networks` (e.g. `case9`, "
          "`create_cigre_network_mv`), or `from_json` with `file`.", kinds=("pandapower",),
          required_for=("pandapower",)),
    Field("kwargs", T, "Keyword arguments of the `pandapower.networks` function.",
          kinds=("pandapower",)),
    Field("keep_buses", S, "A regular expression: the buses (by name) kept, the others "
          "dropped with their elements.", kinds=("pandapower",)),
    Field("islanded", B, "Drop the external grid (an islanded network).", default=False,
          kinds=("pandapower",)),
    Field("file", S, "The case file, relative to the study file: MATPOWER `.m`; ANDES "
          "`.xlsx`/`.json`/`.raw` or `andes:` + a path in ANDES's stock cases; pandapower: the "
          "`.json` of `pandapower.to_json` (with `network = \"from_json\"`).",
          kinds=("pandapower", "matpower", "andes"), required_for=("matpower", "andes")),
    Field("raw", S, "The PSS/E `.raw` file (v29-35), relative to the study file.",
          kinds=("psse",), required_for=("psse",)),
    Field("dyr", S, "The PSS/E dynamic data (`.dyr`), relative to the study file (ANDES: "
          "`andes:` + a stock case path too); the machines and controls then come from it.",
          kinds=("psse", "andes")),
    Field("loads", T, "Load levels. inline: `[grid.loads.LEVEL]` with `\"BUS\" = [P_MW, "
          "Q_Mvar]`; other kinds: `levels = {LEVEL = scale}` (every load scaled) and "
          "optionally `pf = {LOAD NAME = power factor}`.", kinds=("inline", "pandapower",
                                                                   "matpower", "andes")),
    Field("Sb_mva", {**N, "exclusiveMinimum": 0}, "System base of an inline grid.", unit="MVA",
          default=100.0, kinds=("inline",)),
    Field("f_hz", {**N, "exclusiveMinimum": 0}, "Nominal frequency (inline: default 60).",
          unit="Hz"),
    Field("bus", {"type": "array", "items": T}, "`[[grid.bus]]` `id`, `name`, `type` (1 PQ, "
          "2 PV, 3 slack), `base_kv`.", kinds=("inline",), required_for=("inline",)),
    Field("branch", {"type": "array", "items": T}, "`[[grid.branch]]` `name`, `from`, `to`, "
          "`r`, `x`, `b`, `tap`, `shift` (pu on `Sb_mva`).", kinds=("inline",),
          required_for=("inline",)),
    Field("gen", {"type": "array", "items": T}, "`[[grid.gen]]` `name`, `bus`, `P_mw`, "
          "`Q_mvar`, `V_set`, `Mbase`.", kinds=("inline",), required_for=("inline",)),
    Field("add_bus", _EDIT_LIST, "Grid edit: `[[grid.add_bus]]` (below).",
          kinds=GRID_KINDS[1:]),
    Field("sgen_to_gen", _EDIT_LIST, "Grid edit: `[[grid.sgen_to_gen]]` (below; not "
          "MATPOWER).", kinds=("pandapower", "andes", "psse")),
    Field("add_impedance", _EDIT_LIST, "Grid edit: `[[grid.add_impedance]]` (below).",
          kinds=GRID_KINDS[1:]),
    Field("add_gen", _EDIT_LIST, "Grid edit: `[[grid.add_gen]]` (below).",
          kinds=GRID_KINDS[1:]),
), example='[grid]\nkind = "andes"\nfile = "andes:ieee39/ieee39_full.xlsx"'))

_add(Table("grid.add_bus", "A new PQ bus without load (grid edits, applied in the order "
           "add_bus, sgen_to_gen, add_impedance, add_gen, before the power flow; every kind "
           "but inline).", (
    Field("name", S, "The new bus's name (refer to it by this name).", required=True),
    Field("vn_kv", {**N, "exclusiveMinimum": 0}, "Its nominal voltage.", unit="kV",
          required=True),
    Field("number", {**I, "minimum": 1}, "Its number.", default=Said("one above the grid's largest")),
), array=True, example='[[grid.add_bus]]\nname = "PV"\nvn_kv = 135.0'))

_add(Table("grid.sgen_to_gen", "A static generator becomes a voltage-controlled generator "
           "whose dynamics the study gives (e.g. a GTI): pandapower's `net.sgen` by name; on "
           "ANDES/PSS/E grids a generator without a dynamic model (`PV_<idx>`, "
           "`PVSource_<bus>_<id>`).", (
    Field("name", S, "The static generator's name.", required=True),
    Field("bus", REF, "Move it to this bus.", default=Said("its own bus")),
    Field("vm_pu", {**N, "exclusiveMinimum": 0.5, "exclusiveMaximum": 1.5},
          "Its voltage set point.", unit="pu", default=1.0),
    Field("scale", N, "Scale its power.", default=1.0),
), array=True, example='[[grid.sgen_to_gen]]\nname = "WKA 7"\nbus = "Bus WT"'))

_add(Table("grid.add_impedance", "A new series branch (a line, or a transformer with `tap`); "
           "a pi model with the ideal transformer at the `from` end (MATPOWER's and PSS/E's "
           "convention; pandapower: a transformer for `tap` ≠ 1 and two shunts for `b`).", (
    Field("name", S, "The branch's name (a UPQC's `branch` can name it).",
          default=Said("\"impedance J\", J its position in the list")),
    Field("from", REF, "From bus (the tap's end).", required=True),
    Field("to", REF, "To bus.", required=True),
    Field("r_pu", N, "Series resistance.", unit="pu on sn_mva", required=True),
    Field("x_pu", N, "Series reactance (r_pu and x_pu not both 0).", unit="pu on sn_mva",
          required=True),
    Field("sn_mva", {**N, "exclusiveMinimum": 0}, "The base of r_pu, x_pu and b.", unit="MVA",
          required=True),
    Field("b", N, "Total shunt susceptance (half at each end).", unit="pu on sn_mva",
          default=0.0),
    Field("tap", {**N, "minimum": 0.5, "maximum": 1.5}, "Off-nominal ratio at the from end.",
          unit="pu", default=1.0),
), array=True, example='[[grid.add_impedance]]\nname = "PV transformer"\nfrom = "5"\n'
                       'to = "PV"\nsn_mva = 100.0\nr_pu = 0.005\nx_pu = 0.05\ntap = 1.02'))

_add(Table("grid.add_gen", "A new generator row of the power flow (its bus becomes "
           "voltage-controlled); its dynamics come from `[[dynamics.generator]]` or "
           "`[[dynamics.gti]]` at that bus.", (
    Field("name", S, "The generator's name.", required=True),
    Field("bus", REF, "Its bus.", required=True),
    Field("p_mw", {"type": ["number", "object"]}, "Its active power: a number or a table "
          "of one value per load level.", unit="MW", default=0.0),
    Field("vm_pu", {**N, "exclusiveMinimum": 0.5, "exclusiveMaximum": 1.5},
          "Its voltage set point.", unit="pu", default=1.0),
    Field("sn_mva", {**N, "exclusiveMinimum": 0}, "Its rating.", unit="MVA",
          default=Said("the system base")),
    Field("slack", B, "It is the slack.", default=False),
), array=True, example='[[grid.add_gen]]\nname = "PV"\nbus = "PV"\np_mw = 30.0'))

# ------------------------------------------------------------------------------ [dynamics]
_add(Table("dynamics", "The grid's dynamic models (pandapower, MATPOWER, inline grids; "
           "ANDES and PSS/E grids bring their own from their files).", (
    Field("generator", {"type": "array", "items": T}, "`[[dynamics.generator]]` (below).",
          default=[]),
    Field("gti", {"type": "array", "items": T}, "`[[dynamics.gti]]` (below).", default=[]),
)))

_MODEL = {"type": "object", "required": ["model"], "properties": {"model": S}}
_add(Table("dynamics.generator", "A synchronous machine and its controls at a generator bus. "
           "Each part is `{model = NAME, PARAMETER = value, ...}` with ANDES's parameter "
           "names (see the simulator's model reference).", (
    Field("name", S, "Its name (`machine.name`, `report.speed_of`, `gen_trip` events refer "
          "to it).", required=True),
    Field("bus", REF, "Its bus (the generator row there).", required=True),
    Field("machine", _MODEL, "The machine: `GENCLS`, `GENROU`, ... and its parameters.",
          required=True),
    Field("exciter", _MODEL, "Its exciter (`SEXS`, `IEEEX1`, ...)."),
    Field("governor", _MODEL, "Its governor (`TGOV1`, ...)."),
    Field("pss", _MODEL, "Its stabilizer (`IEEEST`, ...)."),
), array=True, example='[[dynamics.generator]]\nname = "G1"\nbus = "1"\nmachine = { model = '
                       '"GENCLS", Sn = 100.0, fn = 60.0, M = 10.0, D = 0.0, ra = 0.0, '
                       'xd1 = 0.2 }'))

_POS = {**N, "exclusiveMinimum": 0}
_add(Table("dynamics.gti", "A grid-tie inverter with its dc link at a generator bus (pu on "
           "the system base).", (
    Field("name", S, "Its name.", required=True),
    Field("bus", REF, "Its bus (the generator row there).", required=True),
    Field("mode", S, "Its own control: dc-link energy, or PQ (PID).", default="energy",
          choices=("energy", "pq")),
    Field("ref_bus", REF, "The bus whose voltage angle it follows."),
    Field("C", _POS, "dc-link capacitance.", unit="pu·s", required=True),
    Field("Vc0", _POS, "dc-link voltage set point.", unit="pu", required=True),
    Field("chi", N, "dc-link losses.", unit="pu"),
    Field("B", _POS, "Coupling susceptance (filter).", unit="pu", required=True),
    Field("ks_max", N, "Largest modulation index.", unit="–"),
    Field("tau", N, "Phase-control gain τ.", unit="1/(pu·s)", required=True),
    *(Field(k, N, f"PQ-mode PID gain {k}.") for k in ("kp_p", "ki_p", "kd_p", "kp_q", "ki_q",
                                                      "kd_q")),
    Field("Td", N, "PQ-mode derivative filter time constant.", unit="s"),
    Field("kp_v", N, "dc-voltage PI gain (proportional)."),
    Field("ki_v", N, "dc-voltage PI gain (integral)."),
), array=True, example='[[dynamics.gti]]\nname = "PV"\nbus = "PV"\nC = 0.05\nVc0 = 1.0\n'
                       'chi = 0.02\nB = 4.0\nks_max = 1.5\ntau = 47.3'))

# ------------------------------------------------------------------------------ machine, UPQC
_add(Table("machine", "The controlled machine.", (
    Field("name", S, "A `[[dynamics.generator]]`/`[[dynamics.gti]]` name, or an imported "
          "grid's machine (ANDES `GENROU_3`, PSS/E `GENROU_<bus>_<id>`).", required=True),
), example='[machine]\nname = "G3"'))

_add(Table("upqc", "The UPQC: on an existing series branch (`branch`, from = its shunt bus) "
           "or inserted into one (`insert`); exactly one of them.", (
    Field("name", S, "Its name.", default="UPQC"),
    Field("branch", {"type": ["string", "integer", "object"]}, "The series branch: a name, "
          "a row, or `{from = SHUNT BUS, to = BUS}`."),
    Field("side", S, "The shunt bus's end of `branch`.", default="from", choices=("from",
                                                                                 "to")),
    Field("insert", T, "`[upqc.insert]` (below)."),
    Field("structure", S, "Conventional (own dc link) or reduced (fed from the machine's dc "
          "link).", default="conventional", choices=STRUCTURES),
    Field("rating", {**N, "exclusiveMinimum": 0, "maximum": 1.0}, "Largest series-voltage "
          "magnitude |Vu|max.", unit="pu", default=0.2),
    Field("s_rating", {**N, "exclusiveMinimum": 0}, "Apparent-power rating of each converter "
          "(series and shunt); maps mark cells where the device's power exceeds it.",
          unit="MVA", default=Said("insert.sn_mva")),
    Field("chi", {**N, "minimum": 0}, "Series converter's loss factor χ of (15): the dc side "
          "carries P + χ|P|.", default=Said("reduced: the controlled GTI's chi; else 0")),
    Field("h_dc", {**N, "exclusiveMinimum": 0}, "Conventional structure: the dc-link energy at "
          "its set point in seconds of s_rating.", unit="s", default=0.01),
    Field("t_dc", {**N, "exclusiveMinimum": 0}, "Conventional structure: time constant of the "
          "dc-voltage loop.", unit="s", default=0.02),
    Field("r_shunt", {**N, "minimum": 0}, "Conventional structure: the shunt converter's loss "
          "resistance.", unit="pu on s_rating", default=0.0),
), example='[upqc]\nbranch = { from = "5", to = "PV" }\nstructure = "reduced"\nrating = 0.15'))

_add(Table("upqc.insert", "A new series branch (the series transformer) put into an existing "
           "branch at one end.", (
    Field("element", S, "pandapower: the element table (`line`, `trafo`)."),
    Field("index", I, "pandapower: the element's index."),
    Field("name", S, "The element's name."),
    Field("branch", {"type": ["string", "integer"]}, "MATPOWER/ANDES/PSS/E: the branch (name "
          "or row)."),
    Field("side", S, "The end the UPQC goes at.", required=True, choices=("from", "to")),
    Field("r", N, "Series resistance of the inserted branch.", unit="pu", default=0.0),
    Field("x", _POS, "Series reactance of the inserted branch.", unit="pu", required=True),
    Field("sn_mva", _POS, "The base of r and x.", unit="MVA"),
), example='[upqc.insert]\nbranch = "Line_37"\nside = "from"\nx = 0.01'))

# ------------------------------------------------------------------------------ design
_add(Table("design", "The design of the controllers (the design model (10) and the game).", (
    Field("T", _POS, "Sampling period of the digital controller.", unit="s", required=True),
    Field("settings", S, "The preset giving Q, R, P, γ, Ω, mesh, basis, initial policy.",
          default="case1-paper", choices=_presets),
    Field("cost", T, "Override the preset's cost (Q, R, P, γ)."),
    Field("mesh", T, "Override the preset's mesh (Ω)."),
    Field("basis", T, "Override the preset's basis."),
    Field("initial_policy", T, "Override the preset's initial policy."),
    Field("solver", T, "Override the preset's solver settings."),
    Field("load", S, "The load level the controllers are designed at.",
          default=Said("the first level")),
    Field("grid_model", S, "The design model's grid: the paper's stiff shunt-bus voltage, or "
          "the grid's Thevenin equivalent at the shunt bus r with the two-machine inertia "
          "factor (both are derived and both mode checks printed).", default="paper",
          choices=_grid_models),
), example='[design]\nT = 1.0e-3\nsettings = "case2-paper"'))

_add(Table("controllers", "The controllers compared; `[controllers.NAME]` tables give a "
           "controller's options (`kind`, and `gain`, `phase` for nonlinear-29; `Q`, `R` for "
           "lqr; `u_bound` for hji-bounded; `path` for kind = \"file\").", (
    Field("compare", {**LS, "minItems": 1}, "The controllers of every scenario (a kind, or a "
          "name with a `[controllers.NAME]` table).", default=["hji", "lqr", "pss-only"],
          choices=_controller_kinds, more="a NAME with a [controllers.NAME] table"),
), open=True, extra=T, example='[controllers]\ncompare = ["hji", "lqr", "pss-only", "none"]'))

# ------------------------------------------------------------------------------ scenarios
_add(Table("scenarios", "A scenario: an operating point and its events; run once per "
           "controller (run id = `<id>-<controller>`).", (
    Field("id", S, "Its id (a file-name-safe word).", required=True),
    Field("description", S, "Free text."),
    Field("load", S, "The load level.", default=Said("the first level")),
    Field("upqc", S, "The UPQC structure.", default=Said("upqc.structure"), choices=STRUCTURES),
    Field("design_load", S, "The load the controllers are designed at.",
          default=Said("the scenario's load")),
    Field("t_end", _POS, "Simulated time.", unit="s", required=True),
    Field("controllers", LS, "The controllers run (among `controllers.compare`).",
          default=Said("controllers.compare")),
    Field("events", {"type": "array"}, "The events (inline tables, below, by `kind`).",
          default=[]),
    Field("bypass", {"type": "array", "items": LN}, "Windows `[t_start, t_end]` [s] in which "
          "the UPQC is bypassed.", unit="s", default=Said("the fault windows")),
    Field("quick", T, "`--quick` settings: `{t_end, controllers}`; a scenario without is "
          "left out of a quick run."),
), array=True, example='[[scenarios]]\nid = "fault-r"\nt_end = 5.0\nevents = [{ kind = '
                       '"fault", bus = "6", t_on = 1.0, duration = 0.1, xf = 0.02 }]\n'
                       'quick = { t_end = 3.0, controllers = ["lqr", "pss-only"] }'))

_add(Table("scenarios.quick", "A scenario's `--quick` settings.", (
    Field("t_end", _POS, "Simulated time.", unit="s", default=Said("the scenario's")),
    Field("controllers", LS, "The controllers run (among the scenario's).",
          default=Said("the scenario's")),
)))

_add(Table("events.fault", "`kind = \"fault\"`: a three-phase fault to ground through "
           "rf + j·xf, from t_on to t_off (or for `duration`; give one of them).", (
    Field("kind", {"const": "fault"}, "The event kind.", required=True),
    Field("bus", REF, "The faulted bus.", required=True),
    Field("t_on", {**N, "minimum": 0}, "Fault applied.", unit="s", required=True),
    Field("t_off", N, "Fault cleared (t_on < t_off ≤ t_end).", unit="s"),
    Field("duration", _POS, "Fault duration (t_off = t_on + duration).", unit="s"),
    Field("rf", {**N, "minimum": 0}, "Fault resistance.", unit="pu", default=0.0),
    Field("xf", {**N, "minimum": 0}, "Fault reactance (rf, xf not both 0).", unit="pu",
          default=1e-3),
), example='{ kind = "fault", bus = "6", t_on = 1.0, duration = 0.1, xf = 0.02 }'))

_add(Table("events.line_trip", "`kind = \"line_trip\"`: a branch opens (or closes) at t "
           "(not the UPQC's own).", (
    Field("kind", {"const": "line_trip"}, "The event kind.", required=True),
    Field("branch", {"type": ["string", "integer", "object"]}, "The branch: a name, a row, "
          "or `{from = BUS, to = BUS}`.", required=True),
    Field("t", {**N, "minimum": 0}, "When (t < t_end).", unit="s", required=True),
    Field("close", B, "It closes instead.", default=False),
), example='{ kind = "line_trip", branch = { from = "7", to = "8" }, t = 1.0 }'))

_add(Table("events.load_step", "`kind = \"load_step\"`: constant-impedance load added at a "
           "bus at t.", (
    Field("kind", {"const": "load_step"}, "The event kind.", required=True),
    Field("bus", REF, "The bus.", required=True),
    Field("t", {**N, "minimum": 0}, "When (t < t_end).", unit="s", required=True),
    Field("dP", N, "Active power added (at the power-flow voltage).", unit="MW", default=0.0),
    Field("dQ", N, "Reactive power added.", unit="Mvar", default=0.0),
), example='{ kind = "load_step", bus = "Bus 7", t = 0.5, dP = 0.5, dQ = 0.1 }'))

_add(Table("events.gen_trip", "`kind = \"gen_trip\"`: a machine or converter is disconnected "
           "with its controls at t (the simulator's GeneratorTrip; not the controlled "
           "machine).", (
    Field("kind", {"const": "gen_trip"}, "The event kind.", required=True),
    Field("machine", S, "The unit's name (as `machine.name`).", required=True),
    Field("t", {**N, "minimum": 0}, "When (t < t_end).", unit="s", required=True),
), example='{ kind = "gen_trip", machine = "GENROU_5", t = 0.5 }'))

EVENT_TABLES = {k: f"events.{k}" for k in EVENT_KINDS}

# ------------------------------------------------------------------------------ report, figures, claims
_add(Table("report", "The report.", (
    Field("speed_of", S, "The synchronous machine whose speed is drawn and measured (`\"\"`: "
          "none).", default=Said("the controlled SG, else the first generator")),
    Field("notes", LS, "The study's own protocol paragraphs.", default=[]),
), example='[report]\nspeed_of = "G3"'))

_add(Table("figures", "A figure: panels × runs (default: one figure per scenario).", (
    Field("id", S, "Its id (a file name).", required=True),
    Field("title", S, "Its title.", required=True),
    Field("label", S, "A label."),
    Field("panels", LS, "The panels, top to bottom.", required=True, choices=_panels),
    Field("runs", {"type": "array", "items": {"type": "array", "items": S, "minItems": 2,
                                              "maxItems": 2}},
          "`[run id, legend label]` pairs.", required=True),
), array=True, example='[[figures]]\nid = "fig-fault"\ntitle = "Fault at bus 6"\npanels = '
                       '["sg_speed", "vu"]\nruns = [["fault-r-hji", "HJI"], ["fault-r-lqr", '
                       '"LQR"]]'))


def _judge_params() -> tuple:
    import inspect

    from .claims import RULES

    out = {}
    for fn in RULES.values():
        for k in inspect.signature(fn).parameters:
            if k != "m":
                out.setdefault(k, None)
    return tuple(out)


_add(Table("claims", "A claim judged over run ids by a rule (`judge`, "
           "`weakgrid.study.claims.RULES`) with that rule's parameters.", (
    Field("id", S, "Its id.", required=True),
    Field("case", S, "The case it belongs to."),
    Field("paper", S, "What the paper says.", required=True),
    Field("rule", S, "The rule in words.", required=True),
    Field("judge", S, "The rule that judges it.", required=True, choices=_judges),
), array=True, open=True, extra={}, example='[[claims]]\nid = "C1"\npaper = "HJI settles '
                                            'faster"\nrule = "settling(hji) < settling(lqr)"\n'
                                            'judge = "less_overshoot_settling"\npairs = '
                                            '[["fault-r-hji", "fault-r-lqr"]]'))

# ------------------------------------------------------------------------------ sweep, simulation
_add(Table("sweep", "A sweep: axes over any study field × scenarios × controllers "
           "(`weakgrid sweep`, and the report's sweep section).", (
    Field("axes", T, "Dotted study path = list of values (e.g. `\"upqc.rating\" = [0.1, "
          "0.3]`, `\"scenarios.ID.events.0.duration\" = [...]`).", required=True),
    Field("mode", S, "Every combination, or the axes zipped.", default="product",
          choices=("product", "points")),
    Field("scenarios", LS, "The scenarios swept.", default=Said("every scenario")),
    Field("controllers", LS, "The controllers swept.", default=Said("each scenario's")),
    Field("t_end", _POS, "Simulated time of every run.", unit="s"),
    Field("design_load", S, "Controllers designed at this load."),
    Field("signals", LS, "Signals kept per run."),
    Field("quick", T, "`--quick` settings: `{t_end, axes}`."),
    Field("maps", {"type": "array", "items": T}, "`[[sweep.maps]]` (below)."),
    Field("dt_check", T, "Swept path = values run again at half the step (the numerical "
          "uncertainty)."),
), example='[sweep]\naxes = { "upqc.rating" = [0.1, 0.2, 0.3] }\ncontrollers = ["hji", '
           '"lqr"]'))

_add(Table("sweep.maps", "A map of a sweep for a claim.", (
    Field("claim", S, "The claim's id.", required=True),
    Field("id", S, "Its id (a file name).", default=Said("the claim's id")),
    Field("title", S, "Its title."),
    Field("kind", S, "What it draws.", required=True, choices=_map_kinds),
    Field("metric", S, "The metric."),
    Field("metrics", LS, "Metrics (several)."),
    Field("a", S, "Controller a."),
    Field("b", S, "Controller b."),
    Field("holds_below", N, "kind = ratio: the claim holds where a/b ≤ this, and is a tie where a is within the runs' uncertainty of this · b; the map's colour scale is centred on it.", default=1.0),
    Field("holds_within", {**LN, "minItems": 2, "maxItems": 2}, "kind = value: the claim "
          "holds where the value is within `[lo, hi]`."),
    Field("label", S, "Its label."),
    Field("x", S, "Swept path on the x axis."),
    Field("y", S, "Swept path on the y axis."),
    Field("facet", S, "Swept path of the facets."),
), array=True))

_add(Table("simulation", "Numerical settings of every run of the study.", (
    Field("dt", _POS, "Integration step (≤ design.T).", unit="s", default=Said("design.T")),
    Field("tol", {**N, "minimum": 1e-13, "maximum": 1e-4}, "Newton tolerance.", unit="pu",
          default=Said("the simulator's default for dt")),
    Field("record", {**LS, "minItems": 1}, "Signal names or fnmatch patterns the run files "
          "keep (the figures' signals always).", default=Said("every signal")),
    Field("engine", S, "The simulator of every run: weakgrid's phasor engine, or the same grid "
          "in DPsim's electromagnetic transients or dynamic phasors (the extra `weakgrid[emt]`; "
          "its step: the run's step divided into the fewest equal parts of at most dpsim_dt_max; "
          "a model or event DPsim lacks is refused by name before any run; "
          "documentation: Engines).", default="phasor", choices=_engines),
    Field("gti_power", S, "DPsim engines: the ac power a GTI's dc link pays — the power its "
          "DPsim source delivered (energy-consistent), or the GTI model's own power at the "
          "measured voltage (blind to the coupling's current transients; documentation: "
          "Engines).", default="measured", choices=("measured", "model")),
    Field("dpsim_dt_max", {**_POS, "maximum": 1e-3}, "DPsim engines: the longest DPsim step; "
          "the run's step is divided into the fewest equal parts of at most this. EMT needs a "
          "step well below the period; a GTI's dc link through a fault converges at 2e-5 s or "
          "less (documentation: Engines).", unit="s", default=1e-4),
    Field("drop_saturation", B, "DPsim engines: run a GENROU or GENSAL whose data have "
          "saturation (S10 ≠ 0) unsaturated — DPsim's machines have none — instead of refusing "
          "it; the choice is the study's, written in its runs' parameters (documentation: "
          "Engines).", default=False),
    Field("notes", LS, "Notes on the settings."),
), example='[simulation]\nrecord = ["*.omega", "bus*.v"]'))

#: the top-level tables, in the order of a study file
TOP = ("study", "grid", "dynamics", "machine", "upqc", "design", "controllers", "scenarios",
       "report", "figures", "claims", "sweep", "simulation")
#: the top-level tables the validator requires
REQUIRED_TOP = ("grid", "machine", "upqc", "design", "scenarios")


def table(path: str) -> Table:
    """The :class:`Table` at dotted ``path`` (``"upqc"``, ``"grid.add_bus"``,
    ``"events.fault"``)."""
    return TABLES[path]


def keys(path: str) -> set:
    """The field names table ``path`` accepts."""
    return {f.name for f in TABLES[path].fields}


def grid_keys(kind: str) -> set:
    """The ``[grid]`` fields of grid kind ``kind``."""
    return {f.name for f in TABLES["grid"].fields if not f.kinds or kind in f.kinds}


def default(path: str, name: str):
    """The default of field ``name`` of table ``path`` (a fresh copy of a list)."""
    for f in TABLES[path].fields:
        if f.name == name:
            if f.default is NO_DEFAULT or isinstance(f.default, Said):
                raise KeyError(f"{path}.{name} has no default")
            return list(f.default) if isinstance(f.default, list) else f.default
    raise KeyError(f"{path}.{name}")
