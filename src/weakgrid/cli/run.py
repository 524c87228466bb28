"""``weakgrid run``: every scenario × controller of a study, metrics, figures, HTML report."""

from __future__ import annotations

from pathlib import Path

from ._common import (HelpFormatter, add_batch_argument, add_cluster_arguments,
                      add_force_argument, check_cluster,
                      output_folder)

from ._common import show_progress
from ._study import add_engine_argument, add_study_argument, study_of

NAME = "run"


def add_parser(sub):
    """Add ``weakgrid run`` to the subcommand parsers ``sub``; return its parser."""
    p = sub.add_parser(
        NAME, help="run every scenario × controller of a study (metrics, figures, report)",
        description="Derive the design model at every operating point the study's scenarios "
                    "need, train the HJI controller there, simulate every scenario with every "
                    "controller, and write metrics (CSV, Markdown), figures, run signals and "
                    "report.html.",
        formatter_class=HelpFormatter)
    add_study_argument(p, nargs="?")
    p.add_argument("--output", "-o", type=output_folder, default=None,
                   help="output folder (default: <study>-output)")
    p.add_argument("--quick", action="store_true",
                   help="each scenario's quick settings (shorter runs, fewer controllers) "
                        "and the [sweep.quick] of a study with a [sweep]; what runs is said "
                        "first, the sweep's runs are a table in the report")
    p.add_argument("--list", action="store_true", help="list the shipped studies")
    p.add_argument("--no-maps", dest="maps", action="store_false",
                   help="leave out the study's [sweep] (its runs, maps and the claims' "
                        "step-halving uncertainty, which then counts 0): the scenarios' runs "
                        "only. On a DPsim engine the sweep's half-step check halves the "
                        "controller's step, which DPsim divides into parts of at most "
                        "dpsim_dt_max again, so it does not halve DPsim's step")
    add_engine_argument(p)
    add_cluster_arguments(p)
    add_batch_argument(p)
    add_force_argument(p, overwrite="files in the output folder", limits=False)
    p.set_defaults(func=run)
    return p


def run(args) -> int:
    """Run ``weakgrid run`` with the parsed ``args``; return the exit status."""
    from ..study.studyfile import load_study, shipped_studies

    if args.list:
        for n in shipped_studies():
            st = load_study(n)
            print(f"  {n:<28} {st.data['study']['title']}")
        return 0
    if not args.study:
        from ..game.errors import ParameterError

        raise ParameterError("STUDY", None, f"give a study file (TOML) or a shipped study's "
                             f"name: {shipped_studies()} (`weakgrid run --list`)")
    from ..study.engine import run_studies

    st = study_of(args)
    check_cluster(args)
    out = args.output or Path(f"{st.name}-output")
    summary = run_studies([st], out, quick=args.quick, title=st.data["study"]["title"] or st.name,
                          scheduler=args.scheduler, workers=args.workers,
                          progress=show_progress(args), force=args.force,
                          batched=args.batched, maps=args.maps)
    for d in summary["designs"]:
        print(f"  design {d['load']} {d['upqc']}: a = {d['a']}, V̄r = {d['Vr_bar']}, "
              f"ϕs0 = {d['phi_s0']}; modes {d['modes']}")
    failed = [m["id"] for m in summary["metrics"] if m["failed"]]
    if failed:
        print(f"  runs that failed (see metrics.csv, column failure): {failed}")
    for c in summary["claims"]:
        print(f"  {c['id']:<14} {c['verdict']:<10} {c['paper']}")
    return 0
