"""``weakgrid sweep``: a study's ``[sweep]`` on Dask — a Parquet table, a row per run."""

from __future__ import annotations

from pathlib import Path

from ._common import (HelpFormatter, add_batch_argument, add_cluster_arguments,
                      add_force_argument, check_cluster,
                      output_folder, show_progress)

from ._study import add_study_argument, study_of

NAME = "sweep"


def add_parser(sub):
    """Add ``weakgrid sweep`` to the subcommand parsers ``sub``; return its parser."""
    p = sub.add_parser(
        NAME, help="run a study's sweep ([sweep]: axes over study fields) on dask.distributed",
        description="Run every point of the study's [sweep] table (axes over study fields by "
                    "dotted path, × scenarios × controllers) on a local Dask cluster (one "
                    "worker process per core) or an existing one, and write one Parquet table, "
                    "a row per run (its parameters, every metric, status, failure cause, wall "
                    "time). Finished runs are cached under a hash of their full input and the "
                    "code: an interrupted sweep (Ctrl-C, SIGTERM) resumes, a repeated one is "
                    "free. Before any run it prints an estimate of the time and memory of the "
                    "runs still to do (a short probe of the study's grid is timed) and refuses "
                    "a sweep beyond 30 min or 4 GiB / half the available memory "
                    "(WEAKGRID_MAX_GIB) unless --force.",
        formatter_class=HelpFormatter)
    add_study_argument(p)
    p.add_argument("--output", "-o", type=output_folder, default=None,
                   help="output folder (default: <study>-sweep)")
    add_cluster_arguments(p)
    add_batch_argument(p)
    p.add_argument("--quick", action="store_true", help="the sweep's [sweep.quick] axes")
    p.add_argument("--signals", action="store_true",
                   help="keep every run's signals (Parquet, in the cache folder)")
    p.add_argument("--maps", action="store_true", help="also draw the sweep's maps (PNG)")
    add_force_argument(p, overwrite="files in the output folder")
    p.set_defaults(func=run)
    return p


def run(args) -> int:
    """Run ``weakgrid sweep`` with the parsed ``args``; return the exit status."""
    from ..study.sweep import claim_sweep_outputs, run_study_sweep
    from ..study.sweep_estimate import check_sweep, estimate_sweep
    from ..sweep import SweepInterrupted

    st = study_of(args)
    if args.signals and "sweep" in st.data:
        st.data["sweep"]["signals"] = True
    check_cluster(args)
    out = args.output or Path(f"{st.name}-sweep")
    if "sweep" in st.data:      # a file of the user's in the way: refused before any work
        claim_sweep_outputs(st, out, args.quick, args.maps, args.force, write=False)
    # before anything is written: what the runs still to do will cost (refused beyond limits)
    est = estimate_sweep(st, out / "cache", quick=args.quick, workers=args.workers,
                         scheduler=args.scheduler, batched=args.batched)
    print(est.line())
    check_sweep(est, st, quick=args.quick, force=args.force)
    try:
        table = run_study_sweep(st, out, quick=args.quick, scheduler=args.scheduler,
                                workers=args.workers, progress=show_progress(args),
                                force=args.force, maps=args.maps, batched=args.batched)
    except SweepInterrupted as exc:
        print(f"weakgrid sweep: {exc}")
        return 130
    n_fail = int((table["status"] != "ok").sum())
    print(f"{len(table)} runs, {n_fail} failed; table: "
          f"{out / (st.name + '-sweep' + ('-quick' if args.quick else '') + '.parquet')}")
    if n_fail:
        for _, r in table[table["status"] != "ok"].head(10).iterrows():
            print(f"  run {r['run']}: {r['failure'][:160]}")
    if args.maps:
        from ..study.sweep_maps import draw_maps, map_summaries

        maps = draw_maps(st, table, out / "maps", quick=args.quick)
        from ..manifest import Manifest

        Manifest(out).record(m["path"] for m in maps if m.get("path"))   # their content
        for s in map_summaries(maps):
            print(f"  {s['claim']}: at the shipped setting {s['at_setting']}; {s['region']}")
    return 0
