"""Helpers shared by the subcommands (problem selection, records)."""

from __future__ import annotations

import argparse
import math
import os
from pathlib import Path

from .. import __version__
from ..models.presets import preset_names


class HelpFormatter(argparse.ArgumentDefaultsHelpFormatter):
    """Help with each option's default, said once: not appended where the help text already
    says it (``default: …``), nor where there is none to say (``None``, ``False``)."""

    def _get_help_string(self, action):
        text = action.help or ""
        if "default" in text.lower() or action.default in (None, False, argparse.SUPPRESS):
            return text
        return super()._get_help_string(action)


def add_problem_arguments(p):
    """``--preset NAME`` or ``--config FILE`` (one of them required)."""
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--preset", choices=preset_names(), help="a shipped preset")
    src.add_argument("--config", type=input_file, help="a problem file (TOML), see the README")


def problem_of(args):
    """The :class:`~weakgrid.models.TrainingProblem` selected by the arguments."""
    from ..models import load_preset, load_problem

    return load_preset(args.preset) if args.preset else load_problem(args.config)


def provenance(problem, command: str, **parameters) -> dict:
    """What a result file records about how it was made."""
    return {"command": command, "weakgrid_version": __version__, "problem": problem.name,
            "source": problem.source, "parameters": parameters}




# ------------------------------------------------------------------ argument types
# argparse turns an ArgumentTypeError into "argument --NAME: MESSAGE" and exit code 2.

def _number(text, what):
    try:
        v = float(text)
    except (TypeError, ValueError):
        raise argparse.ArgumentTypeError(f"{text!r} is not a number ({what})") from None
    if not math.isfinite(v):
        raise argparse.ArgumentTypeError(f"{text!r} is not finite: give {what}")
    return v


def finite_float(text) -> float:
    """A finite number."""
    return _number(text, "a finite number")


def positive_float(text) -> float:
    """A finite number > 0."""
    v = _number(text, "a number > 0")
    if v <= 0:
        raise argparse.ArgumentTypeError(f"{text!r} must be > 0")
    return v


def nonnegative_float(text) -> float:
    """A finite number ≥ 0."""
    v = _number(text, "a number ≥ 0")
    if v < 0:
        raise argparse.ArgumentTypeError(f"{text!r} must be ≥ 0")
    return v


def positive_int(text) -> int:
    """An integer ≥ 1."""
    try:
        v = int(text)
    except (TypeError, ValueError):
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number (give an integer "
                                         "≥ 1)") from None
    if v < 1:
        raise argparse.ArgumentTypeError(f"{text!r} must be ≥ 1")
    return v


def nonnegative_int(text) -> int:
    """An integer ≥ 0."""
    try:
        v = int(text)
    except (TypeError, ValueError):
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number (give an integer "
                                         "≥ 0)") from None
    if v < 0:
        raise argparse.ArgumentTypeError(f"{text!r} must be ≥ 0")
    return v


def worker_count(text) -> int:
    """A number of local worker processes: 0 (serial) up to 4 per core."""
    v = nonnegative_int(text)
    cap = 4 * (os.cpu_count() or 1)
    if v > cap:
        raise argparse.ArgumentTypeError(
            f"{text!r} worker processes on {os.cpu_count()} core(s): give at most {cap} (one "
            "per core is usually fastest; more only adds memory and start-up time)")
    return v


def add_cluster_arguments(p):
    """``--workers`` and ``--scheduler``: where the simulations of a command run (Dask)."""
    p.add_argument("--workers", type=worker_count, default=None,
                   help="worker processes of the local Dask cluster that runs the simulations "
                        "(default: one per core; 0 = serially in this process)")
    p.add_argument("--scheduler", type=scheduler_address, default=None,
                   help="address of an existing Dask scheduler (tcp://host:port); default: a "
                        "local cluster")


def add_batch_argument(p):
    """``--no-batch``: simulate every run alone (the scalar path) instead of the runs of one
    grid together (:mod:`weakgrid.sim.batch`; the same results, the comparison's baseline)."""
    p.add_argument("--no-batch", dest="batched", action="store_false",
                   help="simulate every run alone (one task per run), not the runs of one "
                        "grid together in batches (the default; the same results)")


_SCHEMES = ("tcp", "tls", "ucx", "ws", "wss")


def scheduler_address(text) -> str:
    """A Dask scheduler address ``[tcp://]host:port`` (the form is checked, not the host)."""
    from urllib.parse import urlsplit

    s = text.strip()
    url = urlsplit(s if "://" in s else f"tcp://{s}")
    try:
        port = url.port
    except ValueError:
        port = None
    if url.scheme not in _SCHEMES or not url.hostname or port is None or not 0 < port < 65536 \
            or url.path not in ("", "/"):
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a scheduler address: give tcp://HOST:PORT (e.g. "
            "tcp://10.0.0.5:8786), as `dask scheduler` prints it")
    host = f"[{url.hostname}]" if ":" in url.hostname else url.hostname
    return f"{url.scheme}://{host}:{port}"


def check_cluster(args, timeout: float = 5.0):
    """Before any work: the scheduler given by ``--scheduler`` answers on its port."""
    import socket
    from urllib.parse import urlsplit

    from ..game.errors import ParameterError

    address = getattr(args, "scheduler", None)
    if not address:
        return
    url = urlsplit(address)
    if url.scheme not in ("tcp", "tls"):
        return  # other transports: Dask reports them itself
    try:
        socket.create_connection((url.hostname, url.port), timeout=timeout).close()
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise ParameterError("--scheduler", address,
                             f"no Dask scheduler answers there ({reason}). Fix: start it "
                             "(`dask scheduler`) and check the address, or leave out "
                             "--scheduler to use a local cluster") from None


def output_file(*suffixes):
    """A path to write, whose suffix must be one of ``suffixes`` (checked before any work)."""
    def parse(text) -> Path:
        p = Path(text)
        if not text or text.endswith(("/", "\\")):
            raise argparse.ArgumentTypeError(f"{text!r} is a folder: give a file name "
                                             f"ending in {' or '.join(suffixes)}")
        if p.is_dir():
            raise argparse.ArgumentTypeError(f"{text!r} is a folder: give a file name")
        if suffixes and p.suffix.lower() not in suffixes:
            raise argparse.ArgumentTypeError(
                f"{text!r}: unsupported file type {p.suffix or '(none)'!r}; use "
                f"{' or '.join(suffixes)}")
        _check_writable_folder(p.parent, text)
        return p
    parse.__name__ = "output file"
    return parse


def _check_writable_folder(folder: Path, text):
    """The nearest existing ancestor of ``folder`` must be a folder we may write into."""
    q = folder if str(folder) else Path(".")
    while not q.exists() and q != q.parent:
        q = q.parent
    if not q.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r}: {str(q)!r} is a file, not a folder")
    if not os.access(q, os.W_OK | os.X_OK):
        try:
            readonly = bool(os.statvfs(q).f_flag & os.ST_RDONLY)
        except (OSError, AttributeError):  # pragma: no cover
            readonly = False
        if readonly:
            raise argparse.ArgumentTypeError(f"{text!r}: {str(q)!r} is on a read-only file "
                                             "system; write elsewhere")
        raise argparse.ArgumentTypeError(f"{text!r}: no permission to write in {str(q)!r}")


def input_file(text) -> Path:
    """An existing, readable file."""
    p = Path(text)
    if not p.exists():
        raise argparse.ArgumentTypeError(f"{text!r} does not exist")
    if p.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is a folder, not a file")
    return p


def output_folder(text) -> Path:
    """A folder to write into (created if missing); must not be an existing file."""
    p = Path(text)
    if p.exists() and not p.is_dir():
        raise argparse.ArgumentTypeError(f"{text!r} is a file, not a folder")
    _check_writable_folder(p, text)
    return p


# ------------------------------------------------------------------ long work
def show_progress(args) -> bool:
    """Progress bars wanted: neither ``--quiet`` nor ``--no-progress`` (every command has both)."""
    return not (getattr(args, "quiet", False) or getattr(args, "no_progress", False))


def bar_disable(args):
    """tqdm's ``disable`` for a command's progress bar: ``True`` with ``--quiet`` or
    ``--no-progress``, else ``None`` (shown on a terminal only; results stay on stdout)."""
    return None if show_progress(args) else True


def add_force_argument(p, overwrite: str | None = None, limits: bool = True):
    """``--force``: run beyond the estimated limits (``limits``) and/or overwrite files
    weakgrid did not write (``overwrite``: what is overwritten, for the help)."""
    parts = (["run even if the estimated memory/time exceeds the limits (4 GiB or half the "
              "available memory, 30 min; WEAKGRID_MAX_GIB)"] if limits else []) + \
        ([f"overwrite {overwrite} that weakgrid did not write"] if overwrite else [])
    p.add_argument("--force", action="store_true", help="; ".join(parts))


def _json_format(path):
    import json

    try:
        d = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return d.get("format") if isinstance(d, dict) else None


def is_controller_file(path) -> bool:
    """A controller file written by weakgrid (its format tag)."""
    from ..game.controller import FILE_FORMAT

    return _json_format(path) == FILE_FORMAT


def is_command_record(command: str):
    """``is_own`` of :func:`guard_overwrite` for a JSON record of ``command`` written by
    weakgrid (:func:`provenance`: its command and weakgrid_version fields)."""
    import json

    def own(path) -> bool:
        try:
            d = json.loads(Path(path).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return False
        return isinstance(d, dict) and d.get("command") == command and \
            isinstance(d.get("weakgrid_version"), str)
    return own


def is_export_json(path) -> bool:
    """A ``--format json`` export written by weakgrid (its format tag)."""
    from ..game.export_json import EXPORT_FORMAT

    return _json_format(path) == EXPORT_FORMAT


def is_generated_c(path) -> bool:
    """C written by weakgrid and unchanged since (its checksum line)."""
    from ..hashing import stamped_c_ok

    try:
        return stamped_c_ok(Path(path).read_bytes())
    except OSError:
        return False


def is_weakgrid_fmu(path) -> bool:
    """An FMU that weakgrid built (a zip whose modelDescription.xml names weakgrid as its
    generation tool)."""
    import zipfile

    try:
        with zipfile.ZipFile(path) as z:
            return b'generationTool="weakgrid' in z.read("modelDescription.xml")
    except (OSError, KeyError, zipfile.BadZipFile):
        return False


def guard_overwrite(path, is_own, what: str, force: bool, option: str = "--output") -> None:
    """Refuse to replace an existing ``path`` (given as ``option``) that is not weakgrid's
    own output of the same kind (``is_own(path) -> bool``) unless ``force``; names the file
    and the fix."""
    from ..game.errors import ParameterError

    p = Path(path)
    if force or not p.exists() or is_own(p):
        return
    raise ParameterError(option, str(p), f"exists and is not {what} written by weakgrid; "
                         "it is left alone. Fix: give another file name, move it, or --force "
                         "to overwrite it")


def guard_training(problem, force: bool, log=print):
    """Print the estimate of a training and refuse it beyond the limits unless ``force``."""
    from ..game.estimate import training_estimate

    n = int(problem.mesh.points.shape[0])
    est = training_estimate(n, problem.basis.size, problem.system.n_states)
    if n >= 20000 or force:
        log(f"  {est.describe()}")
    est.check("mesh.step", list(problem.mesh.step),
              f"use a larger step in [mesh] of {problem.source} (doubling every step divides "
              f"the {n} points by {2 ** problem.system.n_states})", force)
    return est


def guard_dp(n_nodes: int, force: bool, log=print):
    from ..game.estimate import dp_estimate

    est = dp_estimate(n_nodes)
    if n_nodes >= 10000 or force:
        log(f"  {est.describe()}")
    est.check("--points", int(round(n_nodes**0.5)), "use fewer --points", force)
    return est
