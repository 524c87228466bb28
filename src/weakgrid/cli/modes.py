"""``weakgrid modes``: small-signal analysis of a study's grid or of a plain case (table, plot,
state matrix)."""

from __future__ import annotations


from ._case import is_case
from ._common import HelpFormatter, input_file, nonnegative_float, output_file
from ._study import add_operating_point, add_study_argument, study_of

NAME = "modes"


def add_parser(sub):
    """Add ``weakgrid modes`` to the subcommand parsers ``sub``; return its parser."""
    p = sub.add_parser(
        NAME, help="eigenvalues, frequencies, damping and participation of a study's grid or "
                   "a plain case",
        description="Linearize the full DAE of the grid at its operating point (algebraic "
                    "variables eliminated), print every oscillatory mode with its frequency, "
                    "damping ratio and most participating states, and plot them. STUDY (a "
                    ".toml file or a shipped study's name): the study's grid with its UPQC, "
                    "the mode of the controlled machine marked beside the design model's. CASE "
                    "(a .raw [+ --dyr], .m, .mat, .json or .xlsx file, as `weakgrid simulate "
                    "CASE` reads it): the grid as it is.",
        formatter_class=HelpFormatter)
    add_study_argument(p, case=True)
    add_operating_point(p)
    p.add_argument("--dyr", type=input_file, default=None,
                   help="PSS/E dynamic data (.dyr) of a case (.raw or ANDES)")
    p.add_argument("--min-hz", type=nonnegative_float, default=0.0,
                   help="list modes above this frequency (Hz, ≥ 0)")
    p.add_argument("--plot", type=output_file(".png", ".svg", ".pdf"), default=None,
                   help="eigenvalue plot (.png, .svg or .pdf)")
    p.add_argument("--output", "-o", type=output_file(".csv"), default=None,
                   help="every mode as a CSV table (eigenvalue, frequency, damping, dominant states)")
    p.add_argument("--state-matrix", type=output_file(".npz"), default=None,
                   help="the linearized grid as NumPy arrays: A, B (inputs: a study's UPQC's "
                        "Vup, Vuq; none for a case), C (outputs: a study's controlled "
                        "machine's speed; every machine's speed for a case) and the state names")
    p.set_defaults(func=run)
    return p


def _refuse(args, case):
    from ..game.errors import ParameterError

    opts = {"load": "--load", "upqc": "--upqc", "overrides": "--set"} if case else \
        {"dyr": "--dyr"}
    for dest, opt in opts.items():
        if getattr(args, dest, None):
            raise ParameterError(opt, getattr(args, dest), f"{opt} applies to "
                                 f"{'a study' if case else 'a case file'} only, and "
                                 f"'{args.study}' is {'a case file' if case else 'a study'}")


def run(args) -> int:
    """Run ``weakgrid modes`` with the parsed ``args``; return the exit status."""
    import numpy as np

    from ..design import machine_mode, mode_states, modes

    case = is_case(args.study)
    _refuse(args, case)
    if case:
        from ..sim.io.cases import load_case

        loaded = load_case(args.study, args.dyr)
        system = loaded.system
        system.setup()
        setup = st = None
        title = f"case {args.study}"
        m = modes(system)
        k_m, part = None, 0.0
    else:
        from ..study.build import build_setup

        st = study_of(args)
        setup = build_setup(st, args.load, args.upqc)
        system = setup.system
        title = f"study {st.name}: {setup.load} load, {setup.upqc} UPQC"
        m = modes(system)
        k_m, part = machine_mode(m, mode_states(setup.derivation))
    rows = m.table(min_hz=args.min_hz)
    print(f"{title}; {system.nx} states, {len(rows)} oscillatory modes (upper half-plane)")
    print(f"  {'':2}{'mode':>5} {'σ [1/s]':>10} {'ω [rad/s]':>10} {'f [Hz]':>8} {'ζ':>7}  "
          "most participating states")
    for r in rows:
        mark = "=>" if r["mode"] == k_m else "  "
        print(f"  {mark}{r['mode']:>5} {r['real']:>10.4g} {r['imag']:>10.4g} {r['f_hz']:>8.4g} "
              f"{r['zeta']:>7.3f}  {r['dominant']}")
    if args.output:
        import pandas as pd

        from ..fileio import replace_atomic

        table = pd.DataFrame(m.table(oscillatory_only=False))
        replace_atomic(args.output, lambda tmp: table.to_csv(tmp, index=False))
        print(f"  wrote {args.output} ({len(table)} modes)")
    if args.state_matrix:
        _write_state_matrix(args.state_matrix, system, setup)
    # |λ| < 1e-4: the rigid-body (angle reference) modes, numerically zero
    unstable = [lam for lam in m.eigenvalues if lam.real > 1e-6 and abs(lam) > 1e-4]
    if unstable:
        print(f"  {len(unstable)} eigenvalue(s) with positive real part: "
              f"{', '.join(f'{x:.3g}' for x in unstable)}")
    lam_d = None
    if setup is not None:
        from ..design import design_mode

        lam_d = design_mode(setup.derivation.model)
        print(f"  => mode of the controlled machine '{setup.source}' (participation {part:.2f}); "
              f"design model (10): {abs(lam_d.imag) / (2 * np.pi):.4g} Hz")
        f_grid = float(m.frequency_hz[k_m]) if k_m is not None else float("nan")
        for name, mod in setup.derivation.forms.items():     # both forms of design.grid_model
            if mod is None:
                continue
            fd = abs(design_mode(mod).imag) / (2 * np.pi)
            used = " (used)" if name == setup.derivation.grid_model else ""
            print(f"     grid_model = {name!r}{used}: {fd:.4g} Hz, "
                  f"{(fd - f_grid) / f_grid:+.1%} vs the grid's {f_grid:.4g} Hz")
    if args.plot:
        _plot(args.plot, m, k_m, lam_d, setup, st.name if st is not None else str(args.study))
    return 0


def _write_state_matrix(path, system, setup):
    import io

    import numpy as np

    from ..design import state_space
    from ..fileio import write_bytes_atomic

    names = system.state_names()
    if setup is not None:
        outputs = [f"{setup.source}.omega"]
        inputs = [f"{setup.upqc_name}.Vup", f"{setup.upqc_name}.Vuq"]
        ss = state_space(system, outputs=outputs, upqc=setup.upqc_name)
        A, B, C, D = ss.A, ss.B, ss.C, ss.D
        how = "weakgrid.design.state_space gives it as a python-control StateSpace"
    else:     # a plain case has no UPQC: no input, the machines' speeds as outputs
        from ..design.modes import linearize

        outputs = [f"{mn}.omega" for mn in system.machine_names if f"{mn}.omega" in names]
        inputs = []
        A = linearize(system)
        B, D = np.zeros((len(names), 0)), np.zeros((len(outputs), 0))
        C = np.zeros((len(outputs), len(names)))
        for r, o in enumerate(outputs):
            C[r, names.index(o)] = 1.0
        how = "no inputs: the case has no UPQC; A is weakgrid.design.modes.linearize's"
    buf = io.BytesIO()
    np.savez(buf, A=A, B=B, C=C, D=D, states=np.array(names),
             inputs=np.array(inputs, dtype=str), outputs=np.array(outputs, dtype=str))
    write_bytes_atomic(path, buf.getvalue())
    print(f"  wrote {path} (A {A.shape}, B {B.shape}, C {C.shape}; {how})")


EM_HZ_MAX = 3.0     # Hz, the top of the electromechanical range the eigenvalue plot shows
EM_ZETA_MAX = 0.3   # damping ratio above which an oscillatory pole is not an electromechanical mode


def _plot(path, m, k_m, lam_d, setup, name):
    import numpy as np

    from ..fileio import savefig_atomic
    from ..figure import new_figure

    fig, ax = new_figure(figsize=(7, 4.5))
    lam = m.eigenvalues
    ax.scatter(lam.real, lam.imag, s=12, label="full grid")
    if k_m is not None:
        ax.scatter([lam[k_m].real], [lam[k_m].imag], s=60, facecolors="none",
                   edgecolors="r", label=f"mode of {setup.source}")
    if lam_d is not None:
        ax.scatter([0, 0], [lam_d.imag, -lam_d.imag], marker="x", c="k",
                   label="design model (10)")
    # zoomed on the electromechanical range (lightly damped, |f| ≤ EM_HZ_MAX), not autoscaled
    # to the fastest pole; the poles outside the view are counted in a note
    zeta = -lam.real / np.maximum(np.abs(lam), 1e-12)
    em = lam[(np.abs(lam.imag) > 1e-6) & (np.abs(lam.imag) <= 2 * np.pi * EM_HZ_MAX)
             & (zeta <= EM_ZETA_MAX)]
    tops = list(np.abs(em.imag)) + ([abs(lam_d.imag)] if lam_d is not None else [])
    ylim = 1.15 * max(tops + [2 * np.pi * EM_HZ_MAX])
    re = list(em.real) + ([lam[k_m].real] if k_m is not None else [])
    lo, hi = min(re + [-0.5]), max(re + [0.0])
    ax.set_ylim(-ylim, ylim)
    ax.set_xlim(2.0 * lo, max(0.5, 2.0 * hi))
    x0, x1 = ax.get_xlim()
    out = lam[(lam.real < x0) | (lam.real > x1) | (np.abs(lam.imag) > ylim)]
    if out.size:
        w = np.abs(out.imag).max()
        ax.text(0.01, 0.01, f"{out.size} poles outside the view (σ from {out.real.min():.3g} "
                f"to {out.real.max():.3g} 1/s" + (f", |ω| up to {w:.3g} rad/s" if w > ylim
                                                   else "") + ")",
                transform=ax.transAxes, fontsize=7, color="0.3")
    for z in (0.05, 0.1):
        x = np.linspace(ax.get_xlim()[0], 0, 2)
        ax.plot(x, -x * np.sqrt(1 - z**2) / z, ":", c="0.6", lw=0.8)
        ax.plot(x, x * np.sqrt(1 - z**2) / z, ":", c="0.6", lw=0.8)
    ax.set_xlabel("real part σ [1/s]")
    ax.set_ylabel("imaginary part ω [rad/s]")
    load = f"{setup.load} load; " if setup is not None else ""
    ax.set_title(f"{name}: electromechanical eigenvalues, |f| ≤ {EM_HZ_MAX:g} Hz ({load}"
                 "dotted: ζ = 5 %, 10 %)", fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    savefig_atomic(fig, path, dpi=110)
    print(f"  wrote {path}")
