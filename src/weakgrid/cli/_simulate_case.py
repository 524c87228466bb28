"""``weakgrid simulate CASE``: a plain case file simulated as it is, with command-line events.

Steps: read the case (:func:`weakgrid.sim.io.cases.load_case`), resolve the events against
its buses and branches, initialize (power flow, every device's initial state), estimate the
run (steps × recorded variables, a timed probe; refused beyond the limits unless ``--force``,
:mod:`weakgrid.sim.run_estimate`), simulate with a progress bar on stderr, print the final
state, and with ``-o`` write the run file (:func:`weakgrid.sim.runfile.write_run`).
Exit codes: 0, 2 (bad input), 3 (the run ended unstable: said on stderr, the run up to
there is still written), 130 (Ctrl-C: what was kept is said on stderr).
"""

from __future__ import annotations

import logging
import sys

import numpy as np

from ._case import case_name, describe_event, events_of
from ._common import bar_disable

log = logging.getLogger("weakgrid.cli.simulate")

T_END_DEFAULT = 20.0          # s, ANDES's default tf
DT_DEFAULT = 1 / 120          # s, the simulator's default step
DT_DPSIM = 1e-4               # s, the DPsim engines' default step (EMT: well below the period)
NOTES_SHOWN = 5


def _check_record(system, dt, record):
    """Every ``--record`` name or pattern names a signal (else the closest names)."""
    from ..sim.integrate import Simulator
    from ..sim.runfile import match_signals

    names = Simulator(system, dt=dt, record="all").run(dt, on_failure="return").names
    match_signals(names, record, "--record")


def _final_state(res) -> list[str]:
    """Lines on the last recorded instant: machine speeds, bus voltages."""
    out = []
    if not len(res.t):
        return out
    w = [n for n in res.names if n.endswith(".omega")]
    if w:
        last = np.array([res[n][-1] for n in w])
        k_lo, k_hi = int(np.argmin(last)), int(np.argmax(last))
        out.append(f"  machine speeds {last[k_lo]:.6f} ({w[k_lo]}) … {last[k_hi]:.6f} "
                   f"({w[k_hi]}) pu")
    v = [n for n in res.names if n.startswith("bus") and n.endswith(".v")]
    if v:
        last = np.array([res[n][-1] for n in v])
        k_lo, k_hi = int(np.argmin(last)), int(np.argmax(last))
        out.append(f"  bus voltages   {last[k_lo]:.4f} ({v[k_lo][:-2]}) … {last[k_hi]:.4f} "
                   f"({v[k_hi][:-2]}) pu")
    return out


def run_case(args) -> int:
    """Run ``weakgrid simulate CASE`` with the parsed ``args``; return the exit status."""
    from ..game.errors import ParameterError
    from ..sim.integrate import Simulator
    from ..sim.io.cases import load_case
    from ..sim.run_estimate import run_estimate

    out = args.output
    if out is not None and out.suffix.lower() != ".parquet":
        raise ParameterError("--output", str(out), "the run of a case is written as a Parquet "
                             "run file: give a name ending in .parquet")
    t_end = float(args.t_end) if args.t_end is not None else T_END_DEFAULT
    engine = getattr(args, "engine", None) or "phasor"
    dt = float(args.dt) if args.dt is not None else (DT_DEFAULT if engine == "phasor" else DT_DPSIM)
    case = load_case(args.study, args.dyr)
    system, net = case.system, case.system.network
    # the case file's own events (ANDES Toggle, Fault) after the end are not reached, as in ANDES
    start = lambda e: getattr(e, "t_on", getattr(e, "t", 0.0))    # noqa: E731
    late = [e for e in case.events if start(e) >= t_end]
    case.events = [e for e in case.events if start(e) < t_end]
    events = events_of(system, args) + list(case.events)
    last = max([getattr(e, "t_off", None) or getattr(e, "t_on", None) or getattr(e, "t", 0.0)
                for e in events] or [0.0])
    if events and not t_end > last:
        raise ParameterError("--t-end", t_end, f"the last event is at {last:g} s: give a longer "
                             "--t-end")
    print(f"case {case_name(args.study)} ({case.format}): {net.nb} buses, {net.nl} branches, "
          f"{len(system.machine_names)} machines")
    for n in case.notes[:NOTES_SHOWN]:
        log.info(f"  note: {n}")
    if len(case.notes) > NOTES_SHOWN:
        log.info(f"  … {len(case.notes) - NOTES_SHOWN} more import notes "
                 "(system.import_notes in Python)")
    system.setup()
    print(f"initialization: power flow converged (largest mismatch {net.pf.mismatch:.1e} pu), "
          f"{system.nx} states, {system.N - system.nx} algebraic variables")
    for e in late:
        print(f"  event: {describe_event(e)} (in the case file): after the end, not reached")
    from_file = {id(e) for e in case.events}
    for e in sorted(events, key=lambda e: getattr(e, "t_on", getattr(e, "t", 0.0))):
        print(f"  event: {describe_event(e)}" + (" (in the case file)" if id(e) in from_file
                                                 else ""))
    if not events:
        print("  no events: the run should stay at the operating point (a flat start check)")
    if engine != "phasor":
        return _run_dpsim(system, engine, t_end, dt, events, args, case)
    if args.record:
        _check_record(system, dt, args.record)
    first = min([getattr(e, "t_on", getattr(e, "t", 0.0)) for e in events] or [t_end])
    est = run_estimate(system, t_end, dt, first_event=first, record=args.record)
    if est.bytes > 2.0**28 or est.seconds > 60.0 or args.force:
        print(f"  {est.describe()}")
    est.check("--t-end", t_end, "give a shorter --t-end, a larger --dt or fewer signals "
              "(--record)", args.force)
    print(f"simulating {t_end:g} s at dt = {dt:.4g} s ({int(round(t_end / dt))} steps)")
    sim = Simulator(system, dt=dt, record=args.record)
    res, reached = _simulate(sim, t_end, events, args)
    if res is None:          # interrupted
        print(f"weakgrid simulate: interrupted at t = {reached:.4g} s of {t_end:g} s; nothing "
              "was kept" + (f" ({out} was not written: a run file is written only when the "
                            "run ends)" if out else ""), file=sys.stderr, flush=True)
        return 130
    t_last = float(res.t[-1]) if len(res.t) else 0.0
    print(f"final state at t = {t_last:.4g} s ({res.stats.get('steps', 0)} steps, "
          f"{len(res.names)} signals recorded):")
    for line in _final_state(res):
        print(line)
    if out is not None:
        from ..sim.runfile import write_run

        meta = {"command": "weakgrid simulate", "case": str(args.study),
                "case_format": case.format,
                "dyr": None if args.dyr is None else str(args.dyr),
                "events": [describe_event(e) for e in events], "t_end": t_end, "dt": dt}
        write_run(out, res, samples=None, meta=meta)
        print(f"wrote {out}" + ("" if res.ok else f" (the run up to t = {t_last:.4g} s)"))
    if not res.ok:
        print(f"weakgrid simulate: the run ended unstable: {res.failure}", file=sys.stderr,
              flush=True)
        return 3
    return 0


def _run_dpsim(system, engine, t_end, dt, events, args, case) -> int:
    """The case in a DPsim engine (:func:`weakgrid.sim.emt.simulate_dpsim`): models and events
    DPsim lacks are refused by name before any step; ``--record`` selects among its signals."""
    from ..sim.emt import simulate_dpsim
    from ..sim.runfile import match_signals, write_run

    print(f"simulating {t_end:g} s in DPsim ({engine}) at dt = {dt:.4g} s "
          f"({int(round(t_end / dt))} steps)")
    res = simulate_dpsim(system, t_end, engine=engine, dt=dt, events=events)
    if args.record:
        res = res.subset(match_signals(res.names, args.record, "--record"))
    print(f"final state at t = {float(res.t[-1]):.4g} s ({res.stats['steps']} steps, "
          f"{len(res.names)} signals recorded, {res.stats['wall_s']:.2f} s):")
    for line in _final_state(res):
        print(line)
    out = args.output
    if out is not None:
        from ._case import describe_event

        meta = {"command": "weakgrid simulate", "case": str(args.study), "case_format": case.format,
                "dyr": None if args.dyr is None else str(args.dyr), "engine": engine,
                "events": [describe_event(e) for e in events], "t_end": t_end, "dt": dt}
        write_run(out, res, samples=None, meta=meta)
        print(f"wrote {out}")
    if not res.ok:
        print(f"weakgrid simulate: the run ended unstable: {res.failure}", file=sys.stderr,
              flush=True)
        return 3
    return 0


def _simulate(sim, t_end, events, args):
    """``(results, t)`` of the run, or ``(None, t reached)`` on Ctrl-C; a tqdm bar on
    stderr in simulated seconds."""
    from tqdm.auto import tqdm

    bar = tqdm(total=round(t_end, 6), unit="s", desc="  simulating", leave=False,
               disable=bar_disable(args),
               bar_format="{l_bar}{bar}| {n:.3g}/{total:.3g} s [{elapsed}<{remaining}]")
    reached = [0.0]

    def progress(t):
        if t - bar.n >= 1e-3 * t_end:
            bar.update(t - bar.n)
        reached[0] = t

    try:
        res = sim.run(t_end, events=events, on_failure="return", progress=progress)
    except KeyboardInterrupt:
        return None, reached[0]
    finally:
        bar.close()
    return res, reached[0]
