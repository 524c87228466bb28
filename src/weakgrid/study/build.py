"""Build a study's grid for the simulator at a load level, UPQC structure and variant.

Grid kinds (``[grid] kind``):

* ``inline`` — buses, branches, generators and loads per level in the study file
  (``[[grid.bus]] id, name, type, base_kv``; ``[[grid.branch]] name, from, to, r, x, b``
  (pu on ``Sb_mva``); ``[[grid.gen]] name, bus, P_mw, Q_mvar, V_set, Mbase``;
  ``[grid.loads.LEVEL] "BUS" = [P_MW, Q_Mvar]``, constant impedance).
* ``pandapower`` — ``network`` names a function of ``pandapower.networks`` (``kwargs``), or
  ``network = "from_json"`` reads ``file`` (the user's network, written by
  ``pandapower.to_json``; path relative to the study file); then in this order: ``keep_buses``
  (regex on bus names; the rest is dropped), ``islanded`` (external grids removed),
  ``loads.levels`` (p_mw multiplier per level) and ``loads.pf`` (power factor by load name),
  then the grid edits.
* ``matpower`` — ``file`` (a ``.m``/``.mat`` case); ``loads.levels`` scale PD, QD.
* ``andes`` — ``file`` (any case ANDES parses: PSS/E ``.raw``, ``.xlsx``, ``.json``; ``andes:``
  prefix for ANDES's stock cases) and ``dyr`` (PSS/E dynamic data): machines and controls come
  from the file (named ``<MODEL>_<idx>``: ``GENROU_4``, kundur's ``GENROU_1``; buses keep their
  integer idx), the UPQC is an existing ``Line`` (``upqc.branch`` =
  its idx; ``upqc.side = "to"`` when its bus2 is the shunt bus) or inserted into one
  (``upqc.insert = {branch = idx, side, r, x}``, pu on the system base).
* ``psse`` — ``raw`` (PSS/E ``.raw``, versions 29-35) and ``dyr`` (optional), paths relative to
  the study file, read by weakgrid's own reader (:func:`weakgrid.sim.io.psse.from_psse`):
  buses keep their PSS/E numbers (a bus is its number, or its name from the ``.raw``), machines
  and controls come from the ``.dyr`` (named ``GENROU_<bus>_<id>`` …), the UPQC is an existing
  branch (``upqc.branch = "I-J-CKT"``, e.g. ``"101-102-1"``, or ``{from, to}``) or inserted into
  one (``upqc.insert = {branch = "I-J-CKT", side, r, x}``, pu on the system base).

Grid edits, the same on every kind but ``inline`` (:mod:`weakgrid.study.grid_edits`):
``add_bus``, ``sgen_to_gen`` (a static generator handed to the study's dynamics, e.g. a wind
turbine that becomes a GTI; ``bus`` moves it), ``add_impedance``, ``add_gen`` (``p_mw`` a number
or a table per level) — applied before the power flow and before the UPQC is inserted.

Buses are referred to by the source's number (inline/matpower/PSS/E, an ANDES idx), by name
(PSS/E ``.raw``, ANDES ``Bus.name``, pandapower, inline), or by pandapower index — which is the
simulator's bus number of a pandapower grid, so results (``bus<number>.v``), events and the
design printout use one numbering. Branches (events, ``upqc.branch``) by the source's names
(PSS/E ``"I-J-CKT"``, ANDES ``Line`` idx, a pandapower element's name or ``"line_3"``, an inline
branch's name), ``{from, to}`` buses, or a 0-based row.
The UPQC is either an existing series branch (``upqc.branch``: a branch name, a row, or
``{from, to}``; from = the shunt bus r) or inserted into a branch (``upqc.insert``, see
:mod:`weakgrid.design.upqc_insert`).
"""

from __future__ import annotations

import contextlib
import copy
import logging
import math
import warnings
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np

from ..design import derive_design
from ..design.upqc_insert import insert_upqc_matpower, insert_upqc_pandapower
from .grid_edits import apply_case_edits, has_edits, per_level
from ..game.errors import ParameterError
from ..hashing import canonical_json
from ..logs import quiet_loggers
from ..sim.errors import DataError, DataWarning
from ..sim.controllers import gti_signals, gti_state_map, mapped, sg_signals, sg_state_map
from ..sim.gti import GTI
from ..sim.network import BR_R, BR_X, F_BUS, GEN_BUS, T_BUS, Network
from ..sim.system import System
from ..sim.upqc import UPQC
from .device import s_rating_mva, upqc_params

__all__ = ["Setup", "build_setup", "baseline_machine", "VARIANTS"]

log = logging.getLogger(__name__)

# "upqc": the UPQC in service (driven by a digital controller, or idle);
# "pq": no UPQC, the controlled GTI's phase by its PQ loops (the conventional baseline);
# "no-pss": the UPQC in service and the baseline machine's stabilizer(s) taken out before the
# initialization (the `none` baseline; :func:`baseline_machine`)
VARIANTS = ("upqc", "pq", "no-pss")


@dataclass
class Setup:
    """A study's grid, set up for simulation at one operating point.

    ``machine`` is "gti" or "sg"; ``source`` the controlled machine; ``measure`` returns the
    design states ``[ϕ̂ (rad), υ (rad/s)]``: ``state_map(measure_signals(...))``, the
    measured signals of the machine mapped by a :mod:`weakgrid.sim.design_states` map (what a
    device computes, exported with the controller); ``design`` the derived model (10) and
    ``derivation`` how it was derived; ``signals`` maps figure keys to result variables.
    """

    study: object
    load: str
    upqc: str
    variant: str
    system: System
    machine: str
    source: str
    upqc_name: str | None
    shunt_bus: int
    upqc_branch: int
    measure: object
    design: object
    derivation: object
    line_power_mw: float
    signals: dict = field(default_factory=dict)
    Sb_mva: float = 100.0
    bus_id: dict = field(default_factory=dict)
    branch_names: dict = field(default_factory=dict)
    measure_signals: object = None
    state_map: object = None
    #: the UPQC converters' rating [MVA] (None: not given; :mod:`weakgrid.study.device`)
    s_rating_mva: float | None = None
    #: the line's apparent power, the product of the magnitudes of V_r and I_line at the
    #: operating point [MVA]
    line_mva: float = float("nan")

    def bus(self, ref, where="bus") -> int:
        """Simulator bus number of a bus reference (the source's number or name; a pandapower
        index); :class:`ParameterError` listing some of the grid's buses if unknown."""
        return _bus_ref(ref, self.bus_id, self.system.network, where)


def _bus_ref(ref, bus_id, network, where):
    """Simulator bus number of a study's bus reference: a bus number of the source (PSS/E,
    MATPOWER, ANDES idx, pandapower index) or a name of the source (``bus_id``: name → number).
    An unknown reference raises :class:`ParameterError` listing some of the grid's buses."""
    if isinstance(ref, str) and ref in bus_id:
        return int(bus_id[ref])
    if isinstance(ref, (int, np.integer)) and not isinstance(ref, bool):
        if ref in bus_id:                      # pandapower index (the simulator bus number)
            return int(bus_id[ref])
        if int(ref) in network._pos:
            return int(ref)
    raise ParameterError(where, ref, f"no such bus in this grid; {bus_choices(bus_id, network)}")


def bus_choices(bus_id, network, n=8) -> str:
    """A few of a grid's bus numbers and names, for an error message."""
    nums = [int(b) for b in network.bus_ids]
    names = [k for k in bus_id if isinstance(k, str) and k != str(bus_id[k])]
    text = f"bus numbers: {nums[:n]}{' …' if len(nums) > n else ''}"
    if names:
        text += f"; names: {names[:n]}{' …' if len(names) > n else ''}"
    elif any(isinstance(k, str) for k in bus_id):
        text += " (also as strings, e.g. \"" + str(nums[0]) + "\")"
    return text


# ----------------------------------------------------------------------------- grids
def _inline_case(g, load, where="grid"):
    loads = g.get("loads", {}).get(load, {}) if g.get("loads") else {}
    bus = []
    ids = []
    for i, b in enumerate(g["bus"]):
        bid = int(b["id"])
        ids.append(bid)
        pd, qd = loads.get(str(bid), loads.get(b.get("name", ""), [0.0, 0.0]))
        bus.append([bid, b.get("type", 1), pd, qd, 0, 0, 1, 1.0, 0, b.get("base_kv", 1.0), 1,
                    1.5, 0.5])
    for k in loads:
        if not any(str(b["id"]) == k or b.get("name") == k for b in g["bus"]):
            raise ParameterError(f"{where}.loads.{load}.{k}", loads[k], "no bus with that id")
    gen = [[gg["bus"], gg.get("P_mw", 0.0), gg.get("Q_mvar", 0.0), 9999, -9999,
            gg.get("V_set", 1.0), gg.get("Mbase", 100.0), 1, 9999, -9999] + [0] * 11
           for gg in g["gen"]]
    branch = [[br["from"], br["to"], br["r"], br["x"], br.get("b", 0.0), 0, 0, 0,
               br.get("tap", 0), br.get("shift", 0), 1, -360, 360] for br in g["branch"]]
    case = {"baseMVA": float(g.get("Sb_mva", 100.0)), "bus": np.array(bus, float),
            "gen": np.array(gen, float), "branch": np.array(branch, float)}
    names = {br.get("name", br.get("role", str(k))): k for k, br in enumerate(g["branch"])}
    bus_id = {b["name"]: int(b["id"]) for b in g["bus"] if "name" in b}
    return case, names, bus_id


def _pandapower_net(g, load, resolve=str):
    """The pandapower network of ``[grid]`` at ``load``, edited; ``resolve`` maps a file name
    of the study to its path. Returns ``(net, bus name → index, bus reference function)``."""
    import pandapower as pp
    import pandapower.networks as pn

    if g["network"] == "from_json":
        return _pandapower_edits(g, load, _pandapower_from_json(g, resolve))
    fn = getattr(pn, g["network"], None)
    if fn is None or not callable(fn):
        raise ParameterError("grid.network", g["network"], "not a function of "
                             "pandapower.networks (e.g. case9, create_cigre_network_mv)")
    kwargs = g.get("kwargs", {})
    if not isinstance(kwargs, dict):
        raise ParameterError("grid.kwargs", kwargs, f"give a table of keyword arguments of "
                             f"pandapower.networks.{g['network']}")
    import inspect

    params = inspect.signature(fn).parameters
    if not any(p.kind is p.VAR_KEYWORD for p in params.values()):
        for k in kwargs:
            if k not in params:
                raise ParameterError(f"grid.kwargs.{k}", kwargs[k], f"not an argument of "
                                     f"pandapower.networks.{g['network']}; its arguments: "
                                     f"{list(params)}")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            net = fn(**kwargs)
        except (ValueError, TypeError, KeyError, NotImplementedError) as exc:
            raise ParameterError("grid.kwargs", kwargs, f"pandapower.networks.{g['network']} "
                                 f"refused them: {exc}") from None
    return _pandapower_edits(g, load, net)


def _pandapower_from_json(g, resolve=str):
    """The user's pandapower network: ``[grid] network = "from_json"``, ``file`` (written by
    ``pandapower.to_json``; the path resolved against the study file by the validator)."""
    import pandapower as pp

    path = g.get("file")
    if not path:
        raise ParameterError("grid.file", None, 'network = "from_json" needs file = "NET.json" '
                             "(written by pandapower.to_json), relative to the study file")
    from pathlib import Path

    p = Path(resolve(path))
    if not p.is_file():
        raise ParameterError("grid.file", path, "no such file; paths are relative to the "
                             "study file")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            net = pp.from_json(str(p))
        except Exception as exc:   # noqa: BLE001 - any parser failure is the file's fault
            raise ParameterError("grid.file", path, "not a pandapower network written by "
                                 f"pandapower.to_json ({type(exc).__name__}: {exc})") from None
    if not isinstance(net, pp.pandapowerNet) or "bus" not in net:
        raise ParameterError("grid.file", path, "not a pandapower network written by "
                             f"pandapower.to_json (it holds a {type(net).__name__})")
    return net


def _pandapower_edits(g, load, net):
    """``[grid]``'s edits of a pandapower network (:mod:`weakgrid.study.grid_edits`), with
    pandapower's own ``create_*`` functions."""
    import pandapower as pp

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        if "keep_buses" in g:
            keep = net.bus.name.astype(str).str.match(g["keep_buses"])
            pp.toolbox.drop_buses(net, net.bus.index[~keep], drop_elements=True)
        if g.get("islanded", False):
            net.ext_grid.drop(net.ext_grid.index, inplace=True)
        bus_of = {str(n): int(i) for i, n in net.bus.name.items() if n is not None}

        def bref(ref, where):
            if isinstance(ref, str):
                if ref not in bus_of:
                    raise ParameterError(where, ref, f"no bus of that name; e.g. "
                                         f"{list(bus_of)[:8]}")
                return bus_of[ref]
            if ref not in net.bus.index:
                raise ParameterError(where, ref, "no bus with that pandapower index; e.g. "
                                     f"{list(net.bus.index[:8])}, or a name {list(bus_of)[:8]}")
            return int(ref)

        ld = g.get("loads", {})
        levels = ld.get("levels", {})
        if levels:
            if load not in levels:
                raise ParameterError("grid.loads.levels", levels, f"no level '{load}'")
            scale = float(levels[load])
            pf = ld.get("pf", {})
            for i, row in net.load.iterrows():
                p = float(row.p_mw) * scale
                net.load.at[i, "p_mw"] = p
                if row["name"] in pf:
                    net.load.at[i, "q_mvar"] = p * math.tan(math.acos(float(pf[row["name"]])))
                else:
                    net.load.at[i, "q_mvar"] = float(row.q_mvar) * scale
                net.load.at[i, "scaling"] = 1.0
        for j, b in enumerate(g.get("add_bus", [])):
            if "number" in b and b["number"] in net.bus.index:
                raise ParameterError(f"grid.add_bus.{j}.number", b["number"], "a bus of that "
                                     f"index exists; choose another (largest: "
                                     f"{int(net.bus.index.max())})")
            kw = {"index": int(b["number"])} if "number" in b else {}
            bus_of[b["name"]] = int(pp.create_bus(net, float(b["vn_kv"]), name=b["name"], **kw))
        for j, sg in enumerate(g.get("sgen_to_gen", [])):
            w = f"grid.sgen_to_gen.{j}"
            hit = net.sgen.index[net.sgen.name == sg["name"]]
            if len(hit) != 1:
                raise ParameterError(f"{w}.name", sg["name"], "no unique static generator of "
                                     f"that name; e.g. {list(net.sgen.name)[:8]}")
            row = net.sgen.loc[hit[0]]
            p = float(row.p_mw) * float(row.scaling) * float(sg.get("scale", 1.0))
            pp.create_gen(net, bref(sg["bus"], f"{w}.bus") if "bus" in sg else int(row.bus),
                          p_mw=p, vm_pu=float(sg.get("vm_pu", 1.0)),
                          name=sg["name"], sn_mva=float(row.sn_mva) if row.sn_mva == row.sn_mva
                          else None)
            net.sgen.drop(hit, inplace=True)
        for j, z in enumerate(g.get("add_impedance", [])):
            w = f"grid.add_impedance.{j}"
            _pandapower_impedance(net, z, bref(z["from"], f"{w}.from"),
                                  bref(z["to"], f"{w}.to"), z.get("name", f"impedance {j}"))
        for j, ge in enumerate(g.get("add_gen", [])):
            w = f"grid.add_gen.{j}"
            kw = {"slack": True} if ge.get("slack") else {}
            if "sn_mva" in ge:
                kw["sn_mva"] = float(ge["sn_mva"])
            pp.create_gen(net, bref(ge["bus"], f"{w}.bus"),
                          p_mw=per_level(ge.get("p_mw", 0.0), load, f"{w}.p_mw"),
                          vm_pu=ge.get("vm_pu", 1.0), name=ge["name"], **kw)
    return net, bus_of, bref


def _pandapower_impedance(net, z, f, t, name):
    """``[[grid.add_impedance]]`` on a pandapower network: pandapower's ``impedance`` element
    at ratio 1, else a two-winding transformer whose rated voltages give the off-nominal ratio
    ``tap`` at the ``from`` end (``vn_hv_kv = tap·vn(from)``, the impedance referred to the
    ``to`` end: MATPOWER's model); the shunt susceptance ``b`` [pu on ``sn_mva``] as two
    shunts, ``b/2`` at the ``to`` bus and ``b/2/tap²`` at the ``from`` bus (the pi model's
    shunt behind the ideal transformer)."""
    import pandapower as pp

    sn, r, x = float(z["sn_mva"]), float(z["r_pu"]), float(z["x_pu"])
    tap, b = float(z.get("tap", 1.0)), float(z.get("b", 0.0))
    if tap == 1.0:
        pp.create_impedance(net, f, t, rft_pu=r, xft_pu=x, sn_mva=sn, name=name)
    else:
        vf, vt = float(net.bus.vn_kv.at[f]), float(net.bus.vn_kv.at[t])
        pp.create_transformer_from_parameters(
            net, f, t, sn_mva=sn, vn_hv_kv=tap * vf, vn_lv_kv=vt, vkr_percent=100.0 * r,
            vk_percent=100.0 * math.hypot(r, x), pfe_kw=0.0, i0_percent=0.0, name=name)
    if b:
        # pandapower's shunt: q_mvar consumed at 1 pu (a capacitive b > 0 is q < 0)
        pp.create_shunt(net, t, q_mvar=-b / 2 * sn, name=f"{name} (b/2, to)")
        pp.create_shunt(net, f, q_mvar=-b / 2 / tap ** 2 * sn, name=f"{name} (b/2, from)")


# ----------------------------------------------------------------------------- setup
#: per process: the grids built by :func:`_network`, most recent last (a command builds the
#: same grid at the same load for its planning, its training and every run of it; reading a
#: case and its power flow's network once is enough)
_NETWORKS: OrderedDict = OrderedDict()
NETWORK_CACHE_SIZE = 8
_FILE_FIELDS = ("file", "raw", "dyr")


def _network_key(study, load) -> str:
    """What :func:`_build_network` reads: ``[grid]``, ``[upqc]`` but its rating (a sweep's
    axis; the grid does not depend on it), the study's folder, the load level and the stamp
    (size, modification time) of every file ``[grid]`` names — an edited case file is read
    again."""
    g = study.data["grid"]
    up = {k: v for k, v in study.data["upqc"].items() if k != "rating"}
    stamps = {}
    for k in _FILE_FIELDS:
        v = g.get(k)
        if isinstance(v, str):
            p = study.resolve(v)
            try:
                st = p.stat()
                stamps[k] = [str(p), st.st_size, st.st_mtime_ns]
            except OSError:
                stamps[k] = str(p)
    return canonical_json([g, up, str(study.base_dir), load, stamps])


def _network(study, load):
    """``(Network, bus_id name→number, branch names, upqc row, System or None)`` at ``load``:
    a private copy of the grid :func:`_build_network` built (once per process for the same
    inputs, :func:`_network_key`); the caller may edit it."""
    key = _network_key(study, load)
    hit = _NETWORKS.get(key)
    if hit is None:
        hit = _build_network(study, load)
        _NETWORKS[key] = copy.deepcopy(hit)   # kept pristine: every caller gets a copy
        while len(_NETWORKS) > NETWORK_CACHE_SIZE:
            _NETWORKS.popitem(last=False)
        return hit
    _NETWORKS.move_to_end(key)
    return copy.deepcopy(hit)


def _build_network(study, load):
    """``(Network, bus_id name→number, branch names, upqc row, System or None)`` at ``load``."""
    g = study.data["grid"]
    up = study.data["upqc"]
    if g["kind"] == "pandapower":
        net, bus_of, bref = _pandapower_net(g, load, study.resolve)
        ins = up.get("insert")
        ends = None
        if ins:
            el = ins.get("element", "line")
            tab = getattr(net, el)
            idx = ins.get("index")
            if "name" in ins:
                hit = tab.index[tab.name == ins["name"]]
                if len(hit) != 1:
                    raise ParameterError("upqc.insert.name", ins["name"],
                                         f"no unique {el} of that name")
                idx = int(hit[0])
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                res = insert_upqc_pandapower(net, el, idx, ins["side"], ins.get("r", 0.0),
                                             ins["x"], ins.get("sn_mva", net.sn_mva),
                                             name=up["name"])
            ends = (res["shunt_bus"], res["series_bus"])
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            network = Network.from_pandapower(net)
        ids = network.pandapower_bus     # pandapower index -> simulator bus (the same index)
        bus_id = {n: ids[i] for n, i in bus_of.items()}
        bus_id.update({i: ids[i] for i in net.bus.index})
        if ends is None:
            br = up["branch"]
            if not isinstance(br, dict):
                raise ParameterError("upqc.branch", br, "for a pandapower grid give "
                                     "{from = SHUNT BUS, to = BUS} (names or indices)")
            ends = (bref(br["from"], "upqc.branch.from"), bref(br["to"], "upqc.branch.to"))
        r_id, b1_id = ids[ends[0]], ids[ends[1]]
        rows = [k for k, row in enumerate(network.branch)
                if int(row[F_BUS]) == r_id and int(row[T_BUS]) == b1_id]
        if len(rows) != 1:
            raise ParameterError("upqc.branch", up.get("branch", up.get("insert")),
                                 "no unique series branch from the shunt bus to that bus")
        return network, bus_id, {}, rows[0], None
    if g["kind"] == "andes":
        return _andes_network(study, g, up, load)
    if g["kind"] == "psse":
        return _psse_network(study, g, up, load)
    if g["kind"] == "inline":
        case, names, bus_id = _inline_case(g, load)
        f_hz = float(g.get("f_hz", 60.0))
    else:
        from ..sim.io.matpower import load_matpower

        case = load_matpower(study.resolve(g["file"]))
        lv = g.get("loads", {}).get("levels", {})
        if lv:
            case["bus"] = np.array(case["bus"], float)
            case["bus"][:, 2:4] *= float(lv[load])
        names, bus_id = {}, {}
        case = _edit_case(case, g, load, bus_id, names)
        f_hz = float(g.get("f_hz", 60.0))

    def row_of(ref, where):
        if isinstance(ref, str):
            if ref not in names:
                raise ParameterError(where, ref, f"no branch of that name; choose one of "
                                     f"{list(names)}")
            return names[ref]
        if isinstance(ref, int) and 0 <= ref < len(case["branch"]):
            return ref
        raise ParameterError(where, ref, "give a branch name or a 0-based row")

    if up.get("insert"):
        ins = up["insert"]
        k = row_of(ins.get("branch", ins.get("index")), "upqc.insert.branch")
        case, k_up, _, _ = insert_upqc_matpower(case, k, ins["side"], ins.get("r", 0.0), ins["x"])
        names[up["name"]] = k_up
    else:
        k_up = row_of(up["branch"], "upqc.branch")
    network = Network(case)
    network.f_hz = f_hz
    return network, bus_id, names, k_up, None


def _edit_case(case, g, load, bus_id, names):
    """``[grid]``'s edits (:mod:`.grid_edits`) applied to a MATPOWER-layout case; the new
    buses and branches join ``bus_id`` (name → number) and ``names`` (name → row) in place."""
    if not has_edits(g):
        return case
    from types import SimpleNamespace

    nums = [int(b) for b in np.asarray(case["bus"])[:, 0]]
    known = dict(bus_id)
    for num, name in dict(case.get("bus_names") or {}).items():
        known.setdefault(str(name), int(num))
    grid = SimpleNamespace(bus_ids=nums, _pos={b: i for i, b in enumerate(nums)})

    def ref(r, where, new):
        if isinstance(r, str) and r not in known and r not in new and r.strip().isdigit():
            r = int(r)                       # "7": a bus number written as a string
        return _bus_ref(r, {**known, **new}, grid, where)

    case, new_bus, new_br = apply_case_edits(case, g, load, ref)
    bus_id.update(new_bus)
    names.update(new_br)
    return case


def _edit_system(system, g, load, bus_id, names):
    """``[grid]``'s edits of an imported System's network (ANDES, PSS/E): rows are appended,
    so the machines and controls keep their generator rows and buses."""
    if not has_edits(g):
        return
    net = system.network
    case = dict(net.case, bus_names=net.bus_names, branch_names=list(net.branch_names))
    case = _edit_case(case, g, load, bus_id, names)
    for j, sg in enumerate(g.get("sgen_to_gen", [])):
        _static_to_gen(system, case, sg, f"grid.sgen_to_gen.{j}", bus_id)
    system.network = _rebuilt(net, case)


def _static_to_gen(system, case, sg, where, bus_id):
    """A static generator of an imported grid (a PV generator without a dynamic model, which
    the importer holds as a constant-P, constant-|V| ``PVSource`` named ``PV_<idx>`` (ANDES)
    or ``PVSource_<bus>_<id>`` (PSS/E)) freed for the study's dynamics: the source leaves the
    system and its generator row stays in the power flow, ``scale``-d, at ``vm_pu``,
    moved to ``bus`` if given; ``case`` (the edited tables) is changed in place."""
    comp = system.components.get("PVSource")
    known = list(comp.names) if comp is not None else []
    if sg["name"] not in known:
        raise ParameterError(f"{where}.name", sg["name"], "no static generator (a generator "
                             "without a dynamic model) of that name; this grid's: "
                             f"{known or 'none'}")
    row = int(comp.links[known.index(sg["name"])]["gen"])
    comp.remove(sg["name"])
    if comp.n == 0:
        del system.components["PVSource"]
    system.is_setup = False
    gen, bus = case["gen"], case["bus"]
    gen[row, 1] *= float(sg.get("scale", 1.0))
    if "bus" in sg:
        from types import SimpleNamespace

        nums = [int(b) for b in bus[:, 0]]
        grid = SimpleNamespace(bus_ids=nums, _pos={b: i for i, b in enumerate(nums)})
        new = _bus_ref(sg["bus"], bus_id, grid, f"{where}.bus")
        old = int(gen[row, 0])
        gen[row, 0] = new
        if not np.any(gen[:, 0].astype(int) == old) and bus[nums.index(old), 1] == 2:
            bus[nums.index(old), 1] = 1            # no generator left: a PQ bus
        if bus[nums.index(new), 1] == 1:
            bus[nums.index(new), 1] = 2
    if "vm_pu" in sg:
        gen[row, 5] = float(sg["vm_pu"])


def _rebuilt(net, case):
    """A new :class:`Network` of ``case`` keeping ``net``'s declarations (series capacitors,
    negative resistances, generator split, names) and frequency."""
    case = dict(case)
    case.setdefault("series_capacitors", sorted(net.series_capacitors))
    case.setdefault("negative_resistance", sorted(net.negative_resistance))
    case.setdefault("gen_split", net.gen_split)
    case.setdefault("branch_names", list(net.branch_names))
    case.setdefault("bus_names", net.bus_names)
    return Network(case, f_hz=net.f_hz)


def _andes_file(study, name):
    if name.startswith("andes:"):
        import andes

        return andes.get_case(name[len("andes:"):])
    return str(study.resolve(name))


def _andes_network(study, g, up, load):
    """An ANDES/PSS/E case (``file``, optional ``dyr``) with its machines and controls."""
    try:
        import andes
    except ImportError:
        raise ParameterError("grid.kind", "andes", "install the optional ANDES parser: "
                             "pip install 'weakgrid[andes]'") from None
    from ..sim.io.andes import from_andes

    addfile = _andes_file(study, g["dyr"]) if g.get("dyr") else None
    main = _andes_file(study, g["file"])
    if str(main).lower().endswith(".raw"):   # ANDES misreads layouts it does not know
        from ..sim.io.psse.raw import raw_version

        raw_version(main)
    ss = andes.load(main, addfile=addfile, setup=False,
                    no_output=True, default_config=True)
    system, _ = from_andes(ss, include_events=False)
    bus_id = {str(k): int(v) for k, v in system.andes_bus_id.items()}
    names = {str(k): int(v) for k, v in system.andes_line_row.items()}
    _edit_system(system, g, load, bus_id, names)
    ins = up.get("insert")
    ref = str(ins.get("branch", ins.get("index")) if ins else up["branch"])
    if ref not in names:
        br = system.network.branch
        ends = {str(b): int(v) for b, v in system.andes_bus_id.items()}
        nums = {v: b for b, v in ends.items()}
        listed = [f"{n} ({nums.get(int(br[k, 0]), int(br[k, 0]))}-"
                  f"{nums.get(int(br[k, 1]), int(br[k, 1]))})" for n, k in names.items()]
        raise ParameterError("upqc.insert.branch" if ins else "upqc.branch", ref,
                             f"no ANDES Line with that idx; choose one of (its buses): "
                             f"{', '.join(listed)}")
    if ins:     # a new bus and series branch (pu on the system base), appended to the tables
        net = system.network
        case, k_up, _, _ = insert_upqc_matpower(net.case, names[ref], ins["side"],
                                                ins.get("r", 0.0), ins["x"])
        system.network = _rebuilt(net, case)
        names[up["name"]] = k_up
        return system.network, bus_id, names, k_up, system
    return system.network, bus_id, names, names[ref], system


def _psse_network(study, g, up, load):
    """A PSS/E ``.raw`` (+ ``.dyr``) case read natively, with its machines and controls."""
    from ..sim.io.psse import from_psse

    paths = {}
    for k in ("raw", "dyr"):
        if g.get(k):
            p = study.resolve(g[k])
            if not p.exists():
                raise ParameterError(f"grid.{k}", g[k], f"no such file ({p}); paths are relative "
                                     "to the study file")
            paths[k] = p
    system, _ = from_psse(paths["raw"], paths.get("dyr"), include_events=False)
    if "f_hz" in g:
        system.network.f_hz = float(g["f_hz"])
    net = system.network
    bus_id = {str(int(b)): int(b) for b in net.bus_ids}
    for b, name in system.psse_bus_name.items():
        if name and name not in bus_id:
            bus_id[name] = int(b)
    names = {f"{i}-{j}-{c}": int(r) for (i, j, c), r in system.psse_branch_row.items()}
    for (i, j, k, c), rows in system.psse_transformer_rows.items():
        if k == 0:
            names[f"{i}-{j}-{c}"] = int(rows[0])
    _edit_system(system, g, load, bus_id, names)
    net = system.network
    ins = up.get("insert")
    ref = ins.get("branch", ins.get("index")) if ins else up["branch"]
    where = "upqc.insert.branch" if ins else "upqc.branch"
    if isinstance(ref, dict):
        a = _bus_ref(ref.get("from"), bus_id, net, f"{where}.from")
        b = _bus_ref(ref.get("to"), bus_id, net, f"{where}.to")
        rows = [r for r in names.values() if {int(net.branch[r, F_BUS]), int(net.branch[r, T_BUS])} == {a, b}]
        if len(rows) != 1:
            raise ParameterError(where, ref, f"{len(rows)} branches between buses {a} and {b}; "
                                 "name it as \"I-J-CKT\"")
        k_ref = rows[0]
        if int(net.branch[k_ref, F_BUS]) != a:
            raise ParameterError(where, ref, f"the branch runs from bus {int(net.branch[k_ref, F_BUS])}: "
                                 "give that bus as 'from' and set upqc.side = \"to\" if the other "
                                 "end is the shunt bus")
    else:
        if str(ref) not in names:
            raise ParameterError(where, ref, "no PSS/E branch \"I-J-CKT\" of that name; e.g. "
                                 f"{list(names)[:8]}")
        k_ref = names[str(ref)]
    if ins:     # a new bus and series branch (pu on the system base), appended to the tables
        case, k_up, _, _ = insert_upqc_matpower(net.case, k_ref, ins["side"], ins.get("r", 0.0), ins["x"])
        system.network = _rebuilt(net, case)
        names[up["name"]] = k_up
        return system.network, bus_id, names, k_up, system
    return net, bus_id, names, k_ref, system


_SAID: set = set()   # messages this process has logged (grid data warnings, baseline notes)


@contextlib.contextmanager
def _data_warnings_once():
    """Say the grid's data warnings (:class:`~weakgrid.sim.errors.DataWarning`, one per model
    with a count) once per process, through this module's log: a study builds its grid
    again for every run, and each build would repeat them. Later repeats go to DEBUG; other
    warnings pass through unchanged."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", DataWarning)
        yield
    for w in caught:
        if issubclass(w.category, DataWarning):
            _say_once(logging.WARNING, f"grid data: {w.message}")
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)


def _say_once(level: int, msg: str):
    """Log ``msg`` at ``level`` the first time this process says it, at DEBUG afterwards."""
    log.log(logging.DEBUG if msg in _SAID else level, msg)
    _SAID.add(msg)


def baseline_machine(study, system) -> str | None:
    """The synchronous machine whose supplementary control the baselines are about.

    The controlled machine (``machine.name``) when it is a synchronous machine; when it is a
    GTI (which has no stabilizer), the SG the study follows: ``report.speed_of``, else the
    first ``[[dynamics.generator]]`` (None if there is none or ``speed_of = ""``). Only this
    machine's stabilizers leave the grid for the ``none`` baseline; every other unit keeps
    its own.
    """
    d = study.data
    name = d["machine"]["name"]
    if name in system.machine_names:
        return name
    speed_of = d["report"].get("speed_of")
    return (speed_of if speed_of is not None else _first_generator(d)) or None


def _first_generator(d):
    gens = d["dynamics"]["generator"]
    return gens[0]["name"] if gens else None


def _remove_stabilizers(system, machine):
    """Take ``machine``'s stabilizers (every ``kind = "pss"`` control linked to it) out of
    ``system`` before its set-up, which re-initializes the grid without them and checks the
    initial point."""
    if machine is None:
        _say_once(logging.WARNING, "baseline 'none': no synchronous machine to take the "
                  "stabilizer of (the controlled machine is a GTI and report.speed_of names no "
                  "SG); 'none' equals 'pss-only'")
        return
    removed = system.remove_controls(machine, "pss")
    if removed:
        _say_once(logging.INFO, "baseline 'none': " + ", ".join(
            f"{m} '{n}'" for m, n in removed) + f" of {machine} out of service")
    else:
        _say_once(logging.WARNING, f"baseline 'none': machine {machine} has no stabilizer; "
                  "'none' equals 'pss-only'")


def _source_names(network, bus_id, br_names):
    """One set of identifiers for the study file, the printouts and the results: the source's
    bus names and branch names of ``network`` join the study's (``bus_id``, ``br_names``,
    completed in place), and the study's branch names label the network's rows."""
    for num, name in network.bus_names.items():
        bus_id.setdefault(name, int(num))
    for name, num in bus_id.items():     # the study's own bus names (inline grids)
        if isinstance(name, str) and name != str(num):
            network.bus_names.setdefault(int(num), name)
    for k, name in enumerate(network.branch_names):
        if name is not None:
            br_names.setdefault(name, k)
    for name, k in br_names.items():
        if network.branch_names[k] is None:
            network.branch_names[k] = name


def _plausible_rating(up: dict, load: str, v_r: float, i_line: float, Sb: float) -> None:
    """Check the UPQC rating against what the converter and the line can carry.

    The largest series power is ``|Vu|max · |I_line|``. Beyond the converter's rating
    (``upqc.insert.sn_mva``, when given) it is refused. Beyond the line's apparent power
    ``|V_r| · |I_line|`` at the shunt bus r (a series voltage above the bus voltage) it is
    said loudly, once, as a warning: the shipped studies' sweeps reach rating 1.0 pu, above
    case 1's sagging shunt-bus voltage (0.83 pu at high load), on purpose.

    Parameters
    ----------
    up : dict
        The study's ``[upqc]`` table (``rating`` in pu of the bus voltage).
    load : str
        The load level (in messages).
    v_r, i_line : float
        ``|V_r|`` and ``|I_line|`` at the operating point [pu on ``Sb``].
    Sb : float
        System power base [MVA].
    """
    rating = float(up["rating"])
    per_pu = i_line * Sb                                  # MVA of series power per pu of |Vu|
    p_series = rating * per_pu
    sn = (up.get("insert") or {}).get("sn_mva")
    if sn is not None and p_series > float(sn) * (1 + 1e-9):
        raise ParameterError(
            "upqc.rating", rating, f"its largest series power |Vu|max · |I_line| = "
            f"{p_series:.4g} MVA at load '{load}' ({100 * p_series / float(sn):.0f} % of the "
            f"converter's rating upqc.insert.sn_mva = {float(sn):g} MVA) is beyond what the "
            f"converter carries. Give a rating at most {float(sn) / per_pu:.3g} pu, or a "
            "larger upqc.insert.sn_mva")
    s_line = v_r * per_pu
    if p_series > s_line * (1 + 1e-9):
        _say_once(logging.WARNING, (
            f"warning: upqc.rating = {rating:g} pu: its largest series power |Vu|max · "
            f"|I_line| = {p_series:.4g} MVA is {100 * p_series / s_line:.0f} % of the line's "
            f"power at load '{load}' ({s_line:.4g} MVA = |V_r| {v_r:.4g} pu × |I_line| "
            f"{i_line:.4g} pu on {Sb:g} MVA): a series voltage above the shunt bus's own. "
            f"Results at this rating are beyond a plausible device; a rating at most "
            f"{v_r:.3g} pu keeps it within the line"))


def build_setup(study, load: str | None = None, upqc: str | None = None,
                variant: str = "upqc") -> Setup:
    """Build and set up the study's grid at ``load`` with the UPQC in structure ``upqc``;
    ``variant`` is one of :data:`VARIANTS` (what a controller needs: :func:`weakgrid.study.
    controllers.controller_variant`), made before the grid is initialized and checked."""
    d = study.data
    load = load or d["design"].get("load", study.loads[0])
    if load not in study.loads:
        raise ParameterError("load", load, f"choose one of {study.loads}")
    upqc = upqc or d["upqc"]["structure"]
    if variant not in VARIANTS:
        raise ParameterError("variant", variant, f"choose one of {VARIANTS}")
    with quiet_loggers("pandapower", "andes"):   # their parsers' notes; restored after
        network, bus_id, br_names, k_up, system = _network(study, load)
    _source_names(network, bus_id, br_names)
    if d["upqc"].get("side", "from") == "to":     # the branch's to-bus is the shunt bus r
        row = network.branch[k_up]
        row[F_BUS], row[T_BUS] = row[T_BUS], row[F_BUS]
    r_id = int(network.branch[k_up, F_BUS])
    s = system if system is not None else System(network)
    net = s.network
    gbus = net.gen[:, GEN_BUS].astype(int)

    def gen_row(ref, where):
        bid = _bus_ref(ref, bus_id, net, where)
        rows = np.nonzero(gbus == bid)[0]
        if len(rows) != 1:
            raise ParameterError(where, ref, f"expected exactly one generator at bus {bid}, "
                                 f"found {len(rows)}")
        return int(rows[0])

    ctl_name = d["machine"]["name"]
    dyn = d["dynamics"]
    for i, gen in enumerate(dyn["generator"]):
        parts = {}
        for part in ("machine", "exciter", "governor", "pss"):
            if part in gen:
                p = dict(gen[part])
                parts[part] = (p.pop("model"), p)
        try:
            s.add_generator(gen["name"], gen_row(gen["bus"], f"dynamics.generator.{i}.bus"),
                            **parts)
        except DataError as exc:  # an unknown model: name the study field
            bad = [k for k, (m, _) in parts.items() if m == exc.value]
            if exc.element != "model" or not bad:
                raise
            raise ParameterError(f"dynamics.generator.{i}.{bad[0]}.model", exc.value,
                                 exc.fix) from None
    gti_names = [gt["name"] for gt in dyn["gti"]]
    if variant == "pq" and ctl_name not in gti_names:
        raise ParameterError("controller", "pq", "the PQ baseline replaces the UPQC by the "
                             "PQ loops of a GTI; this study's controlled machine is not a GTI")
    if dyn["gti"]:
        comp = s.add_component(GTI())
        for i, gt in enumerate(dyn["gti"]):
            p = {k: v for k, v in gt.items() if k not in ("name", "bus", "mode", "ref_bus")}
            mode = "pq" if (variant == "pq" and gt["name"] == ctl_name) else gt.get("mode",
                                                                                   "energy")
            ref = _bus_ref(gt["ref_bus"], bus_id, net, f"dynamics.gti.{i}.ref_bus") \
                if "ref_bus" in gt else r_id
            comp.add_gti(gt["name"], gen=gen_row(gt["bus"], f"dynamics.gti.{i}.bus"),
                         ref_bus=ref, mode=mode, **p)
    if variant == "no-pss":
        _remove_stabilizers(s, baseline_machine(study, s))
    up = d["upqc"]
    upqc_name = None
    if variant in ("upqc", "no-pss"):
        if upqc == "reduced" and ctl_name not in gti_names:
            raise ParameterError("upqc.structure", "reduced", "the reduced UPQC takes its "
                                 "series power from the controlled GTI's dc link; this study's "
                                 "controlled machine is an SG: use 'conventional'")
        u = s.add_component(UPQC())
        u.add_upqc(up["name"], branch=k_up, structure=upqc,
                   gti=ctl_name if upqc == "reduced" else None,
                   **upqc_params(d, upqc, float(net.Sb)))
        upqc_name = up["name"]
    with _data_warnings_once():
        s.setup()
    der = derive_design(s, ctl_name, k_up, float(d["design"]["T"]), structure=upqc,
                        grid_model=d["design"].get("grid_model", "paper"))
    b1 = net.index_of(int(net.branch[k_up, T_BUS]))
    r = net.index_of(r_id)
    yu = 1.0 / complex(net.branch[k_up, BR_R], net.branch[k_up, BR_X])
    I = yu * (net.pf.V[r] - net.pf.V[b1])
    p_line = abs(float((net.pf.V[r] * np.conj(I)).real)) * net.Sb
    s_line = float(abs(net.pf.V[r]) * abs(I)) * float(net.Sb)
    if upqc_name:
        _plausible_rating(up, load, abs(net.pf.V[r]), abs(I), float(net.Sb))
    if der.machine == "gti":
        measure_signals = gti_signals(ctl_name)
        state_map = gti_state_map(s, ctl_name)
    else:   # upsilon in rad/s: speed error pu times ws
        measure_signals = sg_signals(ctl_name, r_id)
        state_map = sg_state_map(s, ctl_name, r_id, ws=2 * math.pi * float(net.f_hz))
    measure = mapped(measure_signals, state_map)
    speed_of = d["report"].get("speed_of")
    speed_of = speed_of if speed_of is not None else (ctl_name if der.machine == "sg" else
                                                      _first_generator(d))
    signals = {"shunt_bus_v": f"bus{r_id}.v"}
    if speed_of:
        signals.update(sg_speed=f"{speed_of}.omega", sg_pe=f"{speed_of}.Pe")
    if der.machine == "gti":
        signals.update(dc_voltage=f"{ctl_name}.Vc", phi_hat=f"{ctl_name}.phi_hat",
                       upsilon=f"{ctl_name}.upsilon")
    if upqc_name:
        signals.update(vup=f"{upqc_name}.Vup", vuq=f"{upqc_name}.Vuq",
                       p_series=f"{upqc_name}.P_series", q_series=f"{upqc_name}.Q_series",
                       p_line=f"{upqc_name}.P_line", vu=f"{upqc_name}.Vu",
                       s_series=f"{upqc_name}.S_series")
        if upqc == "conventional":
            signals.update(s_shunt=f"{upqc_name}.S_shunt", upqc_vdc=f"{upqc_name}.Vdc",
                           shunt_limited=f"{upqc_name}.limited")
    return Setup(study=study, load=load, upqc=upqc, variant=variant, system=s,
                 machine=der.machine, source=ctl_name, upqc_name=upqc_name, shunt_bus=r_id,
                 upqc_branch=k_up, measure=measure, design=der.model, derivation=der,
                 line_power_mw=p_line, signals=signals, Sb_mva=float(net.Sb), bus_id=bus_id,
                 branch_names=br_names, measure_signals=measure_signals, state_map=state_map,
                 s_rating_mva=s_rating_mva(up) if upqc_name else None, line_mva=s_line)
