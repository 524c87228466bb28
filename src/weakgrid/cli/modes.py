"""``weakgrid modes``: small-signal analysis of a study's grid (table and plot)."""

from __future__ import annotations


from ._common import HelpFormatter, nonnegative_float, output_file
from ._study import add_operating_point, add_study_argument, study_of

NAME = "modes"


def add_parser(sub):
    """Add ``weakgrid modes`` to the subcommand parsers ``sub``; return its parser."""
    p = sub.add_parser(
        NAME, help="eigenvalues, frequencies, damping and participation of a study's grid",
        description="Linearize the full DAE of the study's grid at its operating point "
                    "(algebraic variables eliminated), print every oscillatory mode with its "
                    "frequency, damping ratio and most participating states, mark the mode of "
                    "the controlled machine beside the design model's, and plot them.",
        formatter_class=HelpFormatter)
    add_study_argument(p)
    add_operating_point(p)
    p.add_argument("--min-hz", type=nonnegative_float, default=0.0,
                   help="list modes above this frequency (Hz, ≥ 0)")
    p.add_argument("--plot", type=output_file(".png", ".svg", ".pdf"), default=None,
                   help="eigenvalue plot (.png, .svg or .pdf)")
    p.add_argument("--output", "-o", type=output_file(".csv"), default=None,
                   help="every mode as a CSV table (eigenvalue, frequency, damping, dominant states)")
    p.add_argument("--state-matrix", type=output_file(".npz"), default=None,
                   help="the linearized grid as NumPy arrays: A, B (inputs: the UPQC's Vup, Vuq), "
                        "C (output: the controlled machine's speed) and the state names")
    p.set_defaults(func=run)
    return p


def run(args) -> int:
    """Run ``weakgrid modes`` with the parsed ``args``; return the exit status."""
    import numpy as np

    from ..design import design_mode, machine_mode, mode_states, modes
    from ..study.build import build_setup

    st = study_of(args)
    setup = build_setup(st, args.load, args.upqc)
    m = modes(setup.system)
    k_m, part = machine_mode(m, mode_states(setup.derivation))
    rows = m.table(min_hz=args.min_hz)
    print(f"study {st.name}: {setup.load} load, {setup.upqc} UPQC; {setup.system.nx} states, "
          f"{len(rows)} oscillatory modes (upper half-plane)")
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
        import io

        from ..design import state_space
        from ..fileio import write_bytes_atomic

        omega = f"{setup.source}.omega"
        ss = state_space(setup.system, outputs=[omega], upqc=setup.upqc_name)
        buf = io.BytesIO()
        np.savez(buf, A=ss.A, B=ss.B, C=ss.C, D=ss.D, states=np.array(setup.system.state_names()),
                 inputs=np.array([f"{setup.upqc_name}.Vup", f"{setup.upqc_name}.Vuq"]),
                 outputs=np.array([omega]))
        write_bytes_atomic(args.state_matrix, buf.getvalue())
        print(f"  wrote {args.state_matrix} (A {ss.A.shape}, B {ss.B.shape}, C {ss.C.shape}; "
              "weakgrid.design.state_space gives it as a python-control StateSpace)")
    # |λ| < 1e-4: the rigid-body (angle reference) modes, numerically zero
    unstable = [lam for lam in m.eigenvalues if lam.real > 1e-6 and abs(lam) > 1e-4]
    if unstable:
        print(f"  {len(unstable)} eigenvalue(s) with positive real part: "
              f"{', '.join(f'{x:.3g}' for x in unstable)}")
    lam_d = design_mode(setup.derivation.model)
    print(f"  => mode of the controlled machine '{setup.source}' (participation {part:.2f}); "
          f"design model (10): {abs(lam_d.imag) / (2 * np.pi):.4g} Hz")
    if args.plot:
        from ..figure import new_figure

        fig, ax = new_figure(figsize=(7, 4.5))
        lam = m.eigenvalues
        ax.scatter(lam.real, lam.imag, s=12, label="full grid")
        if k_m is not None:
            ax.scatter([lam[k_m].real], [lam[k_m].imag], s=60, facecolors="none",
                       edgecolors="r", label=f"mode of {setup.source}")
        ax.scatter([0, 0], [lam_d.imag, -lam_d.imag], marker="x", c="k",
                   label="design model (10)")
        lim = max(40.0, 1.2 * abs(lam_d.imag))
        ax.set_ylim(-lim, lim)
        ax.set_xlim(max(lam.real.min(), -4 * lim), max(1.0, lam.real.max() + 1))
        for z in (0.05, 0.1):
            x = np.linspace(ax.get_xlim()[0], 0, 2)
            ax.plot(x, -x * np.sqrt(1 - z**2) / z, ":", c="0.6", lw=0.8)
            ax.plot(x, x * np.sqrt(1 - z**2) / z, ":", c="0.6", lw=0.8)
        ax.set_xlabel("real part σ [1/s]")
        ax.set_ylabel("imaginary part ω [rad/s]")
        ax.set_title(f"{st.name}: eigenvalues ({setup.load} load; dotted: ζ = 5 %, 10 %)",
                     fontsize=10)
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
        fig.tight_layout()
        from ..fileio import savefig_atomic

        savefig_atomic(fig, args.plot, dpi=110)
        print(f"  wrote {args.plot}")
    return 0
