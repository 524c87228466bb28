"""The report's protocol, in words, from a study's own data: its grid, machine, UPQC,
scenarios (every event: bus, time, duration, impedance), controllers by their full names and
claims. Text about one study (the paper's protocol) comes from that study's ``[report] notes``,
never from here."""

from __future__ import annotations

__all__ = ["CONTROLLER_NAMES", "controller_name", "describe_event", "protocol_of",
           "speed_machine"]

# controller kind -> full name (the kinds of weakgrid.study.controllers)
CONTROLLER_NAMES = {
    "hji": "HJI game-theoretic controller",
    "hji-bounded": "HJI controller trained with the rating bound",
    "nonlinear-29": "initial nonlinear controller (29)",
    "lqr": "discrete LQR of the design model",
    "pq": "PQ control of the GTI (no UPQC)",
    "pss-only": "PSS only (UPQC idle)",
    "none": "no supplementary control (UPQC idle, PSS out)",
    "file": "trained controller from a file",
}


def controller_name(study, name: str) -> str:
    """The full name of the study's controller ``name`` (its kind's name; ``name`` itself
    when it is not the kind, e.g. ``"hji-high (HJI game-theoretic controller)"``)."""
    from .controllers import controller_kind

    kind = controller_kind(study, name)
    full = CONTROLLER_NAMES.get(kind, kind)
    return full if name == kind else f"{name} ({full})"


def _bus(b) -> str:
    return str(b) if str(b).lower().startswith("bus") else f"bus {b}"


def _t(x) -> str:
    return f"{float(x):g} s"


def describe_event(ev: dict) -> str:
    """One event of a scenario in words (bus, time, duration, impedance)."""
    kind = ev.get("kind")
    if kind == "fault":
        t_on = float(ev["t_on"])
        t_off = float(ev["t_off"]) if "t_off" in ev else t_on + float(ev["duration"])
        return (f"three-phase fault at {_bus(ev['bus'])} at t = {_t(t_on)} for "
                f"{(t_off - t_on) * 1e3:g} ms (cleared at {_t(t_off)}), fault impedance "
                f"{float(ev.get('rf', 0.0)):g} + j{float(ev.get('xf', 0.0)):g} pu")
    if kind == "line_trip":
        b = ev["branch"]
        br = f"{b['from']}–{b['to']}" if isinstance(b, dict) else str(b)
        return (f"branch {br} {'closes' if ev.get('close') else 'opens'} at t = "
                f"{_t(ev['t'])}")
    if kind == "gen_trip":
        return (f"machine {ev['machine']} trips (disconnected with its controls) at t = "
                f"{_t(ev['t'])}")
    if kind == "load_step":
        return (f"load step at {_bus(ev['bus'])} at t = {_t(ev['t'])}: ΔP = "
                f"{float(ev.get('dP', 0.0)):g} MW, ΔQ = {float(ev.get('dQ', 0.0)):g} Mvar")
    return ", ".join(f"{k} = {v}" for k, v in ev.items())


def speed_machine(study) -> str | None:
    """The synchronous machine whose speed the report draws (as the run's ``sg_speed``
    signal, :func:`weakgrid.study.build.build_setup`): ``report.speed_of``, else the
    controlled machine when it is an SG, else the first ``[[dynamics.generator]]``; None when
    there is none (``speed_of = ""``)."""
    from .build import _first_generator

    d = study.data
    speed_of = d.get("report", {}).get("speed_of")
    if speed_of is not None:
        return speed_of or None
    name = d["machine"]["name"]
    gti = any(g["name"] == name for g in d.get("dynamics", {}).get("gti", []))
    return (_first_generator(d) if gti else name) or None


def protocol_of(study, quick: bool = False) -> list[str]:
    """The protocol paragraphs of ``study`` from its own data."""
    d = study.data
    g, m, up = d["grid"], d["machine"], d.get("upqc") or {}
    src = g.get("network") or g.get("file") or g.get("case")
    grid = f"{g['kind']} network {src}" if src else f"{g['kind']} grid given in the study file"
    gti = any(x["name"] == m["name"] for x in d.get("dynamics", {}).get("gti", []))
    out = [f"{study.name}: {d['study'].get('title', study.name)}. Grid: {grid}; controlled "
           f"machine {m['name']} ({'a grid-tied inverter' if gti else 'a synchronous machine'})"
           + (f"; speed drawn and measured: {speed_machine(study)}" if speed_machine(study)
              else "") + "."]
    if up:
        ins = up.get("insert") or {}
        into = " ".join(str(ins[k]) for k in ("element", "index", "branch", "name") if k in ins)
        where = (f", inserted in {into or 'its branch'} at its {ins.get('side', 'from')} end "
                 f"(series reactance x = {ins['x']:g} pu)" if ins and "x" in ins else "")
        name = up.get("name", "UPQC")
        out.append(f"{'UPQC' if name == 'UPQC' else f'UPQC {name}'}: "
                   f"{up.get('structure', '')} structure, rating "
                   f"|Vu|max = {up.get('rating', float('nan')):g} pu{where}.")
    for sc in study.scenarios(quick):
        ev = "; ".join(describe_event(e) for e in sc["events"]) or "no event"
        ctl = ", ".join(controller_name(study, c) for c in sc["controllers"])
        out.append(f"Scenario {sc['id']} ({sc['load']} load, {sc['upqc']} UPQC, "
                   f"{float(sc['t_end']):g} s): {ev}. Controllers: {ctl}.")
    claims = d.get("claims") or []
    out.append(f"Claims: {len(claims)} ({', '.join(c['id'] for c in claims)}), each judged "
               "by the rule stated beside it." if claims else
               "Claims: none; the table \"Who did best\" compares the controllers.")
    return out
