"""Grid edits of a study file for every grid kind: one set of operations, one set of names.

``[grid]`` tables (applied in this order, after the grid is read and its loads are scaled, before
the UPQC is inserted and before the power flow, so a new generator is in the power flow):

* ``[[grid.add_bus]]`` ``name``, ``vn_kv`` [kV], ``number`` (optional: the new bus's number;
  default: one above the grid's largest) — a PQ bus without load;
* ``[[grid.sgen_to_gen]]`` ``name``, ``bus`` (optional: move it), ``vm_pu`` [1.0], ``scale``
  [1.0] — a static generator becomes a voltage-controlled generator whose dynamics the study
  gives (e.g. a GTI): pandapower's ``net.sgen`` by name; on ANDES and PSS/E grids a generator
  without a dynamic model (the importer's constant-power, constant-voltage ``PVSource``, named
  ``PV_<idx>`` / ``PVSource_<bus>_<id>``; an unknown name is refused with the list);
  MATPOWER cases have none (every generator gets its dynamics from the study);
* ``[[grid.add_impedance]]`` ``name``, ``from``, ``to``, ``r_pu``, ``x_pu``, ``sn_mva``
  (the base of ``r_pu``, ``x_pu``, ``b``), ``b`` [0] (total shunt susceptance of the branch's
  pi model, pu on ``sn_mva``, half at each end), ``tap`` [1] (off-nominal ratio, an ideal
  transformer at the ``from`` end: MATPOWER's and PSS/E's convention) — a series branch (a line,
  a transformer);
* ``[[grid.add_gen]]`` ``name``, ``bus``, ``p_mw`` (a number or a table per load level),
  ``vm_pu`` [1.0], ``sn_mva`` (optional: its rating), ``slack`` [false] — a generator row of
  the power flow (its bus becomes voltage-controlled); its dynamics come from
  ``[[dynamics.generator]]`` or ``[[dynamics.gti]]`` (a GTI and its dc link) at that bus.

Buses are referred to as anywhere in a study file: the source's number or name (and names
given by ``add_bus``); an unknown bus is refused with a list of valid ones. Every field with
its type, unit and default: ``docs/study-file-reference.md`` (:mod:`weakgrid.study.fields`).
The pandapower kind applies them with pandapower's own ``create_*`` functions
(:func:`weakgrid.study.build._pandapower_net`); MATPOWER, ANDES and PSS/E grids here, on the
simulator's MATPOWER-layout tables (:func:`apply_case_edits`).
"""

from __future__ import annotations

import numpy as np

from ..game.errors import ParameterError
from .fields import table

__all__ = ["EDITS", "FIELDS", "validate_edits", "apply_case_edits", "has_edits"]

#: the edit tables, in the order they are applied
EDITS = ("add_bus", "sgen_to_gen", "add_impedance", "add_gen")

#: per edit: (required fields, optional fields), from :mod:`weakgrid.study.fields`
FIELDS = {k: ({f.name for f in table(f"grid.{k}").fields if f.required},
              {f.name for f in table(f"grid.{k}").fields if not f.required}) for k in EDITS}


def has_edits(g: dict) -> bool:
    """True when ``[grid]`` has any edit table."""
    return any(g.get(k) for k in EDITS)


def _number(d, key, w, positive=False, nonneg=False):
    v = d[key]
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
        raise ParameterError(f"{w}.{key}", v, "give a finite number")
    if positive and not v > 0:
        raise ParameterError(f"{w}.{key}", v, "must be > 0")
    if nonneg and v < 0:
        raise ParameterError(f"{w}.{key}", v, "must be >= 0")


def validate_edits(g: dict, levels=()) -> None:
    """Check the types of ``[grid]``'s edit tables (the grid itself checks the bus names when
    it is built). ``levels``: the study's load levels (for a per-level ``p_mw``)."""
    kind = g.get("kind")
    if kind == "inline":
        for k in EDITS:
            if k in g:
                raise ParameterError(f"grid.{k}", g[k], "an inline grid lists its buses, "
                                     "branches and generators itself: add them to "
                                     "[[grid.bus]], [[grid.branch]], [[grid.gen]]")
        return
    if kind == "matpower" and g.get("sgen_to_gen"):
        raise ParameterError("grid.sgen_to_gen", g["sgen_to_gen"], "a MATPOWER case has no "
                             "static generators: each of its generators gets its dynamics "
                             "from [[dynamics.generator]] or [[dynamics.gti]] at its bus; add a "
                             "unit with [[grid.add_gen]]")
    for key in EDITS:
        tab = g.get(key, [])
        if not isinstance(tab, list):
            raise ParameterError(f"grid.{key}", tab, f"give a list of tables [[grid.{key}]]")
        need, opt = FIELDS[key]
        for j, e in enumerate(tab):
            w = f"grid.{key}.{j}"
            if not isinstance(e, dict):
                raise ParameterError(w, e, f"must be a table [[grid.{key}]] with "
                                     f"{', '.join(sorted(need))}")
            for f in sorted(need):
                if f not in e:
                    raise ParameterError(f"{w}.{f}", None, f"missing; [[grid.{key}]] needs "
                                         f"{', '.join(sorted(need))} (optional: "
                                         f"{', '.join(sorted(opt))})")
            for f in e:
                if f not in need | opt:
                    raise ParameterError(f"{w}.{f}", e[f], f"unknown field of [[grid.{key}]]; "
                                         f"its fields: {', '.join(sorted(need | opt))}")
            if "name" in e and not isinstance(e["name"], str):
                raise ParameterError(f"{w}.name", e["name"], "give a name (a string)")
            for f in ("vn_kv", "sn_mva"):
                if f in e:
                    _number(e, f, w, positive=True)
            for f in ("r_pu", "x_pu", "vm_pu", "scale", "b"):
                if f in e:
                    _number(e, f, w)
            if "tap" in e:
                _number(e, "tap", w, positive=True)
                if not 0.5 <= e["tap"] <= 1.5:
                    raise ParameterError(f"{w}.tap", e["tap"], "an off-nominal ratio in pu "
                                         "(0.5 .. 1.5; 1 for none)")
            if key == "add_impedance" and e["r_pu"] == 0 and e["x_pu"] == 0:
                raise ParameterError(f"{w}.x_pu", 0.0, "a branch needs a non-zero impedance")
            if "vm_pu" in e and not 0.5 < e["vm_pu"] < 1.5:
                raise ParameterError(f"{w}.vm_pu", e["vm_pu"], "a voltage set point in pu "
                                     "(0.5 .. 1.5)")
            if "number" in e and (isinstance(e["number"], bool)
                                  or not isinstance(e["number"], int) or e["number"] <= 0):
                raise ParameterError(f"{w}.number", e["number"], "give a positive integer")
            if "p_mw" in e:
                p = e["p_mw"]
                if isinstance(p, dict):
                    for lv, v in p.items():
                        if levels and lv not in levels:
                            raise ParameterError(f"{w}.p_mw.{lv}", v, f"no load level '{lv}'; "
                                                 f"the study's levels: {list(levels)}")
                        _number(p, lv, f"{w}.p_mw")
                else:
                    _number(e, "p_mw", w)
            if "slack" in e and not isinstance(e["slack"], bool):
                raise ParameterError(f"{w}.slack", e["slack"], "true or false")


def per_level(v, load, where):
    """``v`` [MW] at load level ``load``: a number, or a table of one value per level."""
    if isinstance(v, dict):
        if load not in v:
            raise ParameterError(where, v, f"give a value for load level '{load}'")
        return float(v[load])
    return float(v)


def apply_case_edits(case: dict, g: dict, load: str, bus_ref) -> tuple[dict, dict, dict]:
    """Apply ``[grid]``'s edits to a MATPOWER-layout case (MATPOWER, ANDES, PSS/E grids).

    Parameters
    ----------
    case : dict
        ``baseMVA``, ``bus``, ``gen``, ``branch`` (MATPOWER columns, pu on ``baseMVA``) and
        optionally ``bus_names``, ``branch_names``; not modified.
    g : dict
        The study's ``[grid]`` table.
    load : str
        The load level (a per-level ``p_mw``).
    bus_ref : callable
        ``bus_ref(ref, where, new)`` → bus number of a study's bus reference, ``new`` the
        buses added so far (name → number); raises :class:`ParameterError` for an unknown one.

    Returns
    -------
    (case, new_buses, new_branches)
        The edited case (new rows appended: existing rows keep their positions), the added
        buses (name → number) and branches (name → 0-based row).
    """
    Sb = float(case["baseMVA"])
    bus = np.array(case["bus"], float)
    gen = np.atleast_2d(np.array(case["gen"], float))
    br = np.array(case["branch"], float)
    bus_names = dict(case.get("bus_names") or {})
    br_names = (list(case.get("branch_names") or []) + [None] * len(br))[:len(br)]
    new_bus, new_br = {}, {}

    def ref(r, where):
        return int(bus_ref(r, where, new_bus))

    for j, b in enumerate(g.get("add_bus", [])):
        w = f"grid.add_bus.{j}"
        num = int(b.get("number", int(bus[:, 0].max()) + 1))
        if num in set(bus[:, 0].astype(int)):
            raise ParameterError(f"{w}.number", num, "a bus of that number exists; choose "
                                 f"another (largest: {int(bus[:, 0].max())})")
        if b["name"] in new_bus:
            raise ParameterError(f"{w}.name", b["name"], "a bus of that name is added twice")
        row = np.zeros(bus.shape[1])
        row[:13] = [num, 1, 0, 0, 0, 0, 1, 1.0, 0.0, float(b["vn_kv"]), 1, 1.1, 0.9]
        bus = np.vstack([bus, row])
        bus_names[num] = b["name"]
        new_bus[b["name"]] = num
    for j, z in enumerate(g.get("add_impedance", [])):
        w = f"grid.add_impedance.{j}"
        f, t = ref(z["from"], f"{w}.from"), ref(z["to"], f"{w}.to")
        if f == t:
            raise ParameterError(f"{w}.to", z["to"], "the same bus as 'from'")
        k = Sb / float(z["sn_mva"])                   # pu on sn_mva -> pu on the system base
        row = np.zeros(br.shape[1])
        row[:5] = [f, t, float(z["r_pu"]) * k, float(z["x_pu"]) * k, float(z.get("b", 0.0)) / k]
        tap = float(z.get("tap", 1.0))
        row[8] = 0.0 if tap == 1.0 else tap            # MATPOWER: 0 = a line (ratio 1)
        row[10] = 1
        if br.shape[1] > 12:
            row[11], row[12] = -360, 360
        br = np.vstack([br, row])
        name = z.get("name", f"impedance {j}")
        if name in br_names:
            raise ParameterError(f"{w}.name", name, "a branch of that name exists; name it "
                                 "otherwise")
        br_names.append(name)
        new_br[name] = len(br) - 1
    pos = {int(b): i for i, b in enumerate(bus[:, 0])}
    ncol = max(gen.shape[1] if gen.size else 0, 21)
    if gen.size and gen.shape[1] < ncol:
        gen = np.hstack([gen, np.zeros((gen.shape[0], ncol - gen.shape[1]))])
    for j, ge in enumerate(g.get("add_gen", [])):
        w = f"grid.add_gen.{j}"
        b = ref(ge["bus"], f"{w}.bus")
        vm = float(ge.get("vm_pu", 1.0))
        row = np.zeros(ncol)
        row[:10] = [b, per_level(ge.get("p_mw", 0.0), load, f"{w}.p_mw"), 0.0, 9999.0,
                    -9999.0, vm, float(ge.get("sn_mva", Sb)), 1, 9999.0, -9999.0]
        gen = np.vstack([gen, row]) if gen.size else row[None, :]
        i = pos[b]
        if ge.get("slack"):
            bus[bus[:, 1] == 3, 1] = 2
            bus[i, 1] = 3
        elif bus[i, 1] == 1:
            bus[i, 1] = 2                              # PQ -> PV: its voltage is held
        bus[i, 7] = vm
    out = dict(case, bus=bus, gen=gen, branch=br, bus_names=bus_names, branch_names=br_names)
    return out, new_bus, new_br
