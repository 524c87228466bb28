"""Nanoseconds per evaluation of the exported C saddle point (goal ≤ 100 ns).

Trains a preset (or reads a controller file), generates the C with
``weakgrid.game.export_c.generate_c``, compiles it with a small timing harness
(-O2, no fast-math) and reports the median over repeats of the time per call
on 4096 random states of Ω cycled through. ``--digital`` times the complete digital
controller's ``NAME_step`` instead (``weakgrid.models.export_digital``: measurement mapping,
law, rating clip 0.15 pu, bypass test), on measured signals that map to those states (GTI
presets: τ = 47.3, Vc0 = 1; SG: ωs = 100π).

    PYTHONPATH=src python benchmarks/bench_export.py [--preset case1-paper] [--file F] [--digital]
"""

from __future__ import annotations

import argparse
import shutil
import statistics
import subprocess
import tempfile
from pathlib import Path

import numpy as np

HARNESS = r"""
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "NAME.h"
#include "states.h"
static double now(void) { struct timespec t; clock_gettime(CLOCK_MONOTONIC, &t);
                          return t.tv_sec + 1e-9 * t.tv_nsec; }
int main(int argc, char **argv) {
    long calls = argc > 1 ? atol(argv[1]) : 10000000L;
    int repeats = argc > 2 ? atoi(argv[2]) : 7;
    double u[NAME_UP_N_CONTROLS], w[NAME_UP_N_DISTURBANCES], sink = 0.0;
    for (int r = 0; r < repeats; ++r) {
        double t0 = now();
        for (long k = 0; k < calls; ++k) {
            const double *x = STATES[k & (N_STATES_TABLE - 1)];
            NAME_saddle(x, u, w);
            sink += u[0] + w[0];
        }
        printf("%.3f\n", (now() - t0) / calls * 1e9);
    }
    fprintf(stderr, "sink %g\n", sink);
    return 0;
}
"""


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--preset", default="case1-paper")
    ap.add_argument("--file", type=Path, default=None, help="a controller file instead")
    ap.add_argument("--calls", type=int, default=5_000_000)
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--digital", action="store_true",
                    help="time NAME_step of the complete digital controller")
    args = ap.parse_args()
    cc = shutil.which("gcc") or shutil.which("cc")
    if cc is None:
        raise SystemExit("no C compiler found")
    from weakgrid.game.export_c import generate_c
    from weakgrid.models import load_controller, load_preset

    if args.file:
        ctl = load_controller(args.file)
        lo, hi = np.array(ctl.problem["mesh"]["lower"]), np.array(ctl.problem["mesh"]["upper"])
        label = str(args.file)
    else:
        p = load_preset(args.preset)
        ctl = p.train()
        lo, hi = np.array(p.mesh.lower), np.array(p.mesh.upper)
        label = args.preset
    name = "bench_ctl"
    X = np.random.default_rng(0).uniform(lo, hi, size=(4096, len(lo)))
    with tempfile.TemporaryDirectory() as d:
        d = Path(d)
        if args.digital:
            X, files, harness = _digital(ctl, name, X)
            for k, text in files.items():
                (d / k).write_text(text)
        else:
            src, hdr = generate_c(ctl, name, "benchmark")
            (d / f"{name}.c").write_text(src)
            (d / f"{name}.h").write_text(hdr)
            harness = HARNESS
        rows = ",\n".join("{" + ", ".join(repr(float(v)) for v in x) + "}" for x in X)
        (d / "states.h").write_text(f"#define N_STATES_TABLE 4096\nstatic const double "
                                    f"STATES[4096][{X.shape[1]}] = {{\n{rows}\n}};\n")
        (d / "main.c").write_text(harness.replace("NAME_UP", name.upper())
                                  .replace("NAME", name))
        exe = d / "bench"
        extra = [str(d / f"{name}_law.c")] if args.digital else []
        subprocess.run([cc, "-std=c99", "-O2", "-o", str(exe), str(d / "main.c"),
                        str(d / f"{name}.c"), *extra, "-lm"], check=True)
        out = subprocess.run([str(exe), str(args.calls), str(args.repeats)], check=True,
                             capture_output=True, text=True).stdout.split()
    ns = [float(v) for v in out]
    what = "digital controller step" if args.digital else "C saddle point"
    print(f"exported {what} of {label}: median {statistics.median(ns):.1f} ns per "
          f"evaluation (min {min(ns):.1f}, max {max(ns):.1f}; {args.repeats} repeats of "
          f"{args.calls} calls; gcc -O2{'' if args.digital else '; goal ≤ 100 ns'})")


DIGITAL = HARNESS.replace("double u[NAME_UP_N_CONTROLS], w[NAME_UP_N_DISTURBANCES], sink = 0.0;",
                          "double u[NAME_UP_N_OUT], sink = 0.0;\n    NAME_state s;\n"
                          "    if (NAME_init(&s, NULL) != 0) return 1;") \
    .replace("NAME_saddle(x, u, w);", "NAME_step(&s, x, u);").replace("u[0] + w[0]", "u[0]")


def _digital(ctl, name, X):
    """Measured signals mapping to the states X, the digital controller's C, its harness."""
    from weakgrid.models.export_digital import generate_digital_c, spec_from_design

    m = ctl.system
    if m.machine == "gti":
        spec = spec_from_design(m, {"tau": 47.3, "Vc0": 1.0}, rating=0.15)
        Y = np.column_stack([X[:, 0] + m.phi_s0, np.sqrt(1.0 + 2.0 * X[:, 1] / 47.3),
                             np.ones(len(X))])
    else:
        spec = spec_from_design(m, {"ws": 100 * np.pi}, rating=0.15)
        Y = np.column_stack([X[:, 0] + m.phi_s0, np.zeros(len(X)),
                             1.0 + X[:, 1] / (100 * np.pi), np.ones(len(X))])
    return Y, generate_digital_c(ctl, spec, name, "benchmark"), DIGITAL


if __name__ == "__main__":
    main()
