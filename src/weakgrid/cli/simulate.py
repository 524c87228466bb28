"""``weakgrid simulate``: one scenario of a case with one controller."""

from __future__ import annotations

import argparse

from ._common import nonnegative_float, output_file, positive_float

NAME = "simulate"


def add_parser(sub):
    """Add ``weakgrid simulate`` to the subcommand parsers ``sub``; return its parser."""
    from ..study.cases import case_names
    from ..study.controllers import CONTROLLERS

    p = sub.add_parser(
        NAME, help="simulate one case with one controller",
        description="Build a case at a load level, attach a controller to the UPQC (or the "
                    "PQ baseline), apply the paper's three-phase fault and print the metrics.",
        formatter_class=argparse.ArgumentDefaultsHelpFormatter)
    p.add_argument("case", choices=case_names(), help="the detailed grid to simulate")
    p.add_argument("--controller", "-c", choices=CONTROLLERS, default="hji",
                   help="controller of the UPQC series voltage (or the PQ baseline)")
    p.add_argument("--load", choices=("high", "low"), default="high", help="load level of the case")
    p.add_argument("--upqc", choices=("conventional", "reduced"), default="conventional",
                   help="UPQC structure: with its shunt branch, or series branch fed by the GTI dc link")
    p.add_argument("--fault", nargs=2, type=nonnegative_float, metavar=("T_ON", "T_OFF"), default=None,
                   help="fault application and clearance [s] (default: the paper's)")
    p.add_argument("--t-end", type=positive_float, default=None, help="simulated time [s]")
    p.add_argument("--output", "-o", type=output_file(".csv", ".parquet"), default=None,
                   help="write the run's signals (.csv or .parquet)")
    p.set_defaults(func=run)
    return p


def check_time_window(t_on: float, t_off: float, t_end: float):
    """The fault must start before it clears, and clear before the end of the run."""
    from ..game.errors import ParameterError

    if not t_on < t_off:
        raise ParameterError("--fault", [t_on, t_off], "the fault must clear after it starts "
                             "(T_ON < T_OFF)")
    if not t_off < t_end:
        raise ParameterError("--fault", [t_on, t_off], f"the fault clears at or after the end "
                             f"of the run (--t-end {t_end:g} s): use T_OFF < --t-end or a "
                             "longer --t-end")


def run(args) -> int:
    """Run ``weakgrid simulate`` with the parsed ``args``; return the exit status."""
    import pandas as pd

    from ..fileio import replace_atomic
    from ..study.runner import run_scenario
    from ..study.scenarios import Scenario

    c1 = args.case.startswith("case1")
    t_on, t_off = args.fault or ((0.2, 0.25) if c1 else (3.0, 3.1))
    t_end = args.t_end if args.t_end is not None else (6.0 if c1 else 10.0)
    check_time_window(t_on, t_off, t_end)
    sc = Scenario(f"{args.case}-{args.load}-{args.upqc}-{args.controller}", args.case,
                  args.load, args.upqc, args.controller, t_on, t_off, t_end)
    rec = run_scenario(sc)
    for k, v in rec.metrics.items():
        print(f"  {k:26s} {v:.6g}" if isinstance(v, float) else f"  {k:26s} {v}")
    if args.output:
        t = rec.series["t"]
        df = pd.DataFrame({k: v for k, v in rec.series.items()
                           if hasattr(v, "shape") and v.shape == t.shape})
        if args.output.suffix.lower() == ".parquet":
            replace_atomic(args.output, df.to_parquet)
        else:
            replace_atomic(args.output, lambda tmp: df.to_csv(tmp, index=False))
        print(f"  wrote {args.output}")
    return 0 if not rec.metrics["failed"] else 3
