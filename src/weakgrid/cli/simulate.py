"""``weakgrid simulate``: one scenario of a study with one controller, or a plain case.

Two forms, told apart by the argument:

* ``weakgrid simulate STUDY`` — a study file (``.toml``) or a shipped study's name: one
  scenario with one controller, its metrics printed;
* ``weakgrid simulate CASE`` — a case file (PSS/E ``.raw`` with ``--dyr``, MATPOWER ``.m``/
  ``.mat``, pandapower ``.json``, ANDES ``.xlsx``/``.json``): the grid as it is, no study and
  no UPQC, with the events of ``--fault``/``--trip``/``--load-step`` (as ``andes run case.raw
  --addfile case.dyr -r tds``), see :mod:`._simulate_case`.
"""

from __future__ import annotations

from ._case import FAULT_FORM, STEP_FORM, TRIP_FORM, fault_arg, is_case, load_step_arg, trip_arg
from ._common import (HelpFormatter, add_force_argument, input_file, output_file, positive_float)
from ._study import add_engine_argument, add_set_argument

NAME = "simulate"

#: options of one form only (dest → the form that takes it)
STUDY_ONLY = {"scenario": "--scenario", "controller": "--controller", "quick": "--quick",
              "list": "--list", "overrides": "--set"}
CASE_ONLY = {"dyr": "--dyr", "fault": "--fault", "trip": "--trip", "load_step": "--load-step",
             "dt": "--dt", "record": "--record", "force": "--force"}


def add_parser(sub):
    """Add ``weakgrid simulate`` to the subcommand parsers ``sub``; return its parser."""
    p = sub.add_parser(
        NAME, help="simulate one scenario of a study, or a plain case file with events",
        description="STUDY (a .toml file or a shipped study's name): build the study's grid at "
                    "the scenario's operating point, attach the controller to the UPQC (or the "
                    "PQ baseline), apply the scenario's events and print the metrics. CASE (a "
                    "PSS/E .raw [+ --dyr], MATPOWER .m/.mat, pandapower .json or ANDES "
                    ".xlsx/.json file): simulate the grid as it is, no study and no UPQC, with "
                    "the events given by --fault, --trip and --load-step (like `andes run "
                    "case.raw --addfile case.dyr -r tds`); print the initialization, the "
                    "events and the final state, and with -o write the run (every signal by "
                    "name, Parquet). A power-flow case (MATPOWER, pandapower) gets a classical "
                    "machine at every generator. Exit code 3 when the run ends unstable.",
        formatter_class=HelpFormatter)
    p.add_argument("study", metavar="STUDY|CASE",
                   help="a study file (.toml) or a shipped study's name; or a case file "
                        "(.raw, .m, .mat, .json, .xlsx)")
    g = p.add_argument_group("a study (STUDY)")
    g.add_argument("--scenario", "-s", default=None,
                   help="scenario id (default: the study's first)")
    g.add_argument("--controller", "-c", default=None,
                   help="controller name (default: the scenario's first)")
    g.add_argument("--quick", action="store_true", help="the scenario's quick settings")
    g.add_argument("--list", action="store_true", help="list scenarios and controllers")
    add_set_argument(g)
    c = p.add_argument_group("a plain case (CASE)")
    c.add_argument("--dyr", type=input_file, default=None,
                   help="PSS/E dynamic data (.dyr) for a .raw or an ANDES case")
    c.add_argument("--fault", type=fault_arg, action="append", default=None,
                   metavar="BUS,T_ON,T_OFF[,XF]",
                   help=f"a three-phase bus fault, {FAULT_FORM}; XF 1e-4 pu if left out "
                        "(repeatable)")
    c.add_argument("--trip", type=trip_arg, action="append", default=None, metavar="BRANCH,T",
                   help=f"a branch opens, {TRIP_FORM} (repeatable)")
    c.add_argument("--load-step", type=load_step_arg, action="append", default=None,
                   metavar="BUS,T,DP[,DQ]",
                   help=f"constant-impedance load added, {STEP_FORM}; negative removes "
                        "(repeatable)")
    c.add_argument("--dt", type=positive_float, default=None,
                   help="integration step [s] (default: 1/120 s)")
    c.add_argument("--record", action="append", default=None, metavar="SIGNAL",
                   help="record only these signals (names or patterns such as '*.omega', "
                        "'bus103.*'; repeatable); default: every signal up to 3000 DAE "
                        "variables, the machines' speeds and angles above")
    add_force_argument(c)
    add_engine_argument(p)
    p.add_argument("--t-end", type=positive_float, default=None,
                   help="simulated time [s] (default: the scenario's; 20 s for a case, as "
                        "ANDES)")
    p.add_argument("--output", "-o", type=output_file(".csv", ".parquet"), default=None,
                   help="write the run: .parquet a run file (every signal by name, units in its "
                        "metadata, a study's controller samples; weakgrid.read_run); .csv every "
                        "signal in per unit (a study only)")
    p.set_defaults(func=run)
    return p


def _refuse_other_form(args, case: bool):
    from ..game.errors import ParameterError

    wrong = CASE_ONLY if not case else STUDY_ONLY
    for dest, opt in wrong.items():
        v = getattr(args, dest, None)
        if v not in (None, False, [], ()):
            what = "a plain case (CASE)" if not case else "a study (STUDY)"
            raise ParameterError(opt, v if not isinstance(v, list) else
                                 [getattr(x, "text", x) for x in v],
                                 f"{opt} applies to {what} only, and '{args.study}' is "
                                 f"{'a case file' if case else 'a study'}. See `weakgrid "
                                 "simulate --help`")


def run(args) -> int:
    """Run ``weakgrid simulate`` with the parsed ``args``; return the exit status."""
    case = is_case(args.study)
    _refuse_other_form(args, case)
    if case:
        from ._simulate_case import run_case

        return run_case(args)
    return run_study(args)


def run_study(args) -> int:
    """``weakgrid simulate STUDY``: one scenario with one controller."""
    import dataclasses

    import pandas as pd

    from ..fileio import replace_atomic
    from ..game.errors import ParameterError
    from ..study.cache import write_run_file
    from ..study.runner import Run, run_scenario
    from ._study import study_of

    st = study_of(args)
    scs = st.scenarios(args.quick) or st.scenarios(False)
    if args.list:
        for sc in scs:
            print(f"  {sc['id']:<24} load {sc['load']:<6} {sc['upqc']:<13} t_end {sc['t_end']:g} s"
                  f"  controllers: {', '.join(sc['controllers'])}")
        return 0
    ids = [sc["id"] for sc in st.scenarios(False)]
    sid = args.scenario or ids[0]
    if sid not in ids:
        raise ParameterError("--scenario", sid, f"choose one of {ids}")
    sc = next((s for s in scs if s["id"] == sid), None) or \
        next(s for s in st.scenarios(False) if s["id"] == sid)
    ctrl = args.controller or sc["controllers"][0]
    if ctrl not in st.controllers:
        raise ParameterError("--controller", ctrl, f"this study compares {st.controllers} "
                             "(controllers.compare)")
    run_ = Run.of(st, sc, ctrl)
    if args.t_end is not None:
        last = max([float(e.get("t_off", e.get("t", 0.0))) for e in sc.get("events", [])
                    if isinstance(e, dict)] or [0.0])
        if not args.t_end > last:
            raise ParameterError("--t-end", args.t_end, f"the scenario's last event is at "
                                 f"{last:g} s: give a longer --t-end")
        run_ = dataclasses.replace(run_, t_end=float(args.t_end))
    rec = run_scenario(st, run_)
    for k, v in rec.metrics.items():
        print(f"  {k:26s} {v:.6g}" if isinstance(v, float) else f"  {k:26s} {v}")
    if args.output:
        if args.output.suffix.lower() == ".parquet":   # a run file: every signal, by name
            write_run_file(rec, args.output)
        else:   # CSV: every signal per instant (per unit), no metadata
            df = rec.results.to_frame() if rec.results is not None else pd.DataFrame(rec.series)
            replace_atomic(args.output, lambda tmp: df.to_csv(tmp, index=False))
        print(f"  wrote {args.output}")
    return 0 if not rec.metrics["failed"] else 3
