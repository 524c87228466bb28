"""A plain case on the command line: telling it from a study, and its events
(``--fault``, ``--trip``, ``--load-step``) parsed and resolved against the case's buses and
branches.

Each option's value is checked for its form when the command line is read (argparse: exit 2,
naming the option, the value and the form), and its bus or branch when the case is loaded
(:class:`~weakgrid.game.errors.ParameterError` naming the option, the value and the buses or
branches the case has).
"""

from __future__ import annotations

import argparse
import math
from dataclasses import dataclass
from pathlib import Path

FAULT_FORM = "BUS,T_ON,T_OFF[,XF] (e.g. 103,1.0,1.1 or 103,1.0,1.1,0.01: times in s, XF in pu)"
TRIP_FORM = "BRANCH,T (BRANCH a 0-based branch row, FROM-TO or FROM-TO-CKT, e.g. 101-103-1,1.0)"
STEP_FORM = "BUS,T,DP[,DQ] (e.g. 103,1.0,50 or 103,1.0,50,10: MW, Mvar)"


def is_case(target) -> bool:
    """A plain case file (by its suffix: .raw, .m, .mat, .json, .xlsx), not a study."""
    from ..sim.io.cases import case_format

    return case_format(target) is not None


@dataclass(frozen=True)
class EventArg:
    """One event of the command line, its references unresolved."""

    option: str
    text: str
    ref: object
    values: tuple


def _ref(s: str):
    s = s.strip()
    return int(s) if s.lstrip("-").isdigit() else s


def _times(option, text, parts, form):
    out = []
    for p in parts:
        try:
            v = float(p)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{text!r}: {p.strip()!r} is not a number; "
                                             f"give {option} {form}") from None
        if not math.isfinite(v):
            raise argparse.ArgumentTypeError(f"{text!r}: {p.strip()!r} is not finite; "
                                             f"give {option} {form}")
        out.append(v)
    return out


def _split(option, text, form, lo, hi):
    parts = [p for p in str(text).split(",")]
    if not lo <= len(parts) <= hi or not parts[0].strip():
        raise argparse.ArgumentTypeError(f"{text!r} has {len(parts)} field(s); give "
                                         f"{option} {form}")
    return parts


def fault_arg(text) -> EventArg:
    """``BUS,T_ON,T_OFF[,XF]``: a three-phase fault through ``j XF`` (default 1e-4 pu, as
    ANDES) from T_ON to T_OFF [s]."""
    parts = _split("--fault", text, FAULT_FORM, 3, 4)
    v = _times("--fault", text, parts[1:], FAULT_FORM)
    if v[0] < 0 or not v[1] > v[0]:
        raise argparse.ArgumentTypeError(f"{text!r}: need 0 ≤ T_ON < T_OFF; give --fault "
                                         f"{FAULT_FORM}")
    if len(v) == 3 and not v[2] > 0:
        raise argparse.ArgumentTypeError(f"{text!r}: XF must be > 0 pu; give --fault "
                                         f"{FAULT_FORM}")
    return EventArg("--fault", str(text), _ref(parts[0]), tuple(v))


def trip_arg(text) -> EventArg:
    """``BRANCH,T``: the branch opens at T [s]."""
    parts = _split("--trip", text, TRIP_FORM, 2, 2)
    v = _times("--trip", text, parts[1:], TRIP_FORM)
    if v[0] < 0:
        raise argparse.ArgumentTypeError(f"{text!r}: T must be ≥ 0 s; give --trip {TRIP_FORM}")
    return EventArg("--trip", str(text), _ref(parts[0]), tuple(v))


def load_step_arg(text) -> EventArg:
    """``BUS,T,DP[,DQ]``: constant-impedance load added at T [s] (MW, Mvar at the
    power-flow voltage; negative removes load)."""
    parts = _split("--load-step", text, STEP_FORM, 3, 4)
    v = _times("--load-step", text, parts[1:], STEP_FORM)
    if v[0] < 0:
        raise argparse.ArgumentTypeError(f"{text!r}: T must be ≥ 0 s; give --load-step "
                                         f"{STEP_FORM}")
    return EventArg("--load-step", str(text), _ref(parts[0]), tuple(v))


# ----------------------------------------------------------------- resolution
def _listing(items, n=24) -> str:
    items = list(items)
    head = ", ".join(map(str, items[:n]))
    return head + (f", … ({len(items)} in all)" if len(items) > n else "")


def bus_number(system, ev: EventArg) -> int:
    """The simulator's bus number of ``ev.ref``: a bus number, a PSS/E bus name or an ANDES
    bus idx."""
    from ..game.errors import ParameterError

    ref = ev.ref
    andes = getattr(system, "andes_bus_id", None)
    if andes:
        hit = {str(k): v for k, v in andes.items()}.get(str(ref))
        if hit is not None:
            return int(hit)
    names = getattr(system, "psse_bus_name", None)
    if names and isinstance(ref, str):
        hit = [b for b, nm in names.items() if str(nm).strip() == ref.strip()]
        if len(hit) == 1:
            return int(hit[0])
    ids = [int(b) for b in system.network.bus_ids]
    if isinstance(ref, int) and ref in ids:
        return ref
    known = list(andes) if andes else ids
    raise ParameterError(ev.option, ev.text, f"the case has no bus {ref!r}; its buses: "
                         f"{_listing(known)}")


def branch_row(system, ev: EventArg) -> int:
    """The 0-based branch row of ``ev.ref``: a row, ``FROM-TO`` or ``FROM-TO-CKT`` (PSS/E),
    or an ANDES ``Line`` idx."""
    from ..game.errors import ParameterError
    from ..sim.network import F_BUS, T_BUS

    ref, net = ev.ref, system.network
    rows = getattr(system, "andes_line_row", None) or {}
    if str(ref) in {str(k) for k in rows}:
        return int({str(k): v for k, v in rows.items()}[str(ref)])
    if isinstance(ref, int):
        if 0 <= ref < net.nl:
            return ref
        raise ParameterError(ev.option, ev.text, f"the case has branch rows 0..{net.nl - 1}; "
                             "give a row or FROM-TO[-CKT]")
    parts = str(ref).split("-")
    ends = [p for p in parts[:2] if p.strip().isdigit()]
    if len(parts) not in (2, 3) or len(ends) != 2:
        raise ParameterError(ev.option, ev.text, "give the branch as a 0-based row, FROM-TO or "
                             f"FROM-TO-CKT (bus numbers){_andes_hint(rows)}")
    i, j = int(parts[0]), int(parts[1])
    psse = getattr(system, "psse_branch_row", None) or {}
    if len(parts) == 3 and psse:
        for (fi, fj, c), row in psse.items():
            if {int(fi), int(fj)} == {i, j} and str(c).strip() == parts[2].strip():
                return int(row)
        raise ParameterError(ev.option, ev.text, f"no branch {i}-{j} with circuit id "
                             f"'{parts[2]}'; the case's branches: "
                             f"{_listing(f'{a}-{b}-{str(c).strip()}' for a, b, c in psse)}")
    hits = [k for k in range(net.nl) if {int(net.branch[k, F_BUS]), int(net.branch[k, T_BUS])}
            == {i, j}]
    if len(hits) == 1:
        return hits[0]
    if not hits:
        pairs = [f"{int(net.branch[k, F_BUS])}-{int(net.branch[k, T_BUS])}" for k in range(net.nl)]
        raise ParameterError(ev.option, ev.text, f"no branch between buses {i} and {j}; the "
                             f"case's branches: {_listing(pairs)}")
    raise ParameterError(ev.option, ev.text, f"{len(hits)} parallel branches between {i} and "
                         f"{j} (rows {hits}): give the row, or FROM-TO-CKT for a PSS/E case")


def _andes_hint(rows):
    return f", or an ANDES Line idx ({_listing(rows, 8)})" if rows else ""


def events_of(system, args) -> list:
    """The weakgrid events of ``args.fault``, ``args.trip`` and ``args.load_step``."""
    from ..sim.events import Fault, LineTrip, LoadStep

    out = []
    for ev in args.fault or []:
        t_on, t_off, *xf = ev.values
        out.append(Fault(bus_number(system, ev), t_on, t_off, xf=xf[0] if xf else 1e-4))
    for ev in args.trip or []:
        out.append(LineTrip(branch_row(system, ev), ev.values[0]))
    for ev in args.load_step or []:
        t, dp, *dq = ev.values
        out.append(LoadStep(bus_number(system, ev), t, dp, dq[0] if dq else 0.0))
    return out


def describe_event(e) -> str:
    """One line of an event."""
    from ..sim.events import Fault, LineTrip, LoadStep

    if isinstance(e, Fault):
        return (f"fault at bus {e.bus} from {e.t_on:g} s to {e.t_off:g} s "
                f"(rf = {e.rf:g}, xf = {e.xf:g} pu)")
    if isinstance(e, LineTrip):
        return f"branch row {e.branch} {'closes' if e.close else 'opens'} at {e.t:g} s"
    if isinstance(e, LoadStep):
        return f"load step at bus {e.bus} at {e.t:g} s: {e.dP:+g} MW, {e.dQ:+g} Mvar"
    return repr(e)


def case_name(path) -> str:
    return Path(str(path)).name
