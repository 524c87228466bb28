"""``weakgrid export``: a trained controller as dependency-free C99 or portable JSON."""

from __future__ import annotations

import re
from pathlib import Path

from .. import __version__
from ..fileio import write_json_atomic
from ..fileio import write_texts_atomic
from ._common import HelpFormatter, input_file, output_folder

NAME = "export"


def add_parser(sub):
    """Add ``weakgrid export`` to the subcommand parsers ``sub``; return its parser."""
    p = sub.add_parser(
        NAME, help="export a trained controller as C99 source or portable JSON",
        description="Export a controller file written by `weakgrid train` (or `weakgrid "
                    "gamma --output`). --format c writes NAME.c and NAME.h: a dependency-free "
                    "C99 function NAME_saddle(x, u, w) computing (u*, w*) with every constant "
                    "inlined and no allocation (link with -lm), and NAME_value(x) = J(x). "
                    "--format json writes NAME.export.json: the model equations and "
                    "parameters, basis exponents, weights, cost and the saddle-point formula. "
                    "Supported model kinds: 'upqc-design' (the paper's model (10)) and "
                    "'linear'.",
        formatter_class=HelpFormatter)
    p.add_argument("file", type=input_file, help="controller file (JSON)")
    p.add_argument("--format", choices=("c", "json"), default="c", help="what to write")
    p.add_argument("--name", default=None,
                   help="C symbol/file prefix (default: the file name up to its first dot, "
                        "made a C identifier)")
    p.add_argument("--output-dir", "-d", type=output_folder, default=None,
                   help="folder for the output (default: the controller file's folder)")
    p.set_defaults(func=run)
    return p


def default_name(path: Path) -> str:
    """C symbol prefix from a controller file name: its part up to the first dot, made a C identifier."""
    stem = path.name.split(".")[0] or "controller"
    name = re.sub(r"[^A-Za-z0-9_]", "_", stem)
    return name if re.match(r"[A-Za-z_]", name) else f"c_{name}"


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
    if args.format == "c":
        prov = f"From {path.name} (weakgrid {__version__}; model kind {kind})."
        src, hdr = generate_c(ctl, name, prov)
        write_texts_atomic({out / f"{name}.h": hdr, out / f"{name}.c": src})
        print(f"weakgrid export: wrote {out / (name + '.c')} and {out / (name + '.h')}")
        print(f"  int {name}_saddle(const double x[{ctl.system.n_states}], "
              f"double u[{ctl.system.n_controls}], double w[{ctl.system.n_disturbances}]);"
              f"  double {name}_value(const double x[{ctl.system.n_states}]);")
        print(f"  compile: cc -std=c99 -O2 -c {name}.c   (link with -lm)")
        return 0
    if args.format == "json":
        d = describe_controller(ctl, __version__, str(path))
        target = out / f"{name}.export.json"
        write_json_atomic(target, d)
        print(f"weakgrid export: wrote {target}")
        return 0
    raise ParameterError("--format", args.format, "use 'c' or 'json'")  # pragma: no cover
