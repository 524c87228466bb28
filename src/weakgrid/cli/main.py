"""The ``weakgrid`` command."""

from __future__ import annotations

import argparse
import sys

from .. import __version__
from ..game.errors import WeakgridError
from . import export, gamma, reproduce, simulate, train, verify

SUBCOMMANDS = [train, gamma, verify, export, simulate, reproduce]


def build_parser() -> argparse.ArgumentParser:
    """The ``weakgrid`` argument parser with every subcommand (the CLI reference is made from it)."""
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
    """Entry point of the ``weakgrid`` command; returns the exit status (1 on a clear input error)."""
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
