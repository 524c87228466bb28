"""The ``weakgrid`` command, and its one error boundary.

Every error of the package and of the operating system becomes one or two lines
on stderr — what, where, the value, the fix — and an exit code:

====  ==========================================================================
0     success
2     bad input: a file, a field or an argument (fix the input and re-run)
3     a failure during the run (simulation, training, disk full, …)
4     an internal error (a bug: re-run with ``--debug`` and report the traceback)
130   interrupted (Ctrl-C or SIGTERM); finished results are kept
====  ==========================================================================

``--debug`` (anywhere on the command line) prints the traceback as well.
"""

from __future__ import annotations

import argparse
import errno
import json
import signal
import sys
import tomllib
import traceback

from .. import __version__
from . import export, gamma, reproduce, simulate, train, verify
from . import design, modes, run  # studies
from . import sweep  # sweeps of studies
from . import plot  # run files
from . import schema  # the study file's schema and reference

SUBCOMMANDS = [train, gamma, verify, export, simulate, reproduce]
SUBCOMMANDS += [design, run, modes]
SUBCOMMANDS += [sweep]
SUBCOMMANDS += [plot]
SUBCOMMANDS += [schema]

EXIT_OK, EXIT_INPUT, EXIT_RUN, EXIT_BUG, EXIT_INTERRUPT = 0, 2, 3, 4, 130


class _Parser(argparse.ArgumentParser):
    """argparse with a one-line error (the usage is one ``--help`` away)."""

    def error(self, message):
        self.exit(EXIT_INPUT, f"{self.prog}: error: {message}. See `{self.prog} --help`.\n")


def build_parser() -> argparse.ArgumentParser:
    """The ``weakgrid`` argument parser with every subcommand (the CLI reference is made from it)."""
    parser = _Parser(
        prog="weakgrid",
        description="Game-theoretic (HJI) nonlinear optimal stabilizers with a UPQC for weak "
                    "and islanded grids.",
        epilog="Exit codes: 0 success, 2 bad input, 3 failure during a run, 4 internal error, "
               "130 interrupted. --debug prints the traceback of an error.")
    parser.add_argument("--version", action="version", version=f"weakgrid {__version__}")
    parser.add_argument("--debug", action="store_true",
                        help="print the full traceback of an error")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for mod in SUBCOMMANDS:
        _add_verbosity(mod.add_parser(sub))
    return parser


def _add_verbosity(p):
    """``--quiet``/``-q``, ``--no-progress`` and ``--verbose``/``-v`` on a subcommand (the
    package's log level and the progress bars, :func:`._common.bar_disable`; a command that
    already has ``--quiet`` keeps its own, which also shortens its tables)."""
    if "--quiet" not in p._option_string_actions:
        p.add_argument("--quiet", "-q", action="store_true",
                       help="print only warnings, errors and the results (no progress bars, "
                            "no informational messages of the library)")
    if "--no-progress" not in p._option_string_actions:
        p.add_argument("--no-progress", action="store_true",
                       help="no progress bars on stderr (they show only on a terminal)")
    p.add_argument("--verbose", "-v", action="count", default=0,
                   help="more detail (repeatable)")


def _input_errors():
    from ..game.errors import ParameterError, ShapeError
    from ..sim.errors import DataError

    return (ParameterError, ShapeError, DataError)


def _os_message(exc: OSError) -> tuple[str, int]:
    """One line for an OSError: what happened to which path, and the fix."""
    if exc.filename is None and exc.errno is None:  # raised with a message of ours
        return str(exc), (EXIT_INPUT if isinstance(exc, FileNotFoundError) else EXIT_RUN)
    path = exc.filename if exc.filename is not None else "?"
    what = exc.strerror or str(exc)
    code = exc.errno
    if isinstance(exc, FileNotFoundError):
        return (f"'{path}' does not exist. Fix: check the path (or create the folder "
                "first)", EXIT_INPUT)
    if isinstance(exc, IsADirectoryError):
        return f"'{path}' is a folder where a file is expected. Fix: give a file name", EXIT_INPUT
    if isinstance(exc, NotADirectoryError):
        return (f"'{path}': a part of this path is a file where a folder is expected. Fix: "
                "choose another folder", EXIT_INPUT)
    if isinstance(exc, PermissionError):
        return (f"permission denied on '{path}'. Fix: choose a file/folder you can "
                "read/write, or change its permissions", EXIT_INPUT)
    if isinstance(exc, FileExistsError):
        return f"'{path}' already exists. Fix: remove it or choose another name", EXIT_INPUT
    if code in (errno.ENOSPC, errno.EDQUOT):
        return (f"no space left on the device while writing '{path}'; the previous file "
                "(if any) is unchanged. Fix: free space or write elsewhere", EXIT_RUN)
    if code == errno.EROFS:
        return f"'{path}' is on a read-only file system. Fix: write elsewhere", EXIT_INPUT
    if code == errno.ENAMETOOLONG:
        return f"the file name '{path}' is too long. Fix: use a shorter name", EXIT_INPUT
    return f"{what} ({path})", EXIT_RUN


def describe_error(exc: BaseException) -> tuple[str, int]:
    """The message (one or two lines) and the exit code for an error reaching the CLI."""
    from ..game.errors import WeakgridError
    from ..sim.errors import SimError

    if isinstance(exc, KeyboardInterrupt):
        return ("interrupted; finished results are kept — re-run the same command to "
                "continue", EXIT_INTERRUPT)
    if isinstance(exc, _input_errors()):
        return str(exc), EXIT_INPUT
    if isinstance(exc, tomllib.TOMLDecodeError):
        return f"not valid TOML: {exc}. Fix: correct the file's syntax", EXIT_INPUT
    if isinstance(exc, json.JSONDecodeError):
        return (f"not valid JSON: {exc.msg} at line {exc.lineno} column {exc.colno}. Fix: "
                "correct the file or write it again", EXIT_INPUT)
    if isinstance(exc, UnicodeDecodeError):
        return (f"a file is not UTF-8 text (byte {exc.object[exc.start:exc.start + 1]!r} at "
                f"position {exc.start}). Fix: give a text file (TOML/JSON)", EXIT_INPUT)
    if isinstance(exc, OSError):
        return _os_message(exc)
    if isinstance(exc, MemoryError):
        return ("out of memory. Fix: a coarser mesh/grid or fewer runs (see the estimate "
                "printed before the run)", EXIT_RUN)
    if isinstance(exc, (WeakgridError, SimError)):
        return str(exc), EXIT_RUN
    return (f"internal error {type(exc).__name__}: {exc}\n  this is a bug: re-run with "
            "--debug and report the traceback", EXIT_BUG)


def _sigterm(signum, frame):
    raise KeyboardInterrupt


def main(argv=None) -> int:
    """Entry point of the ``weakgrid`` command; returns the exit status (0 ok, 2 bad input,
    3 failure during a run, 4 internal error, 130 interrupted)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    debug = "--debug" in argv
    argv = [a for a in argv if a != "--debug"]
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse: --help/--version (0) or a bad argument (2)
        return exc.code if isinstance(exc.code, int) else EXIT_INPUT
    if not getattr(args, "command", None):
        parser.print_help()
        return EXIT_INPUT
    previous = None
    try:
        previous = signal.signal(signal.SIGTERM, _sigterm)
    except ValueError:  # not the main thread
        pass
    from ..logs import console

    try:
        from ..sim.kernels import choice   # WEAKGRID_KERNELS checked before any work

        choice()
        with console(-1 if getattr(args, "quiet", False) else getattr(args, "verbose", 0)):
            return int(args.func(args) or 0)
    except BaseException as exc:  # the one error boundary
        if isinstance(exc, SystemExit):
            raise
        if isinstance(exc, BrokenPipeError):  # `weakgrid … | head`: the reader left
            return EXIT_RUN
        msg, code = describe_error(exc)
        sys.stdout.flush()
        if debug:
            traceback.print_exc()
        print(f"\nweakgrid {args.command}: error: {msg}", file=sys.stderr, flush=True)
        return code
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
