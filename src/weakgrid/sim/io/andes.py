"""Import an ANDES system (loaded with ``andes.load(..., setup=False)``) into weakgrid.

Supported ANDES models: the network (``Bus``, ``Line``, ``PQ``, ``Shunt``,
``PV``, ``Slack``), every dynamic model registered in
:func:`weakgrid.sim.system._registry` (machines, exciters, governors, PSS,
renewables — REGCA1 with its controls REECA1/REECB1 and REPCA1, PVD1, the type-3 wind
turbine WTDTA1/WTARA1/WTPTA1/WTTQA1 —, ZIP loads;
parameters are read by their ANDES names), and the
events ``Toggle`` (of a ``Line``: each toggle flips the line's status, so
a second toggle recloses it) and ``Fault``. Measurement-only models
(``BusFreq``, ``BusROCOF``, ``FreqDiv``, ``PLL1``, ``PLL2``, ``COI``, ``PMU``, ``ACEc``) and bookkeeping (``Area``,
``Summary``) are ignored with a note in ``system.import_notes``: they feed no
signal back into the grid models weakgrid has. Any other model with
in-service devices raises one :class:`~weakgrid.sim.errors.DataError` that
lists *all* of them. Devices with ``u = 0`` are skipped (with their controls).

Raw ANDES input data are used (device bases); the per-unit conversions are
done by weakgrid exactly as ANDES does (impedances by ``(Vn^2/Sn)/(Vb^2/Sb)``,
powers and inertias by ``Sn/Sb``). PQ loads become constant impedances in the
time domain, as with ANDES's default ``p2z = q2z = 1``.

PSS/E data: read them with :func:`weakgrid.sim.io.psse.from_psse`, weakgrid's own reader
(``.raw`` versions 29-35, each ``.dyr`` record by its model's PSS/E field order, PSS/E's
conventions: ``H = 0`` infinite bus, remote bus 0 = local, ``MBASE``/``ZSORCE``, negative branch
resistance, switched shunts at ``BINIT``; nothing substituted, nothing dropped). The ANDES route
below stays for ANDES's own formats and for peer comparisons with ANDES: ANDES 2.0's parser
changes PSS/E data without a word (issue 26: a ``GENCLS`` with ``H = 0`` becomes a machine with
``M = 6 s``, ``ESAC1A`` is read in the wrong field order, ``GENSAL`` and several exciters and
governors are replaced by other models, a text field such as ``'EG'`` crashes it).

``andes.load(raw, addfile=dyr, setup=False)`` parses a ``.raw`` +
``.dyr`` pair into the same ANDES models, which this module then imports. Two gaps of
ANDES 2.0's parser are handled here: non-transformer branches are read on the system base
(:func:`psse_branch_sn`; the parser leaves them at 100 MVA), and ``.dyr`` models the parser
drops are listed among the unsupported models (:func:`psse_dyr_dropped`).

Static generators without a dynamic model: a ``Slack`` or ``PV`` that no in-service machine or
converter replaces keeps its power-flow equations in ANDES's time-domain simulation. weakgrid
does the same (``static_gens="ideal"``, the default): a Slack becomes an
:class:`~weakgrid.sim.sources.InfiniteBus` (ideal voltage source: fixed voltage and angle,
infinite inertia), a PV a :class:`~weakgrid.sim.sources.PVSource` (constant P at constant ``|V|``,
no inertia), each with a note in ``system.import_notes``; ``static_gens="refuse"`` refuses
the case instead, naming them.

Out-of-service buses (``Bus.u = 0``) are dropped with every line and device on them, with
notes (ANDES disconnects them: their lines go out of service, their voltages are frozen).

Islands: every island of the in-service network (at t = 0) must hold a slack
(reference) bus; an island without one is refused naming its buses. An island's reference is
its slack: the machine that replaces it, or, without one, an ideal source (above).

Conventions: ``from_andes(ss, conventions="standard")`` (the default) builds every model
as its standard (IEEE 421.5 / PSS/E) block diagram. ``conventions="andes"`` reproduces
where ANDES 2.0 departs from it (see :data:`ANDES_CONVENTIONS`), so that a comparison with
ANDES isolates real differences; each departure is a flag parameter of the weakgrid model,
documented in its module, and listed in ``system.import_notes``.

ANDES is an optional dependency and is not imported by this module; pass the
loaded ``andes.System``.
"""

from __future__ import annotations

import re

import numpy as np

from ..errors import DataError
from ..events import Fault, LineTrip
from ..system import System, _registry

_NETWORK = {"Bus", "Line", "PQ", "Shunt", "PV", "Slack", "Toggle", "Fault"}
#: models ignored on import (measurements and bookkeeping; nothing in the grid reads them)
_IGNORED = {"Area", "Summary", "BusFreq", "BusROCOF", "FreqDiv", "PLL1", "PLL2", "COI", "PMU", "ACEc"}
_SUPPORTED = _NETWORK | _IGNORED   # plus the registry (see _supported())


def _supported():
    return _SUPPORTED | set(_registry())


#: Where ANDES 2.0 departs from the standard diagram: model -> {flag parameter: value that
#: reproduces ANDES}; applied by ``from_andes(..., conventions="andes")``.
ANDES_CONVENTIONS = {
    "EXAC1": {"TR_used": 0.0},    # the summing junction takes the unfiltered voltage (TR unused)
    "EXAC2": {"TR_used": 0.0},    # as its EXAC1
    "ESDC2A": {"TR_used": 0.0},   # idem
    "REGCA1": {"LVPL_strict": 0.0},  # LVPL resets S0 only while dS0/dt >= 0 (S0 may stay above it)
    "REPCA1": {"P_total": 0.0},   # Pmin, Pmax bound the increment Pext, not the total P reference
    "IEEEX1": {"VR_Vt": 0.0},     # regulator limits VRMAX, VRMIN, not times Vt
    "EXST1": {"VR_limited": 0.0},  # output limit tested on the rate feedback (in effect never acts)
    "IEEEVC": {"on_Sb": 1.0},     # rc, xc on the system base (its IEEEVC has no Sn)
    "IEEEST": {"F2_bypass": 1.0},  # (1 + A5 s + A6 s^2)/(1 + A3 s + A4 s^2) bypassed when A4 = 0
    # unit-gain gate integrator (Tr unused); flow, gate and Dt on the system base; rate bounds -x1/r
    "HYGOV": {"Tr_used": 0.0, "Tw_sysbase": 1.0, "Dt_sysbase": 1.0, "VELM_offset": 1.0},
    "ESST4B": {"PI_nonwindup": 0.0},   # PI regulators with tracking anti-windup (Ks = 2)
    "AC8B": {"PID_nonwindup": 0.0, "VE_limited": 0.0},   # tracking PID; VEMIN, VFEMAX unused
    "ESST1A": {"VOSc": 1.0},       # the PSS output always enters the summing junction
    "ESAC1A": {"VF_used": 0.0, "VR_limited": 0.0},  # no rate feedback; no VRMIN..VRMAX, no VE >= 0
    "ESDC1A": {"TR_used": 0.0},   # as ESDC2A
    # wind type 3: speed reference held at w0, rate limits on Tp*dtheta/dt
    "WTPTA1": {"wref_tq": 0.0, "rate_T": 1.0},
    # speed error wref - wg, unfiltered Pe, REECA1's wg = 1 + wg - fPe, limits widened at t = 0
    "WTTQA1": {"speed_err": 0.0, "Pe_filt": 0.0, "wg_reset": 1.0, "adjust_lim": 1.0},
}
CONVENTIONS = ("standard", "andes")


def device_name(model: str, idx) -> str:
    """weakgrid's name of ANDES device ``idx`` of ``model``: ``"<model>_<idx>"``.

    ANDES's own generated idx already carry the model (``GENROU_4``, ``Line_13``): they are kept
    as they are, not prefixed twice (``GENROU_4``, not ``GENROU_GENROU_4``); a numeric or other
    idx gets the model in front (kundur's GENROU ``1`` → ``GENROU_1``, REGCA1 ``RE1`` →
    ``REGCA1_RE1``), so that a name says its model and the idx a user gave.
    """
    s = str(idx).strip()
    return s if s.startswith(f"{model}_") else f"{model}_{s}"


def bus_numbers(idx) -> tuple[dict, bool]:
    """weakgrid bus number of each ANDES bus idx: the idx itself when every idx is an integer
    (PSS/E numbers, ANDES's stock cases), else 1..n in the case's bus order.

    Returns
    -------
    numbers : dict
        ANDES bus idx -> weakgrid bus number.
    kept : bool
        True when the numbers are the idx themselves.
    """
    def as_int(v):
        if isinstance(v, (bool, np.bool_)):
            return None
        if isinstance(v, (int, np.integer)):
            return int(v)
        if isinstance(v, (float, np.floating)) and float(v).is_integer():
            return int(v)
        if isinstance(v, str) and re.fullmatch(r"[+-]?\d+", v.strip()):
            return int(v)
        return None

    nums = [as_int(v) for v in idx]
    if all(n is not None for n in nums) and len(set(nums)) == len(nums):
        return dict(zip(idx, nums)), True
    return {b: k + 1 for k, b in enumerate(idx)}, False


def _col(m, name):
    p = getattr(m, name)
    return list(p.v)


def _raw(m, name):
    """Raw (input-base) numeric values of parameter ``name`` of ANDES model ``m``."""
    p = getattr(m, name)
    v = getattr(p, "vin", None)
    if v is None:
        v = p.v
    return np.asarray(v, dtype=float)


def _in_service(m):
    """Number of devices of ANDES model ``m`` with ``u > 0``."""
    if m.n == 0:
        return 0
    if "u" not in m.params:
        return m.n
    return int(np.sum(_raw(m, "u") > 0))


def _params(cls, m, k):
    """Values of the weakgrid parameters of ``cls`` read by name from ANDES device ``k`` of ``m``
    (those ANDES has: weakgrid's own flags, e.g. the conventions, keep their defaults)."""
    return {p.name: float(_raw(m, p.name)[k]) for p in cls.params if p.name in m.params}


def psse_branch_sn(ss):
    """Power base ``Sn`` [MVA] of each ANDES ``Line``'s ``r``, ``x``, ``b``, as the data mean it.

    In a PSS/E ``.raw`` file the impedances of non-transformer branches are per unit on the
    system base ``SBASE``, but ANDES 2.0's PSS/E parser leaves their ``Sn`` at the ``Line``
    default of 100 MVA, so with ``SBASE != 100`` ANDES scales them by ``SBASE/100`` (the
    ``nordic44`` case, ``SBASE`` = 1000 MVA: lines ten times too long, no power flow).
    For a case read from PSS/E (``ss.files.input_format == "psse"``) every non-transformer
    branch (``trans == 0``) is read on the system base ``ss.config.mva``; other inputs and
    transformers keep their ``Sn``.

    Returns
    -------
    Sn : ndarray
        Base of each line [MVA].
    rebased : list
        ANDES idx of the lines whose ``Sn`` differed from the system base and were rebased.
    """
    line = ss.Line
    Sn = _raw(line, "Sn").copy()
    files = getattr(ss, "files", None)
    if line.n == 0 or getattr(files, "input_format", None) != "psse":
        return Sn, []
    Sb = float(ss.config.mva)
    fix = (_raw(line, "trans") == 0) & (Sn != Sb)
    Sn[fix] = Sb
    return Sn, [line.idx.v[k] for k in np.nonzero(fix)[0]]


def _psse_note(n, Sb):
    return (f"PSS/E data: {n} non-transformer branches read on the system base {Sb:g} MVA "
            "(ANDES 2.0's parser leaves their Sn at 100 MVA)")


def fix_psse_branch_base(ss):
    """Give the non-transformer branches of a PSS/E case read by ANDES their true base.

    Sets ``Sn`` = system base on the ANDES ``Line`` devices that :func:`psse_branch_sn`
    rebases, so that ANDES itself (e.g. a peer run) sees the data as :func:`from_andes`
    reads them. Call it on a system loaded with ``setup=False``, before ``ss.setup()``.

    Returns
    -------
    list of str
        A note for :attr:`System.import_notes` (empty if nothing changed).
    """
    Sn, rebased = psse_branch_sn(ss)
    if not rebased:
        return []
    if getattr(ss, "is_setup", False):
        raise DataError("ANDES system", "is_setup", True,
                        "rebase the PSS/E branches before ss.setup(): load with andes.load(..., "
                        "setup=False), call fix_psse_branch_base(ss), then ss.setup()")
    pos = {ix: k for k, ix in enumerate(ss.Line.idx.v)}
    for ix in rebased:
        ss.Line.Sn.v[pos[ix]] = float(Sn[pos[ix]])
    return [_psse_note(len(rebased), float(ss.config.mva))]


def psse_dyr_dropped(ss):
    """PSS/E dynamic models of the case's ``.dyr`` that ANDES's parser did not read.

    ANDES reads a ``.dyr`` record only for the models its PSS/E table
    (``andes/io/psse-dyr.yaml``) knows and drops the others with a log warning; the case
    would then run without them (e.g. ``nordic44``: 12 ``IEEET2`` exciters and 53 ``STAB2A``
    stabilizers). Returns ``{model: number of records}``; empty for other inputs.
    """
    dyr = getattr(ss, "dyr_dict", None) or {}
    if not dyr:
        return {}
    import os

    import yaml
    from andes.io import psse

    with open(os.path.join(os.path.dirname(psse.__file__), "psse-dyr.yaml")) as f:
        known = yaml.safe_load(f) or {}
    return {m: len(df) for m, df in dyr.items() if m not in known}


def check_supported(ss):
    """Raise one :class:`DataError` listing every ANDES model with in-service devices weakgrid lacks."""
    sup = _supported()
    missing = {name: _in_service(mdl) for name, mdl in ss.models.items()
               if name not in sup and _in_service(mdl) > 0}
    dropped = psse_dyr_dropped(ss)
    missing.update(dropped)
    if missing:
        lst = ", ".join(f"{k} ({v}{', in the .dyr, not read by ANDES' if k in dropped else ''})"
                        for k, v in sorted(missing.items()))
        raise DataError("ANDES case", "models", sorted(missing),
                        f"models not supported by weakgrid.sim (in-service devices): {lst}. "
                        f"Supported: {sorted(sup)}. Set their u = 0 or remove them"
                        + (" (models ANDES does not read: delete their records from the .dyr to "
                           "run the case without them)" if dropped else ""))


def _check_islands(case, bus_names):
    """Every island of the in-service branch graph needs a slack bus; refuse naming the buses."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    B, L = case["bus"], case["branch"]
    nb = B.shape[0]
    on = L[:, 10] > 0
    at = {int(b): i for i, b in enumerate(B[:, 0])}
    f = np.array([at[int(b)] for b in L[on, 0]], dtype=int)
    t = np.array([at[int(b)] for b in L[on, 1]], dtype=int)
    A = coo_matrix((np.ones(len(f)), (f, t)), shape=(nb, nb))
    ncomp, lab = connected_components(A, directed=False)
    bad = []
    for c in range(ncomp):
        members = np.nonzero(lab == c)[0]
        if not np.any(B[members, 1] == 3):
            bad.append([bus_names[i] for i in members])
    if bad:
        raise DataError("ANDES case", "island", bad,
                        f"the bus groups {'; '.join(map(str, bad))} form islands without a slack (reference) "
                        "bus; add a Slack device in each, connect them, or remove their buses")
    return ncomp


def from_andes(ss, include_events: bool = True, conventions: str = "standard", static_gens: str = "ideal"):
    """Build a weakgrid :class:`System` and its event list from an ANDES system.

    Parameters
    ----------
    ss : andes.System
        Loaded with ``setup=False`` (the raw device data are read), from an
        ANDES file or a PSS/E ``.raw`` + ``.dyr`` pair
        (``andes.load(raw, addfile=dyr, setup=False)``).
    include_events : bool
        Convert ANDES ``Toggle`` (line) and ``Fault`` devices into weakgrid events.
    conventions : {"standard", "andes"}
        ``"standard"``: models follow their standard block diagrams. ``"andes"``: models
        reproduce ANDES 2.0's departures from them (:data:`ANDES_CONVENTIONS`; e.g. EXAC1
        and ESDC2A without their sensing lag, IEEEX1 with constant regulator limits), for
        peer comparisons.
    static_gens : {"ideal", "refuse"}
        What to do with an in-service ``Slack``/``PV`` that no dynamic model replaces:
        ``"ideal"`` simulates it as ANDES does (an ideal source, see the module docstring;
        noted in ``system.import_notes``), ``"refuse"`` raises :class:`DataError` naming them.

    Returns
    -------
    system : System
        Not yet set up (call :meth:`System.setup`). ``system.import_notes``
        lists what was ignored or skipped.
    events : list
        weakgrid events equivalent to the case's own timed events.
    """
    if conventions not in CONVENTIONS:
        raise DataError("from_andes", "conventions", conventions,
                        f"must be one of {CONVENTIONS}: 'standard' (IEEE/PSS/E block diagrams) or "
                        "'andes' (ANDES 2.0's departures from them, for peer comparisons)")
    if static_gens not in ("ideal", "refuse"):
        raise DataError("from_andes", "static_gens", static_gens,
                        "use 'ideal' (simulate them as ANDES does) or 'refuse'")
    check_supported(ss)
    reg = _registry()
    notes = []
    applied = {}
    for name in sorted(_IGNORED - {"Area", "Summary"}):
        if name in ss.models and ss.models[name].n:
            notes.append(f"{name} ({ss.models[name].n}): measurement-only, ignored")
    Sb = float(ss.config.mva)
    bus = ss.Bus
    # out-of-service buses (u = 0) are dropped with every line and device on them: ANDES
    # disconnects them (their lines go out of service, their equations are frozen)
    on_bus = _raw(bus, "u") > 0
    off = [b for b, u in zip(bus.idx.v, on_bus) if not u]
    if off:
        notes.append(f"Bus {off}: out of service (u = 0); dropped with every line and device on them")
    nb = int(on_bus.sum())
    bidx = [b for b, u in zip(bus.idx.v, on_bus) if u]
    pos = {b: i for i, b in enumerate(bidx)}
    num, kept = bus_numbers(bidx)   # ANDES bus idx -> weakgrid bus number (the idx if integer)
    if not kept:
        notes.append("Bus idx are not all integers: buses numbered 1..n in the case's order "
                     "(system.andes_bus_id maps each idx to its number)")
    Vn_bus = _raw(bus, "Vn")[on_bus]
    B = np.zeros((nb, 13))
    B[:, 0] = [num[b] for b in bidx]
    B[:, 1] = 1
    B[:, 6] = 1
    B[:, 7] = _raw(bus, "v0")[on_bus]
    B[:, 8] = np.degrees(_raw(bus, "a0")[on_bus])
    B[:, 9] = Vn_bus
    B[:, 10] = 1
    B[:, 11] = _raw(bus, "vmax")[on_bus]
    B[:, 12] = _raw(bus, "vmin")[on_bus]

    def on_off_bus(m, k, *fields):
        if all(getattr(m, f).v[k] in pos for f in fields):
            return False
        if _raw(m, "u")[k] > 0:
            notes.append(f"{m.class_name} {m.idx.v[k]}: on an out-of-service bus, dropped")
        return True

    pq = ss.PQ
    for k in range(pq.n):
        if _raw(pq, "u")[k] > 0 and not on_off_bus(pq, k, "bus"):
            i = pos[pq.bus.v[k]]
            B[i, 2] += _raw(pq, "p0")[k] * Sb
            B[i, 3] += _raw(pq, "q0")[k] * Sb
    if "Shunt" in ss.models:
        sh = ss.Shunt
        for k in range(sh.n):
            if _raw(sh, "u")[k] > 0 and not on_off_bus(sh, k, "bus"):
                i = pos[sh.bus.v[k]]
                Sn, Vn = _raw(sh, "Sn")[k], _raw(sh, "Vn")[k]
                # b [pu on (Sn, Vn)] -> system base at the bus voltage: x (Sn/Sb) (Vb/Vn)^2 (as ANDES)
                c = (Sn / Sb) * (Vn_bus[i] / Vn) ** 2 if Vn > 0 else Sn / Sb
                B[i, 4] += _raw(sh, "g")[k] * c * Sb
                B[i, 5] += _raw(sh, "b")[k] * c * Sb
    G = []
    gen_row = {}
    for mname, btype in (("Slack", 3), ("PV", 2)):
        m = ss.models[mname]
        for k in range(m.n):
            if on_off_bus(m, k, "bus"):
                gen_row[m.idx.v[k]] = None   # its machine or converter is skipped
                continue
            i = pos[m.bus.v[k]]
            u = _raw(m, "u")[k]
            if u > 0:
                B[i, 1] = max(B[i, 1], btype) if btype == 2 else 3
            else:
                notes.append(f"{mname} {m.idx.v[k]}: out of service (u = 0), skipped")
            v0 = _raw(m, "v0")[k]
            if u > 0:
                B[i, 7] = v0
                if mname == "Slack":
                    B[i, 8] = np.degrees(_raw(m, "a0")[k])
            row = np.zeros(21)
            row[0] = num[m.bus.v[k]]
            row[1] = _raw(m, "p0")[k] * Sb
            row[2] = _raw(m, "q0")[k] * Sb
            row[3], row[4] = 9999.0, -9999.0
            row[5] = v0
            row[6] = _raw(m, "Sn")[k]
            row[7] = 1 if u > 0 else 0
            row[8], row[9] = 9999.0, -9999.0
            gen_row[m.idx.v[k]] = len(G)
            G.append(row)
    line = ss.Line
    L = np.zeros((line.n, 13))
    line_sn, rebased = psse_branch_sn(ss)
    if rebased:
        notes.append(_psse_note(len(rebased), Sb))
    lrow = {}   # ANDES Line idx -> row of L (lines on out-of-service buses have none)
    for k in range(line.n):
        if on_off_bus(line, k, "bus1", "bus2"):
            continue
        kk = len(lrow)
        lrow[line.idx.v[k]] = kk
        i, j = pos[line.bus1.v[k]], pos[line.bus2.v[k]]
        Sn, Vn1 = line_sn[k], _raw(line, "Vn1")[k]
        zc = (Vn1 ** 2 / Sn) / (Vn_bus[i] ** 2 / Sb)
        g, g1, g2 = _raw(line, "g")[k], _raw(line, "g1")[k], _raw(line, "g2")[k]
        b, b1, b2 = _raw(line, "b")[k], _raw(line, "b1")[k], _raw(line, "b2")[k]
        if g or g1 or g2:
            raise DataError(f"ANDES Line {line.idx.v[k]}", "g", g, "line conductances are not supported; set g=g1=g2=0")
        if b1 != b2:
            raise DataError(f"ANDES Line {line.idx.v[k]}", "b1", b1, "asymmetric line charging (b1 != b2) unsupported")
        tap = _raw(line, "tap")[k]
        L[kk, :] = [num[line.bus1.v[k]], num[line.bus2.v[k]], _raw(line, "r")[k] * zc,
                    _raw(line, "x")[k] * zc, (b + b1 + b2) / zc,
                    0, 0, 0, 0 if tap == 1 else tap, np.degrees(_raw(line, "phi")[k]),
                    1 if _raw(line, "u")[k] > 0 else 0, -360, 360]
    L = L[:len(lrow)]
    bus_name = dict(zip(bus.idx.v, bus.name.v)) if "name" in bus.params else {}
    case = {"baseMVA": Sb, "bus": B, "gen": np.array(G), "branch": L,
            "branch_names": [str(ix) for ix in lrow],      # Line idx, in row order
            "bus_names": {num[b]: str(bus_name[b]) for b in bidx
                          if bus_name.get(b) not in (None, "") and str(bus_name[b]) != str(b)}}
    _check_islands(case, bidx)
    fn = 60.0
    if "GENROU" in ss.models and ss.GENROU.n:
        fn = float(_raw(ss.GENROU, "fn")[0])
    elif "GENCLS" in ss.models and ss.GENCLS.n:
        fn = float(_raw(ss.GENCLS, "fn")[0])
    system = System(_network(case, fn))
    names_of = {}     # (ANDES model, idx) -> weakgrid name, unique over the whole system

    def name_of(mname, ix):
        key = (mname, ix)
        if key not in names_of:
            taken = set(names_of.values())
            name = device_name(mname, ix)
            if name in taken:        # a kept idx ("GENROU_1") meets a GENROU 1: prefix it
                name = f"{mname}_{str(ix).strip()}"
            if name in taken:
                raise DataError(f"ANDES {mname} {ix}", "idx", ix,
                                f"two devices would both be named '{name}'; give them distinct idx")
            names_of[key] = name
        return names_of[key]
    # machines
    syn_name = {}
    for mname, cls in reg.items():
        m = ss.models.get(mname)
        if cls.kind != "machine" or m is None:
            continue
        for k in range(m.n):
            if _raw(m, "u")[k] <= 0:
                notes.append(f"{mname} {m.idx.v[k]}: out of service (u = 0), skipped")
                continue
            if gen_row[m.gen.v[k]] is None or G[gen_row[m.gen.v[k]]][7] <= 0:
                notes.append(f"{mname} {m.idx.v[k]}: its static generator {m.gen.v[k]} is out of service, skipped")
                continue
            name = name_of(mname, m.idx.v[k])
            system.add_machine(mname, name, gen_row[m.gen.v[k]], **_params(cls, m, k))
            syn_name[m.idx.v[k]] = name
    # machine controls: exciters and governors link to `syn`, stabilizers and compensators to `avr`
    avr_syn = {}
    add = {"exciter": system.add_exciter, "governor": system.add_governor, "pss": system.add_pss,
           "compensator": system.add_compensator}
    for kind in ("exciter", "governor", "pss", "compensator"):
        for mname, cls in reg.items():
            m = ss.models.get(mname)
            if cls.kind != kind or m is None:
                continue
            for k in range(m.n):
                dev = f"{mname} {m.idx.v[k]}"
                if _raw(m, "u")[k] <= 0:
                    notes.append(f"{dev}: out of service (u = 0), skipped")
                    continue
                syn = avr_syn.get(m.avr.v[k]) if kind in ("pss", "compensator") else syn_name.get(m.syn.v[k])
                if syn is None:
                    notes.append(f"{dev}: its machine is out of service, skipped")
                    continue
                name = name_of(mname, m.idx.v[k])
                params = _params(cls, m, k)
                extra = {}
                if mname == "ST2CUT":
                    params["MODE2"] = 0.0 if not np.isfinite(params["MODE2"]) else params["MODE2"]
                    for fld in ("busr", "busr2"):
                        if getattr(m, fld).v[k] not in (None, ""):
                            raise DataError(f"ANDES ST2CUT {m.idx.v[k]}", fld, getattr(m, fld).v[k],
                                            "remote-bus inputs are not supported; leave it empty")
                if mname == "IEEEG1" and m.syn2.v[k] not in (None, ""):
                    extra["machine2"] = syn_name[m.syn2.v[k]]   # cross-compound: LP machine
                if kind == "exciter":
                    avr_syn[m.idx.v[k]] = syn
                if conventions == "andes" and mname in ANDES_CONVENTIONS:
                    params.update(ANDES_CONVENTIONS[mname])
                    applied[mname] = applied.get(mname, 0) + 1
                add[kind](mname, name, syn, **extra, **params)
    # devices that are not machine controls (renewables, loads): their own importers
    dev_name = {}
    for mname, cls in reg.items():
        m = ss.models.get(mname)
        if cls.kind != "device" or m is None or not m.n:
            continue
        comp = system._component(mname, "device")
        for k in range(m.n):
            dev = f"{mname} {m.idx.v[k]}"
            if _raw(m, "u")[k] <= 0:
                notes.append(f"{dev}: out of service (u = 0), skipped")
                continue
            link = cls.andes_link(m, k, gen_row=gen_row, pos=pos, dev_name=dev_name, Sb=Sb, ss=ss)
            if link is None or ("gen" in link and link["gen"] is None):
                notes.append(f"{dev}: the device it controls is out of service, skipped")
                continue
            name = name_of(mname, m.idx.v[k])
            values = _params(cls, m, k)
            if hasattr(cls, "andes_params"):
                values = cls.andes_params(m, k, ss, values)
            if conventions == "andes" and mname in ANDES_CONVENTIONS:
                values.update(ANDES_CONVENTIONS[mname])
                applied[mname] = applied.get(mname, 0) + 1
            comp.add(name, link, values)
            dev_name[(mname, m.idx.v[k])] = name
    # every in-service static generator needs a dynamic model (machine or converter)
    used = {lk["gen"] for c in system.components.values() for lk in c.links if "gen" in lk}
    bare = [(mname, ix, m.bus.v[k]) for mname in ("Slack", "PV") for m in [ss.models[mname]]
            for k, ix in enumerate(m.idx.v) if _raw(m, "u")[k] > 0 and gen_row[ix] not in used | {None}]
    if bare and static_gens == "refuse":
        names = [f"{mname} {ix} (bus {b})" for mname, ix, b in bare]
        raise DataError("ANDES case", "StaticGen", names,
                        f"the static generators {names} have no in-service dynamic model (machine or "
                        "converter); add one or set their u = 0")
    # as ANDES: their power-flow equations stay in the time domain (weakgrid.sim.sources)
    for mname, ix, b in bare:
        src = "InfiniteBus" if mname == "Slack" else "PVSource"
        system._component(src, "device").add_source(name_of(mname, ix), gen_row[ix])
        what = ("an ideal voltage source (infinite bus: fixed voltage and angle, infinite "
                "inertia, unlimited current)" if mname == "Slack" else
                "a constant-P, constant-|V| source (no inertia, unlimited reactive power)")
        notes.append(f"{mname} {ix} (bus {b}): no dynamic model; simulated as ANDES does, as "
                     f"{what} ({src})")
    events = []
    if include_events:
        lpos = lrow
        lu = {ix: _raw(line, "u")[k] > 0 for k, ix in enumerate(line.idx.v)}
        if "Toggle" in ss.models:
            tg = ss.Toggle
            # a Toggle flips the line's status (open -> close -> open ...): replay them in time
            # order from each line's initial status, so that a trip followed by a toggle recloses
            status = {r: bool(lu[ix]) for ix, r in lrow.items()}
            order = sorted(range(tg.n), key=lambda k: float(_raw(tg, "t")[k]))
            for k in order:
                if _raw(tg, "u")[k] <= 0:
                    continue
                if tg.model.v[k] != "Line":
                    raise DataError(f"ANDES Toggle {tg.idx.v[k]}", "model", tg.model.v[k], "only Line toggles supported")
                if tg.dev.v[k] not in lpos:
                    notes.append(f"Toggle {tg.idx.v[k]}: its line {tg.dev.v[k]} is on an out-of-service bus, ignored")
                    continue
                row = lpos[tg.dev.v[k]]
                status[row] = not status[row]
                events.append(LineTrip(row, float(_raw(tg, "t")[k]), close=status[row]))
        if "Fault" in ss.models:
            fl = ss.Fault
            for k in range(fl.n):
                if _raw(fl, "u")[k] <= 0 or on_off_bus(fl, k, "bus"):
                    continue
                tc = float(_raw(fl, "tc")[k])
                events.append(Fault(num[fl.bus.v[k]], float(_raw(fl, "tf")[k]), tc if tc > 0 else None,
                                    rf=float(_raw(fl, "rf")[k]), xf=float(_raw(fl, "xf")[k])))
    system.andes_bus_id = {b: num[b] for b in bidx}
    system.andes_device = dict(names_of)   # (ANDES model, idx) -> weakgrid name
    system.andes_line_row = dict(lrow)
    for mname, n in sorted(applied.items()):
        flags = ", ".join(f"{f} = {v:g}" for f, v in ANDES_CONVENTIONS[mname].items())
        notes.append(f"{mname} ({n}): ANDES 2.0 conventions, {flags}")
    system.import_notes = notes
    system.conventions = conventions
    system.conventions_applied = dict(applied)   # model -> number of devices changed
    return system, events


def _network(case, fn):
    from ..network import Network

    return Network(case, f_hz=fn)
