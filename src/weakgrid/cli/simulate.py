"""``weakgrid simulate``: one scenario of a study with one controller."""

from __future__ import annotations


from ._common import HelpFormatter, output_file, positive_float

NAME = "simulate"


def add_parser(sub):
    """Add ``weakgrid simulate`` to the subcommand parsers ``sub``; return its parser."""
    p = sub.add_parser(
        NAME, help="simulate one scenario of a study with one controller",
        description="Build the study's grid at the scenario's operating point, attach the "
                    "controller to the UPQC (or the PQ baseline), apply the scenario's events "
                    "and print the metrics.",
        formatter_class=HelpFormatter)
    p.add_argument("study", help="a study file (TOML) or a shipped study's name")
    p.add_argument("--scenario", "-s", default=None,
                   help="scenario id (default: the study's first)")
    p.add_argument("--controller", "-c", default=None,
                   help="controller name (default: the scenario's first)")
    p.add_argument("--quick", action="store_true", help="the scenario's quick settings")
    p.add_argument("--t-end", type=positive_float, default=None,
                   help="simulated time [s] (default: the scenario's)")
    p.add_argument("--list", action="store_true", help="list scenarios and controllers")
    p.add_argument("--output", "-o", type=output_file(".csv", ".parquet"), default=None,
                   help="write the run: .parquet a run file (every signal by name, units in its "
                        "metadata, the controller's samples; weakgrid.read_run), .csv every "
                        "signal in per unit")
    p.set_defaults(func=run)
    return p


def run(args) -> int:
    """Run ``weakgrid simulate`` with the parsed ``args``; return the exit status."""
    import dataclasses

    import pandas as pd

    from ..fileio import replace_atomic
    from ..game.errors import ParameterError
    from ..study.cache import write_run_file
    from ..study.runner import Run, run_scenario
    from ..study.studyfile import load_study

    st = load_study(args.study)
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
