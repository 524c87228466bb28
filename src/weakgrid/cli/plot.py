"""``weakgrid plot``: signals of a run file against time (in the style of ``andes plot``)."""

from __future__ import annotations

from ._common import HelpFormatter, input_file, output_file

NAME = "plot"


def add_parser(sub):
    """Add ``weakgrid plot`` to the subcommand parsers ``sub``; return its parser."""
    p = sub.add_parser(
        NAME, help="plot signals of a run file against time",
        description="Plot signals of a run file (written by `weakgrid simulate -o "
                    "RUN.parquet`, `weakgrid run`/`reproduce`: OUTPUT/runs/ID.parquet) against "
                    "time, one panel per unit, and write the figure (never opens a window). "
                    "Signals are named <device>.<signal> (G1.omega, bus7.v, UPQC.P_series); "
                    "fnmatch patterns such as 'G*.omega' or 'bus*.v' select several.",
        formatter_class=HelpFormatter)
    p.add_argument("run", type=input_file, help="a run file (.parquet)")
    p.add_argument("signals", nargs="+", metavar="SIGNAL",
                   help="signal names or fnmatch patterns (quote patterns in the shell)")
    p.add_argument("--output", "-o", type=output_file(".png", ".svg", ".pdf"), default=None,
                   help="figure file (default: RUN.png beside the run)")
    p.add_argument("--si", action="store_true",
                   help="SI units (MW, kV, rad/s, deg, kA) instead of per unit")
    p.set_defaults(func=run)
    return p


def run(args) -> int:
    """Run ``weakgrid plot`` with the parsed ``args``; return the exit status."""
    from ..sim.runplot import plot_run

    out = plot_run(args.run, args.signals, args.output, si=args.si)
    print(f"wrote {out}")
    return 0
