"""The ``weakgrid`` command."""

from __future__ import annotations

import argparse
import sys

from .. import __version__
from ..game.errors import WeakgridError
from . import export, gamma, reproduce, simulate, train, verify
from . import design, modes, run  # studies
from . import sweep  # sweeps of studies

SUBCOMMANDS = [train, gamma, verify, export, simulate, reproduce]
SUBCOMMANDS += [design, run, modes]
SUBCOMMANDS += [sweep]


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="weakgrid",
        description="Game-theoretic (HJI) nonlinear optimal stabilizers with a UPQC for weak "
                    "and islanded grids.")
    parser.add_argument("--version", action="version", version=f"weakgrid {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for mod in SUBCOMMANDS:
        mod.add_parser(sub)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "command", None):
        parser.print_help()
        return 2
    try:
        return int(args.func(args) or 0)
    except (WeakgridError, FileNotFoundError) as exc:
        print(f"weakgrid {args.command}: error: {exc}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
