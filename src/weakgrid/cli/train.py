"""``weakgrid train``: train the HJI controller of a preset or of a TOML problem file."""

from __future__ import annotations

import sys
from pathlib import Path


from ._checkpoint import (CHECKPOINT_SECONDS, TrainingCheckpoint, add_restart_argument,
                          checkpoint_path, outer_bar, training_key)
from ._common import (HelpFormatter, add_force_argument, add_problem_arguments, bar_disable,
                      guard_overwrite, guard_training, is_controller_file, output_file,
                      positive_float, problem_of)

NAME = "train"


def add_parser(sub):
    """Add ``weakgrid train`` to the subcommand parsers ``sub``; return its parser."""
    p = sub.add_parser(
        NAME, help="train the HJI controller (two-loop policy iteration)",
        description="Train the game-theoretic controller of a preset or a TOML problem file, "
                    "print the iterations, the weights beside the published ones, timing and "
                    "diagnostics, and write the controller file (JSON).",
        formatter_class=HelpFormatter)
    add_problem_arguments(p)
    p.add_argument("--output", "-o", type=output_file(".json"), default=None,
                   help="controller file to write (default: NAME.controller.json)")
    p.add_argument("--tol", type=positive_float, default=None,
                   help="δu = δw (default: the problem's [solver] values)")
    p.add_argument("--u-bound", type=positive_float, nargs="+", default=None, metavar="UBAR",
                   help="bound the control (beyond the paper): ‖u‖ ≤ UBAR (disk) or "
                        "abs(u_i) ≤ UBAR_i (box), replacing the problem's [cost] u_bound")
    p.add_argument("--u-bound-shape", choices=("disk", "box"), default=None,
                   help="shape of --u-bound (default: the problem's, else disk)")
    p.add_argument("--quiet", "-q", action="store_true", help="print only the summary")
    add_restart_argument(p, "OUTPUT with the suffix .checkpoint.npz")
    add_force_argument(p, overwrite="an OUTPUT file")
    p.set_defaults(func=run)
    return p


def _fmt_row(cells, widths):
    return "  ".join(str(c).rjust(w) for c, w in zip(cells, widths))


def run(args) -> int:
    """Run ``weakgrid train`` with the parsed ``args``; return the exit status."""
    import numpy as np
    from ..game.hji import closed_loop_spectral_radius
    from ..game.errors import ParameterError

    problem = problem_of(args)
    if args.u_bound is not None:
        problem = problem.with_input_bound(
            args.u_bound[0] if len(args.u_bound) == 1 else args.u_bound, args.u_bound_shape)
    elif args.u_bound_shape is not None:
        if problem.input_bound is None:
            raise ParameterError("--u-bound-shape", args.u_bound_shape,
                                 "give the bound too (--u-bound UBAR)")
        problem = problem.with_input_bound(problem.input_bound.limit.tolist(),
                                           args.u_bound_shape)
    settings = problem.settings
    if args.tol is not None:
        from dataclasses import replace

        settings = replace(settings, tol_u=args.tol, tol_w=args.tol)
    print(f"weakgrid train: {problem.name}  ({problem.source})")
    print(f"  model   {problem.system!r}")
    c = problem.cost
    print(f"  cost    Q = {np.diag(c.Q).tolist()}, R = {np.diag(c.R).tolist()}, "
          f"P = {np.diag(c.P).tolist()}, gamma = {c.gamma:g}")
    if c.bound is not None:
        print(f"  bound   {c.bound.describe()} ({c.bound.shape}; non-quadratic penalty "
              "W(u) in place of u'Ru)")
    mesh_n = problem.mesh.points.shape[0]
    print(f"  mesh    {list(problem.mesh.lower)} .. {list(problem.mesh.upper)} step "
          f"{list(problem.mesh.step)}  ({mesh_n} points);  basis {problem.basis.size} terms")
    print(f"  solver  δu = {settings.tol_u:g}, δw = {settings.tol_w:g}")
    guard_training(problem, args.force)
    out = args.output or Path(f"{problem.name}.controller.json")
    guard_overwrite(out, is_controller_file, "a controller file", args.force)
    cp = TrainingCheckpoint(checkpoint_path(out), training_key(problem, settings),
                            args.restart, NAME)
    if not args.quiet:
        print("\n  outer  inner    max|Δu|     max|Δw| (last)   residual    min J     "
              "max eig Yw  min eig Yu" + ("  bound binds" if c.bound is not None else ""))

    from tqdm.auto import tqdm

    # the bar (stderr, only on a terminal) counts outer iterations and shows max|Δu| vs δu
    bar, update = outer_bar(cp.kept, settings.tol_u, disable=bar_disable(args))

    def progress(rec):
        update(rec)
        if not args.quiet:
            tqdm.write(f"  {rec.outer:5d}  {rec.inner:5d}  {rec.max_du:10.3e}  "
                       f"{rec.max_dw[-1]:12.3e}     {rec.residual:9.2e}  {rec.min_J:9.3g}  "
                       f"{rec.max_eig_Yw:10.3g}  {rec.min_eig_Yu:10.3g}"
                       + (f"  {100 * rec.bound_active:9.1f} %" if rec.bound_active is not None
                          else ""), file=sys.stdout)
            sys.stdout.flush()

    # the finished outer iterations are saved at most every CHECKPOINT_SECONDS, and on an
    # interruption (Ctrl-C, SIGTERM) before the error boundary reports it
    try:
        ctl = cp.train(problem, settings, progress)
    finally:
        bar.close()
    it = ctl.iterations
    print(f"\n  converged: {it['outer']} outer iterations, at most {max(it['inner'])} inner "
          f"({sum(it['inner'])} least-squares fits) in {ctl.train_seconds * 1e3:.1f} ms")

    labels = ctl.basis.labels(problem.system.state_names)
    pub = problem.published.get("weights")
    print("\n  weights" + (f" beside the paper's {problem.published.get('equation', '')}"
                           if pub else ""))
    widths = (20, 12, 12, 12)
    print("  " + _fmt_row(["term", "trained", "published", "rel.err"] if pub else
                          ["term", "trained"], widths))
    for k, (lab, w) in enumerate(zip(labels, ctl.weights)):
        if pub:
            pw = pub[k]
            rel = f"{abs(w - pw) / abs(pw) * 100:.1f} %" if abs(pw) >= 0.01 else \
                f"|Δ|={abs(w - pw):.4f}"
            print("  " + _fmt_row([lab, f"{w:.4f}", f"{pw:.4f}", rel], widths))
        else:
            print("  " + _fmt_row([lab, f"{w:.6g}"], widths))

    d = ctl.diagnostics(problem.mesh.points)
    print("\n  diagnostics on the mesh")
    print(f"    min eig Yu = {d['min_eig_Yu']:.4g} (> 0 {'ok' if d['min_eig_Yu'] > 0 else 'FAIL'})"
          f";  max eig Yw = {d['max_eig_Yw']:.4g} (< 0 {'ok' if d['max_eig_Yw'] < 0 else 'FAIL'})"
          f";  min J = {d['min_J']:.4g} (≥ 0 {'ok' if d['min_J'] >= 0 else 'FAIL'})")
    if "bound" in d:
        b = d["bound"]
        print(f"    input bound {ctl.cost.bound.describe()}: binds on "
              f"{100 * b['fraction_binding']:.1f} % of the mesh of Ω (the unbounded saddle "
              f"point of this J lies outside; up to {b['max_unbounded_ratio']:.3g}× the "
              f"bound); u* uses ≥ 90 % of it on {100 * b['fraction_saturated']:.1f} %; "
              f"max ‖u*‖/ū = {b['max_ratio']:.6f}")
    wide = ctl.diagnostics(1.25 * problem.mesh.points)["n_radial_decrease"]
    print(f"    J grows along rays from 0 (x·∇J > 0) on the mesh and on it scaled ×1.25: "
          f"{'ok' if d['n_radial_decrease'] == 0 and wide == 0 else 'NO'} "
          f"({d['n_radial_decrease']} and {wide} points fail; past such a ridge u* drives the "
          "state away)")
    rho = closed_loop_spectral_radius(problem.system, ctl.control)
    print(f"    closed loop under u* linearized at 0: spectral radius {rho:.6f} "
          f"({'stable' if rho < 1 else 'UNSTABLE'})")
    print(f"    relative residual of the last fit: {ctl.history[-1].residual:.3e}")
    ctl.save(out)
    print(f"\n  wrote {out}")
    cp.discard()
    return 0


# ------------------------------------------------------------------ checkpoints
# (shared with design, gamma and verify: weakgrid.cli._checkpoint)
__all__ = ["run", "add_parser", "checkpoint_path", "training_key", "CHECKPOINT_SECONDS"]

