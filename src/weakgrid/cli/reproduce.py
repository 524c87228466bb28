"""``weakgrid reproduce``: the paper's case studies, figures, tables and report."""

from __future__ import annotations

from pathlib import Path

from ._common import (HelpFormatter, add_batch_argument, add_cluster_arguments,
                      add_force_argument, check_cluster,
                      output_folder, show_progress)

NAME = "reproduce"


def add_parser(sub):
    """Add ``weakgrid reproduce`` to the subcommand parsers ``sub``; return its parser."""
    p = sub.add_parser(
        NAME, help="reproduce the paper's case studies (figures, metrics, report)",
        description="Train the HJI controllers on the design models derived from both grids, "
                    "simulate every scenario and baseline, and write the figures (Figs. 7–16, "
                    "18–25; PNG and SVG), a metrics table (CSV and Markdown) and report.html "
                    "with a verdict for each claim of the paper.",
        formatter_class=HelpFormatter)
    p.add_argument("--output", "-o", type=output_folder, default=Path("reproduce-output"),
                   help="output folder")
    p.add_argument("--quick", action="store_true",
                   help="shorter runs and the essential subset of scenarios")
    add_cluster_arguments(p)
    add_batch_argument(p)
    add_force_argument(p, overwrite="files in the output folder", limits=False)
    p.set_defaults(func=run)
    return p


def run(args) -> int:
    """Run ``weakgrid reproduce`` with the parsed ``args``; return the exit status."""
    from ..study.reproduce import reproduce

    check_cluster(args)
    summary = reproduce(args.output, quick=args.quick, scheduler=args.scheduler,
                        workers=args.workers, progress=show_progress(args), force=args.force,
                        batched=args.batched)
    width = max((len(c["id"]) for c in summary["claims"]), default=0)
    print("\nclaims of the paper:")
    for c in summary["claims"]:
        print(f"  {c['id']:<{width}}  {c['verdict']:<10}  {c['paper']}")
    return 0
