"""``weakgrid export``: a trained controller as the complete digital controller in C99, an
FMI 2.0 co-simulation FMU, the control law alone in C99, or portable JSON."""

from __future__ import annotations

import re
from pathlib import Path

from .. import __version__
from ..fileio import write_json_atomic
from ..fileio import write_texts_atomic
from ._common import (HelpFormatter, add_force_argument, guard_overwrite, input_file,
                      is_export_json, is_generated_c, is_weakgrid_fmu, output_folder,
                      positive_float)

NAME = "export"


def add_parser(sub):
    """Add ``weakgrid export`` to the subcommand parsers ``sub``; return its parser."""
    p = sub.add_parser(
        NAME, help="export a trained controller as a C99 digital controller, an FMU, or JSON",
        description="Export a controller file written by `weakgrid train` (or `weakgrid "
                    "design`, `weakgrid gamma --output`). --format c writes the complete "
                    "digital UPQC controller: NAME.h/NAME.c with NAME_init and NAME_step "
                    "(call once per sampling period T: measured signals -> design state -> "
                    "saddle-point law -> rating clip, bypass windows and an enable input; "
                    "C99, no allocation, only <math.h>) and the law NAME_law.h/NAME_law.c. "
                    "--format fmu builds NAME.fmu, an FMI 2.0 co-simulation FMU of the same C "
                    "(needs gcc and the extra 'fmu'). --format c-law writes the law alone "
                    "(NAME_saddle(x, u, w), NAME_value(x)); --format json the model, basis, "
                    "weights, cost and saddle-point formula. The digital controller's "
                    "constants (measurement mapping at the operating point, rating, bypass "
                    "windows) come from --study (its grid at --load) and --scenario, else from "
                    "the controller file and --param/--rating/--bypass.",
        formatter_class=HelpFormatter)
    p.add_argument("file", type=input_file, help="controller file (JSON)")
    p.add_argument("--format", choices=("c", "fmu", "c-law", "json"), default="c",
                   help="what to write")
    p.add_argument("--name", default=None,
                   help="C symbol/file prefix (default: the file name up to its first dot, "
                        "made a C identifier)")
    p.add_argument("--output-dir", "-d", type=output_folder, default=None,
                   help="folder for the output (default: the controller file's folder)")
    g = p.add_argument_group("digital controller (--format c, fmu)")
    g.add_argument("--study", default=None,
                   help="study (file or shipped name) whose grid gives the measurement "
                        "mapping's operating point and the rating")
    g.add_argument("--load", default=None,
                   help="load level of --study (default: the study's design.load)")
    g.add_argument("--scenario", default=None,
                   help="scenario of --study whose bypass windows the controller keeps")
    g.add_argument("--rating", type=positive_float, default=None,
                   help="UPQC rating: the largest series-voltage magnitude [pu] (default: "
                        "--study's upqc.rating, else the controller's input bound, else no "
                        "clip)")
    g.add_argument("--bypass", action="append", default=None, metavar="START:END",
                   help="a bypass window [START, END) in s (repeatable)")
    g.add_argument("--param", action="append", default=None, metavar="NAME=VALUE",
                   help="a measurement-mapping constant (GTI: phi_s0, tau, Vc0; SG: angle0, "
                        "ws), repeatable")
    add_force_argument(p, overwrite="an output file", limits=False)
    p.set_defaults(func=run)
    return p


_OWN = {".c": (is_generated_c, "C written by weakgrid and unchanged since"),
        ".h": (is_generated_c, "a C header written by weakgrid and unchanged since"),
        ".json": (is_export_json, "a JSON export"),
        ".fmu": (is_weakgrid_fmu, "an FMU")}


def _guard(paths, force):
    """Refuse to replace a file that is not weakgrid's own export of the same kind (a
    hand-edited .c included) unless --force."""
    for p in paths:
        own, what = _OWN[Path(p).suffix]
        guard_overwrite(p, own, what, force)


def _write_c(files: dict, force) -> list[Path]:
    """Generated C files (path → text), each stamped with its checksum, together."""
    from ..hashing import stamp_c

    _guard(files, force)
    return write_texts_atomic({p: stamp_c(t) for p, t in files.items()})


def _digital_names(name) -> list[str]:
    """The files ``--format c`` writes for ``name``."""
    return [f"{name}.h", f"{name}.c", f"{name}_law.h", f"{name}_law.c"]


def default_name(path: Path) -> str:
    """C symbol prefix from a controller file name: its part up to the first dot, made a C identifier."""
    stem = path.name.split(".")[0] or "controller"
    name = re.sub(r"[^A-Za-z0-9_]", "_", stem)
    return name if re.match(r"[A-Za-z_]", name) else f"c_{name}"


def _window(text):
    from ..game.errors import ParameterError

    try:
        a, b = (float(v) for v in text.split(":"))
    except ValueError:
        raise ParameterError("--bypass", text, "give START:END in s, e.g. 3.0:3.2") from None
    return a, b


def _params(items):
    from ..game.errors import ParameterError

    out = {}
    for it in items or ():
        k, sep, v = it.partition("=")
        try:
            out[k.strip()] = float(v)
        except ValueError:
            out[k.strip()] = None
        if not sep or out[k.strip()] is None:
            raise ParameterError("--param", it, "give NAME=VALUE, e.g. ws=314.159")
    return out


def digital_spec(ctl, args):
    """The digital controller's constants from the command line (see the help)."""
    from ..game.errors import ParameterError
    from ..models.export_digital import check_exportable, spec_from_design, spec_from_setup

    check_exportable(ctl)
    bypass = [_window(b) for b in args.bypass or ()]
    rating = args.rating
    if rating is None and args.study is None:
        b = getattr(ctl.cost, "bound", None)
        if b is not None and b.shape == "disk":
            rating = float(b.limit[0])
    values = _params(args.param)
    if args.study is None:
        for k in ("load", "scenario"):
            if getattr(args, k) is not None:
                raise ParameterError(f"--{k}", getattr(args, k), "needs --study")
        return spec_from_design(ctl.system, values, bypass, rating)
    from ..study.build import build_setup
    from ..study.studyfile import load_study

    if values:
        raise ParameterError("--param", args.param, "the constants come from --study; "
                             "give one or the other")
    st = load_study(args.study)
    setup = build_setup(st, args.load, ctl.system.upqc)
    if abs(setup.design.T - ctl.system.T) > 1e-12 * ctl.system.T:
        raise ParameterError("--study", args.study,
                             f"its sampling period design.T = {setup.design.T:g} s differs "
                             f"from the controller's T = {ctl.system.T:g} s")
    if args.scenario is not None:
        sc = next((s for s in st.scenarios() if s["id"] == args.scenario), None)
        if sc is None:
            raise ParameterError("--scenario", args.scenario,
                                 f"choose one of {[s['id'] for s in st.scenarios()]}")
        bypass = [tuple(b) for b in sc["bypass"]] + bypass
    return spec_from_setup(setup, bypass, rating)


def _write_digital(ctl, args, name, prov):
    from ..models.export_digital import generate_digital_c

    spec = digital_spec(ctl, args)
    files = generate_digital_c(ctl, spec, name, prov)
    print(f"digital controller {name}: T = {ctl.system.T:g} s, {spec.state_map.machine} "
          f"measurement mapping")
    for k, v, u, d in spec.parameters():
        print(f"  {k:<12} = {v!r:<22} [{u}]  {spec.origin.get(k, 'default')}")
    print(f"  bypass windows: {str(spec.bypass) + ' s' if spec.bypass else 'none'}; "
          f"rating clip: {'|u| <= %g pu' % spec.Vmax if spec.Vmax else 'off'}")
    return spec, files


def run(args) -> int:
    """Run ``weakgrid export`` with the parsed ``args``; return the exit status."""
    from ..game.errors import ParameterError
    from ..game.export_c import generate_c, valid_c_name
    from ..game.export_json import describe_controller
    from ..models import load_controller

    path = Path(args.file)
    if not path.exists():
        raise FileNotFoundError(f"controller file {path} does not exist (write one with "
                                "`weakgrid train --preset case1-paper --output FILE`)")
    ctl = load_controller(path)
    name = valid_c_name(args.name) if args.name else default_name(path)
    out = Path(args.output_dir) if args.output_dir else path.parent
    kind = ctl.problem.get("model", {}).get("kind", ctl.system.kind)
    prov = f"From {path.name} (weakgrid {__version__}; model kind {kind})."
    if args.format == "c":
        _guard([out / k for k in _digital_names(name)], args.force)
        _, files = _write_digital(ctl, args, name, prov)
        _write_c({out / k: v for k, v in files.items()}, args.force)
        print(f"weakgrid export: wrote {', '.join(str(out / k) for k in files)}")
        print(f"  int {name}_init({name}_state *s, const {name}_params *p);  "
              f"int {name}_step({name}_state *s, const double *meas, double *u_out);")
        print(f"  compile: cc -std=c99 -O2 -c {name}.c {name}_law.c   (link with -lm)")
        return 0
    if args.format == "fmu":
        from ..fmu import build_fmu
        from ..models.export_digital import fmu_block

        _guard([out / f"{name}.fmu"], args.force)
        spec, files = _write_digital(ctl, args, name, prov)
        try:
            target = build_fmu(fmu_block(ctl, spec, name), files, out / f"{name}.fmu",
                               tool=f"weakgrid {__version__}")
        except ImportError as exc:     # the optional extra is not installed
            raise ParameterError("--format", "fmu", str(exc)) from None
        print(f"weakgrid export: wrote {target} (FMI 2.0 co-simulation, binaries/linux64, "
              "sources/); communication step = T")
        return 0
    if args.format == "c-law":
        src, hdr = generate_c(ctl, name, prov)
        _write_c({out / f"{name}.h": hdr, out / f"{name}.c": src}, args.force)
        print(f"weakgrid export: wrote {out / (name + '.c')} and {out / (name + '.h')}")
        print(f"  int {name}_saddle(const double x[{ctl.system.n_states}], "
              f"double u[{ctl.system.n_controls}], double w[{ctl.system.n_disturbances}]);"
              f"  double {name}_value(const double x[{ctl.system.n_states}]);")
        print(f"  compile: cc -std=c99 -O2 -c {name}.c   (link with -lm)")
        return 0
    if args.format == "json":
        d = describe_controller(ctl, __version__, str(path))
        target = out / f"{name}.export.json"
        _guard([target], args.force)
        write_json_atomic(target, d)
        print(f"weakgrid export: wrote {target}")
        return 0
    raise ParameterError("--format", args.format, "use c, fmu, c-law or json")  # pragma: no cover
