"""``weakgrid design``: set up a study's grid, derive the design model (10), check it against
the full grid's mode, train the HJI controller and write it."""

from __future__ import annotations

from pathlib import Path

from ._checkpoint import TrainingCheckpoint, add_restart_argument, checkpoint_path, outer_bar
from ._checkpoint import training_key
from ._common import (HelpFormatter, add_force_argument, bar_disable, guard_overwrite,
                      is_controller_file, output_file)
from ._study import add_operating_point, add_study_argument, study_of

NAME = "design"


def add_parser(sub):
    """Add ``weakgrid design`` to the subcommand parsers ``sub``; return its parser."""
    p = sub.add_parser(
        NAME, help="derive the design model (10) of a study and train its HJI controller",
        description="Build the study's grid at an operating point, derive the design model "
                    "(10) with every intermediate value and its source, set its mode beside the "
                    "full grid's mode in which the controlled machine participates most, train "
                    "the HJI controller with the study's design settings and write it.",
        formatter_class=HelpFormatter)
    add_study_argument(p)
    add_operating_point(p)
    p.add_argument("--output", "-o", type=output_file(".json"), default=None,
                   help="controller file (default: <study>-<load>-<upqc>.controller.json)")
    p.add_argument("--no-train", action="store_true", help="derive and check only")
    add_restart_argument(p, "OUTPUT with the suffix .checkpoint.npz")
    add_force_argument(p, overwrite="an OUTPUT file", limits=False)
    p.set_defaults(func=run)
    return p


def _is_derivation(path) -> bool:
    import json

    try:
        d = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(d, dict) and {"derivation", "mode_check", "study"} <= set(d)


def run(args) -> int:
    """Run ``weakgrid design`` with the parsed ``args``; return the exit status."""
    from ..fileio import write_json_atomic
    from ..study.build import build_setup
    from ..study.controllers import design_problem
    from ..study.engine import MODE_TOLERANCE, mode_check

    st = study_of(args)
    setup = build_setup(st, args.load, args.upqc)
    der = setup.derivation
    d = der.model
    print(f"study {st.name} ({st.source}): {setup.load} load, {setup.upqc} UPQC "
          f"'{setup.upqc_name}' in branch {setup.system.network.branch_label(setup.upqc_branch)} "
          f"(shunt bus r = {setup.system.network.bus_label(setup.shunt_bus)})")
    print(f"controlled machine: {der.machine.upper()} '{der.name}'; line power through the "
          f"UPQC {setup.line_power_mw:.4g} MW")
    print("\ndesign model (10), derived:")
    print(der.table())
    print(f"\n  => T = {d.T:.4g} s, a = {d.a:.5g}, V̄r = {d.Vr_bar:.4g} pu, ϕs0 = {d.phi_s0:.4g} rad")
    chk = mode_check(setup)
    print("\nmode check (design model (9) linearized vs the full grid's DAE):")
    print(f"  design model: {chk['design_f_hz']:.4g} Hz (undamped)")
    if chk["grid_lambda"] is None:
        print("  full grid: no oscillatory mode involves the machine's states")
    else:
        lam = chk["grid_lambda"]
        print(f"  full grid:    {chk['grid_f_hz']:.4g} Hz, ζ = {chk['grid_zeta']:.3g}, "
              f"λ = {lam.real:.4g} ± {abs(lam.imag):.4g}j; participation of "
              f"{'+'.join(chk['states'])}: {chk['participation']:.2f} ({chk['dominant']})")
    verdict = "agree" if chk["ok"] else "MISMATCH"
    print(f"  frequency mismatch {chk['mismatch']:+.1%} (tolerance {MODE_TOLERANCE:.0%}): "
          f"{verdict}")
    for name, fm in chk.get("forms", {}).items():   # both forms of design.grid_model
        used = " (used)" if name == chk.get("grid_model") else ""
        print(f"  grid_model = {name!r}{used}: {fm['f_hz']:.4g} Hz, {fm['mismatch']:+.1%}")
    if der.forms_note:
        print(f"  grid_model = 'thevenin': {der.forms_note}")
    if args.no_train:
        return 0
    out = args.output or Path(f"{st.name}-{setup.load}-{setup.upqc}.controller.json")
    guard_overwrite(out, is_controller_file, "a controller file", args.force)
    der_path = out.with_suffix("").with_suffix(".derivation.json") if \
        out.name.endswith(".controller.json") else Path(str(out) + ".derivation.json")
    guard_overwrite(der_path, _is_derivation, "a derivation file", args.force)
    # the training resumes from its checkpoint beside the output, as `weakgrid train` does
    problem = design_problem(st, d)
    settings = problem.settings
    print(f"\nHJI training: {problem.mesh.points.shape[0]} mesh points, "
          f"{problem.basis.size} basis terms, δu = {settings.tol_u:g}")
    cp = TrainingCheckpoint(checkpoint_path(out),
                            training_key(problem, settings, NAME, model=d.to_dict()),
                            args.restart, NAME)
    bar, update = outer_bar(cp.kept, settings.tol_u, lines=True, disable=bar_disable(args))
    try:
        ctl = cp.train(problem, settings, progress=update)
    finally:
        bar.close()
    ctl.save(out)
    write_json_atomic(der_path, {"derivation": der.to_dict(), "mode_check": {
                          k: (str(v) if isinstance(v, complex) else v) for k, v in chk.items()},
                       "study": st.source})
    n = ctl.iterations["outer"]
    print(f"HJI: {n} outer iterations"
          + (f" ({n - cp.kept} now, {cp.kept} kept from the checkpoint)" if cp.kept else "")
          + f" in {ctl.train_seconds:.2f} s; wrote {out}")
    cp.discard()
    return 0
