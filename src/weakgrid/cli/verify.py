"""``weakgrid verify``: the trained controller against a dynamic-programming ground truth."""

from __future__ import annotations

from pathlib import Path


from ..fileio import write_json_atomic
from ..game.dp_settings import DPSettings
from ._checkpoint import (Keeper, TrainingCheckpoint, add_restart_argument, checkpoint_path,
                          content_key, load_kept, say_kept, training_key)
from ._common import (HelpFormatter, bar_disable, add_force_argument, add_problem_arguments, guard_dp,
                      guard_training, input_file, nonnegative_float, output_file, positive_float,
                      positive_int, problem_of, provenance)

NAME = "verify"


def add_parser(sub):
    """Add ``weakgrid verify`` to the subcommand parsers ``sub``; return its parser."""
    p = sub.add_parser(
        NAME, help="compare the controller with a grid dynamic-programming ground truth",
        description="Solve the zero-sum game of a 2-state problem on a grid (policy iteration "
                    "with exact sparse policy evaluation, cubic interpolation of the value "
                    "around the linearization's game-Riccati quadratic, V(0) = 0 pinned) and "
                    "report the relative error of the controller's cost J against the DP "
                    "value on the training region and the closed-loop optimality gap (cost "
                    "of u* vs the DP policy from a set of starts, with no disturbance and with "
                    "the DP's worst-case disturbance).",
        formatter_class=HelpFormatter)
    add_problem_arguments(p)
    d = DPSettings   # the class: its fields' defaults (no validation, no NumPy)
    p.add_argument("--controller", type=input_file, default=None,
                   help="a controller file to verify (default: train the problem's)")
    p.add_argument("--points", type=positive_int, default=d.n_points[0], help="grid nodes per state "
                   "(odd)")
    p.add_argument("--hold-steps", type=positive_int, default=d.hold_steps,
                   help="k of the k-step lifting (inputs held k steps); 1 = no lifting")
    p.add_argument("--margin", type=nonnegative_float, nargs="+", default=[d.margin],
                   help="grid box = region enlarged by this fraction of its width per side "
                        "(one value, or one per state)")
    p.add_argument("--interpolation", choices=("cubic", "linear"), default=d.interpolation,
                   help="interpolation of the value residual between grid nodes (cubic: Keys' "
                        "cubic convolution, O(h^4); linear: multilinear, O(h^2))")
    p.add_argument("--max-iterations", type=positive_int, default=d.max_iterations,
                   help="cap on the DP policy iterations")
    p.add_argument("--steps", type=positive_int, default=4000, help="closed-loop horizon (steps)")
    p.add_argument("--start-fraction", type=positive_float, default=0.5,
                   help="starts: corners/edge midpoints of the region shrunk by this")
    p.add_argument("--u-bound", type=positive_float, nargs="+", default=None, metavar="UBAR",
                   help="bound the control in the game (as `weakgrid train --u-bound`): the "
                        "DP then optimizes over the same bounded set with the same penalty")
    p.add_argument("--u-bound-shape", choices=("disk", "box"), default=None,
                   help="shape of --u-bound (default: the problem's, else disk)")
    p.add_argument("--report", type=output_file(".json"), default=None, help="write the report (JSON)")
    add_restart_argument(p, "REPORT, else NAME.verify, with the suffixes "
                            ".training.checkpoint.npz and .dp.checkpoint.npz")
    add_force_argument(p)
    p.set_defaults(func=run)
    return p


def _pct(v):
    return f"{100 * v:.2f} %"


def run(args) -> int:
    """Run ``weakgrid verify`` with the parsed ``args``; return the exit status."""
    from ..game.checkpoint import load_dp_checkpoint, save_dp_checkpoint
    import numpy as np
    from ..game.dynamic_programming import solve_game_dp
    from ..game.errors import ParameterError
    from ..game.optimality import closed_loop_gap, default_starts, value_error
    from ..models import load_controller

    problem = problem_of(args)
    if args.u_bound is not None:
        problem = problem.with_input_bound(
            args.u_bound[0] if len(args.u_bound) == 1 else args.u_bound, args.u_bound_shape)
    if problem.system.n_states != 2:
        raise ParameterError("model", f"{problem.system.n_states} states",
                             "the grid ground truth is for 2-state problems")
    if not (0 < args.start_fraction <= 1):
        raise ParameterError("--start-fraction", args.start_fraction, "use a value in (0, 1]")
    settings = DPSettings(n_points=(args.points,) * 2, hold_steps=args.hold_steps,
                          margin=tuple(args.margin), interpolation=args.interpolation,
                          max_iterations=args.max_iterations)
    print(f"weakgrid verify: {problem.name}  ({problem.source})")
    guard_dp(args.points ** 2, args.force)
    if not args.controller:
        guard_training(problem, args.force)
    if args.controller:
        ctl = load_controller(args.controller)
        mine, theirs = problem.system.to_dict(), ctl.problem.get("model", {})
        if any(mine.get(k) != theirs.get(k) for k in set(mine) - {"source", "state_names"}):
            raise ParameterError("--controller", str(args.controller),
                                 f"it was trained on another model ({theirs.get('kind')}: "
                                 f"{ {k: v for k, v in theirs.items() if k != 'source'} }) "
                                 f"than {problem.name}: pass the matching --preset/--config")
        print(f"  controller  {args.controller} (gamma = {ctl.cost.gamma:g})")
    # checkpoints beside the report: the training (kept, once finished, until the DP is
    # done) and the DP iterations (at most every CHECKPOINT_SECONDS and on an interruption)
    base = args.report or Path(f"{problem.name}.verify.json")
    train_cp = None
    if not args.controller:
        train_cp = TrainingCheckpoint(checkpoint_path(base, "training"),
                                      training_key(problem, problem.settings, NAME),
                                      args.restart, NAME, " of the training")
        ctl = train_cp.train(problem, problem.settings)
        train_cp.keeper.flush()  # the finished training: a re-run does not redo it
        print(f"  controller  trained now: {ctl.iterations['outer']} outer iterations"
              + (f" ({train_cp.kept} kept from the checkpoint)" if train_cp.kept else "")
              + f", gamma = {ctl.cost.gamma:g}")
    dp_ckpt = checkpoint_path(base, "dp")
    dp_key = content_key({"command": NAME, "problem": problem.raw, "name": problem.name,
                          "cost": ctl.cost.to_dict(),
                          "lower": list(problem.mesh.lower), "upper": list(problem.mesh.upper),
                          "dp": settings.to_dict()})
    start = None if args.restart else load_kept(dp_ckpt, dp_key, load_dp_checkpoint, NAME)
    lo, hi = problem.mesh.lower, problem.mesh.upper
    print(f"  DP grid     {args.points} x {args.points} on {list(lo)} .. {list(hi)} "
          f"(margin {args.margin}), hold {args.hold_steps} step(s), {args.interpolation} "
          f"residual around the game-Riccati quadratic")
    if start is not None:
        print(f"  resuming the DP from the checkpoint {dp_ckpt}: {start.iteration} finished "
              f"iteration(s) kept, continuing at iteration {start.iteration + 1}")
    print("\n  iteration  max|dV|/max V   max|dz|   bad-inertia nodes  seconds")

    from tqdm.auto import tqdm

    # the bar (stderr, only on a terminal) counts DP iterations against the cap
    bar = tqdm(desc="  DP", unit=" it", total=settings.max_iterations, leave=False,
               disable=bar_disable(args), initial=start.iteration if start is not None else 0)

    def progress(r):
        bar.update(1)
        bar.set_postfix_str(f"max|dV|/max V {r['max_rel_dV']:.2e} → {settings.tol:g}",
                            refresh=False)
        bar.clear()
        print(f"  {r['iteration']:9d}  {r['max_rel_dV']:13.3e}  {r['max_dz']:8.2e}  "
              f"{r['n_bad_inertia']:17d}  {r['seconds']:7.2f}", flush=True)

    keeper = Keeper(dp_ckpt, dp_key, save_dp_checkpoint, start, NAME)
    try:
        dp = solve_game_dp(problem.system, ctl.cost, lo, hi, settings, progress=progress,
                           start=start, checkpoint=keeper.keep)
    except KeyboardInterrupt:
        bar.close()
        saved = keeper.flush()
        if saved is not None and saved.iteration:
            say_kept(f"{saved.iteration} finished DP iteration(s)", dp_ckpt)
        raise
    finally:
        bar.close()
    print(f"  DP {'converged' if dp.converged else 'NOT converged'} in {len(dp.history)} "
          f"iterations, {dp.seconds:.1f} s; lifting bias on the linearization "
          f"{_pct(dp.lifting_bias)}")
    ve = value_error(ctl, dp, lo, hi)
    print(f"\n  value: J (controller) vs V (DP) on {ve['n_nodes']} grid nodes of the region")
    print(f"    max|J - V| / max V = {_pct(ve['sup_error_over_max_V'])}  (max V = "
          f"{ve['max_V']:.4g}, max J = {ve['max_J']:.4g}; worst at x = "
          f"{np.round(ve['worst_state'], 4).tolist()}: J = {ve['J_at_worst']:.4g}, "
          f"V = {ve['V_at_worst']:.4g})")
    print(f"    |J - V| / V: median {_pct(ve['median_relative_error'])}, 90th percentile "
          f"{_pct(ve['p90_relative_error'])} (nodes with V >= 1 % of max V)")
    starts = default_starts(lo, hi, args.start_fraction)
    gap = closed_loop_gap(ctl, dp, starts, args.steps)
    print(f"\n  closed loop from {len(starts)} starts (region shrunk x{args.start_fraction:g}), "
          f"{args.steps} steps: cost of u* vs the DP policy")
    for key, label in (("no_disturbance", "no disturbance"),
                       ("worst_case", "worst case (DP's w)")):
        g = gap[key]
        print(f"    {label:22s} gap mean {_pct(g['mean_relative_gap'])}, max "
              f"{_pct(g['max_relative_gap'])}, min {_pct(g['min_relative_gap'])}; diverged "
              f"{g['diverged_controller']}/{g['diverged_dp']}; DP off grid "
              f"{_pct(g['dp_fraction_of_steps_off_grid'])} of steps")
    print(f"    DP self-consistency: |cost(u_dp, w_dp) - V(x0)| / V(x0) <= "
          f"{_pct(gap['dp_consistency'])}")
    if args.report:
        rec = provenance(problem, NAME, dp=settings.to_dict(), steps=args.steps,
                         start_fraction=args.start_fraction,
                         controller=str(args.controller) if args.controller else "trained",
                         gamma=ctl.cost.gamma)
        write_json_atomic(args.report, {**rec, "dp": dp.to_dict(), "value_error": ve,
                                        "closed_loop": gap})
        print(f"\n  wrote {args.report}")
    keeper.discard()
    if train_cp is not None:
        train_cp.discard()
    return 0
