"""``weakgrid gamma``: the smallest attenuation level γ the HJI method accepts."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from ..fileio import write_json_atomic
from ..game.gamma_settings import SearchSettings
from ._checkpoint import (Keeper, add_restart_argument, checkpoint_path, content_key,
                          load_kept, problem_inputs, say_kept)
from ._common import (HelpFormatter, add_force_argument, add_problem_arguments, bar_disable,
                      guard_overwrite, guard_training, is_command_record, is_controller_file,
                      output_file, positive_float, positive_int, problem_of, provenance)

NAME = "gamma"


def add_parser(sub):
    """Add ``weakgrid gamma`` to the subcommand parsers ``sub``; return its parser."""
    p = sub.add_parser(
        NAME, help="bisect for the minimum attenuation level gamma",
        description="Bisect gamma between the linearization's game-Riccati attenuation limit "
                    "and the problem's gamma: a gamma is accepted when the policy iteration "
                    "converges, Yw < 0 on the whole mesh and the closed loop under the "
                    "worst-case disturbance w* stays bounded and returns to the origin from "
                    "the corners and edge midpoints of the training region. Prints gamma*, "
                    "the bracket and every trial; writes the controller at gamma*.",
        formatter_class=HelpFormatter)
    add_problem_arguments(p)
    d = SearchSettings   # the class: its fields' defaults
    p.add_argument("--rtol", type=positive_float, default=d.rtol, help="relative width of the bracket")
    p.add_argument("--max-trials", type=positive_int, default=d.max_trials, help="cap on gammas tried")
    p.add_argument("--rollout-steps", type=positive_int, default=d.rollout_steps,
                   help="length of the worst-case rollouts (steps)")
    p.add_argument("--escape-factor", type=positive_float, default=d.escape_factor,
                   help="rollouts must stay inside the region enlarged this many times")
    p.add_argument("--return-fraction", type=positive_float, default=d.return_fraction,
                   help="final state within this fraction of the region's half-widths")
    p.add_argument("--starts", nargs="+", default=list(d.starts),
                   choices=("continuation", "game-riccati", "initial"),
                   help="starts of the policy iteration tried for each gamma, in order")
    p.add_argument("--tol", type=positive_float, default=None,
                   help="δu = δw of the policy iteration (default: the problem's)")
    p.add_argument("--output", "-o", type=output_file(".json"), default=None,
                   help="write the controller trained at gamma* (JSON)")
    p.add_argument("--report", type=output_file(".json"), default=None,
                   help="write the search (bracket, history, parameters) as JSON")
    p.add_argument("--quiet", "-q", action="store_true", help="print only the summary")
    add_restart_argument(p, "OUTPUT, else REPORT, else NAME, with the suffix "
                            ".gamma.checkpoint.npz")
    add_force_argument(p, overwrite="an OUTPUT or REPORT file")
    p.set_defaults(func=run)
    return p


def _running(r, text) -> str:
    """``text`` about the running trial ``r`` ({g}, {what}: its start and iterations,
    {kept}: what of it is kept), or "" without one."""
    if r is None:
        return ""
    failed = f"{len(r.reasons)} start(s) failed, " if r.reasons else ""
    if r.training is None:
        what = f"({failed}next the {r.start} start)"
        kept = f"({failed}the {r.start} start due)"
    else:
        what = (f"({failed}the training from the {r.start} start at outer iteration "
                f"{r.training.outer + 1})")
        kept = (f"({failed}{r.training.outer} outer iteration(s) of the training from the "
                f"{r.start} start)")
    return text.format(g=f"{r.gamma:.6g}", what=what, kept=kept)


def run(args) -> int:
    """Run ``weakgrid gamma`` with the parsed ``args``; return the exit status."""
    from ..game.checkpoint import load_search_checkpoint, save_search_checkpoint
    from ..game.gamma_search import search_min_gamma

    problem = problem_of(args)
    settings = SearchSettings(rtol=args.rtol, max_trials=args.max_trials,
                              rollout_steps=args.rollout_steps, escape_factor=args.escape_factor,
                              return_fraction=args.return_fraction,
                              starts=tuple(args.starts))
    solver = problem.settings
    if args.tol is not None:
        solver = replace(solver, tol_u=args.tol, tol_w=args.tol)
    print(f"weakgrid gamma: {problem.name}  ({problem.source})")
    print(f"  problem's gamma = {problem.cost.gamma:g};  bracket rtol = {settings.rtol:g}; "
          f"rollouts of {settings.rollout_steps} steps from the corners/edge midpoints of Ω")
    guard_training(problem, args.force)
    # every decided trial is saved at once, the training of the running one at most every
    # CHECKPOINT_SECONDS and on an interruption; a re-run replays the decided trials
    if args.output:
        guard_overwrite(args.output, is_controller_file, "a controller file", args.force)
    if args.report:
        guard_overwrite(args.report, is_command_record(NAME), "a gamma report", args.force,
                        option="--report")
    ckpt = checkpoint_path(args.output or args.report or Path(f"{problem.name}.json"), NAME)
    key = content_key({"command": NAME, **problem_inputs(problem, solver),
                       "search": settings.to_dict()})
    resume = None if args.restart else load_kept(ckpt, key, load_search_checkpoint, NAME)
    kept = len(resume.trials) if resume is not None else 0
    if resume is not None:
        print(f"  resuming from the checkpoint {ckpt}: {kept} decided trial(s) kept"
              + _running(resume.running, ", the trial at gamma = {g} continues {what}"))
    if not args.quiet:
        print("\n  trial      gamma     decision  start           seconds  reason")
    count = [0]

    def row(t, note=""):
        count[0] += 1
        if not args.quiet:
            print(f"  {count[0]:5d}  {t.gamma:10.6g}  {'accepted' if t.accepted else 'rejected':>9}"
                  f"  {t.start or '-':14}  {t.seconds:7.2f}  {note}{t.reason}", flush=True)

    for t in (resume.trials if resume is not None else []):
        row(t, "(kept) ")

    from tqdm.auto import tqdm

    # the bar (stderr, only on a terminal) follows the training of the running trial
    bar = tqdm(desc="  gamma search", unit=" outer it", leave=False,
               disable=bar_disable(args))
    keeper = Keeper(ckpt, key, save_search_checkpoint, resume, NAME)

    def keep(state, finished):
        keeper.keep(state, now=finished)
        if state.running is not None and state.running.training is not None:
            bar.update(1)
            bar.set_postfix_str(f"trial {len(state.trials) + 1}, gamma "
                                f"{state.running.gamma:.6g} ({state.running.start})",
                                refresh=False)

    def progress(t):
        bar.clear()
        row(t)

    try:
        res = search_min_gamma(problem.system, problem.basis, problem.cost, problem.mesh,
                               problem.initial_policy, solver, settings,
                               problem={"name": problem.name, "source": problem.source},
                               progress=progress, resume=resume, checkpoint=keep)
    except KeyboardInterrupt:
        bar.close()
        saved = keeper.flush()
        if saved is not None and (saved.trials or saved.running is not None):
            say_kept(f"{len(saved.trials)} decided trial(s)"
                     + _running(saved.running, " and the trial at gamma = {g} {kept}"), ckpt)
        raise
    finally:
        bar.close()
    lo, hi = res.bracket
    print(f"\n  gamma* = {res.gamma_star:.6g}   bracket [{lo:.6g}, {hi:.6g}] "
          f"(relative width {(hi - lo) / hi:.2e})")
    print(f"  lower bound (game-Riccati limit of the linearization) = {res.linear_limit:.6g}; "
          f"gamma*/bound = {res.gamma_star / res.linear_limit:.4g}")
    print(f"  {len(res.history)} trials ({len(res.history) - kept} run now, {kept} kept from "
          f"the checkpoint) in {res.seconds:.1f} s (this run)" if kept else
          f"  {len(res.history)} trials in {res.seconds:.1f} s"
          + ("" if res.converged else "  (stopped at --max-trials before the bracket closed)"))
    if args.report:
        rec = provenance(problem, NAME, **settings.to_dict(), solver=solver.to_dict())
        write_json_atomic(args.report, {**rec, **res.to_dict()})
        print(f"  wrote {args.report}")
    if args.output:
        res.controller.save(args.output)
        print(f"  wrote the controller at gamma* to {args.output}")
    keeper.discard()
    return 0
