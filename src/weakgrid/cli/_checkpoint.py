"""Checkpoints of the long commands (train, design, gamma, verify): found, kept, resumed.

One pattern for every long command:

* the checkpoint lies beside the command's output (its name ends in
  ``.checkpoint.npz``) and carries a key — a content hash of everything the result
  depends on (:func:`content_key`): a checkpoint of other inputs is said to be
  stale and ignored, a damaged one is reported in one warning line and ignored;
* the work in progress is saved at most every :data:`CHECKPOINT_SECONDS`, at once
  when a unit of work is finished (a γ trial), and on an interruption (Ctrl-C,
  SIGTERM) before the error boundary of :mod:`weakgrid.cli.main` reports it; one
  line then says what was kept and how to continue (re-run the same command);
* ``--restart`` ignores a checkpoint; a finished command removes its checkpoint.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path


CHECKPOINT_SECONDS = 1.0  # work shorter than this writes no checkpoint unless stopped


def add_restart_argument(p, what="the work"):
    """``--restart``: ignore the checkpoint of an interrupted run."""
    p.add_argument("--restart", action="store_true",
                   help=f"start over, ignoring the checkpoint of an interrupted run ({what})")


def checkpoint_path(out: Path, kind: str = "") -> Path:
    """The checkpoint of the run that writes ``out``: beside it, ``[.KIND].checkpoint.npz``."""
    return Path(out).with_suffix((f".{kind}" if kind else "") + ".checkpoint.npz")


def content_key(inputs: dict) -> str:
    """A content hash of ``inputs`` (JSON-able) and of the code (every source and data file
    of the package, with its version): :func:`weakgrid.hashing.content_key`."""
    from ..hashing import content_key as key

    return key(inputs)


def problem_inputs(problem, settings) -> dict:
    """What a training of ``problem`` depends on: the problem file as read, the cost (with
    any bound), mesh, basis and solver settings after the command-line overrides."""
    return {"problem": problem.raw, "name": problem.name, "cost": problem.cost.to_dict(),
            "mesh": problem.mesh.to_dict(), "basis": problem.basis.to_dict(),
            "settings": settings.to_dict()}


def training_key(problem, settings, command: str = "train", **extra) -> str:
    """The key of a training by ``command`` (see :func:`problem_inputs`; ``extra`` adds
    inputs the problem file does not hold, e.g. a derived model)."""
    return content_key({"command": command, **problem_inputs(problem, settings), **extra})


def load_kept(path: Path, key: str, load, command: str, log=print):
    """What ``load(path, key)`` finds in the checkpoint ``path``, or None (said why)."""
    from ..game.checkpoint import CheckpointError, StaleCheckpointError

    path = Path(path)
    if not path.exists():
        return None
    try:
        return load(path, key)
    except StaleCheckpointError:
        log(f"  the checkpoint {path} is of other inputs (the problem, the settings or the "
            "code changed): starting over; it will be replaced")
    except CheckpointError as exc:
        print(f"weakgrid {command}: warning: {exc}: ignored, starting over (it will be "
              "replaced; delete it to silence this warning)", file=sys.stderr, flush=True)
    return None


class Keeper:
    """The latest state of a long computation, saved to ``path`` with ``key`` by
    ``save(path, state, key)``: at most every :data:`CHECKPOINT_SECONDS`, or at once.

    A checkpoint that cannot be written (read-only folder, disk full) is said once in a
    warning line and the work goes on without one: the checkpoint only protects the work.
    """

    def __init__(self, path: Path, key: str, save, saved=None, command="train"):
        self.path, self.key, self._save, self.command = Path(path), key, save, command
        self.state = self.saved = saved  # `saved`: a state loaded from the file
        self._at = time.monotonic()
        self.failed = None

    def keep(self, state, now: bool = False):
        """Hold ``state``; save it if ``now`` or if the last save is old enough."""
        self.state = state
        if now or time.monotonic() - self._at >= CHECKPOINT_SECONDS:
            self.flush()

    def flush(self):
        """Save the state held if it is not saved yet; return the state saved (or None)."""
        if self.state is not None and self.state is not self.saved and self.failed is None:
            try:
                self._save(self.path, self.state, self.key)
            except OSError as exc:
                from .main import describe_error

                self.failed = describe_error(exc)[0]
                print(f"weakgrid {self.command}: warning: cannot write the checkpoint: "
                      f"{self.failed}; going on without one (an interruption will lose the "
                      "work done)", file=sys.stderr, flush=True)
                return self.saved
            self.saved, self._at = self.state, time.monotonic()
        return self.saved

    def discard(self):
        """Remove the checkpoint (the result is written)."""
        try:
            self.path.unlink(missing_ok=True)
        except OSError as exc:
            from .main import describe_error

            print(f"weakgrid {self.command}: warning: cannot remove the checkpoint: "
                  f"{describe_error(exc)[0]}", file=sys.stderr, flush=True)


def say_kept(what: str, path: Path, log=print):
    """The line of an interruption: what was kept where, and how to continue."""
    log(f"\n  kept {what} in {path}; re-run the same command to continue", flush=True)


class TrainingCheckpoint:
    """The checkpoint of one training (:meth:`TrainingProblem.train`): resumed when it is
    of the same inputs, kept on an interruption.

    Parameters
    ----------
    path : Path
    key : str
        :func:`training_key`.
    restart : bool
        Ignore the checkpoint.
    command : str
        For the messages.
    what : str
        The training, in the messages (e.g. "of the controller").
    """

    def __init__(self, path, key, restart=False, command="train", what="", log=print):
        from ..game.checkpoint import load_checkpoint, save_checkpoint

        self.path, self.command, self.what, self.log = Path(path), command, what, log
        self.start = None if restart else load_kept(self.path, key, load_checkpoint,
                                                    command, log)
        self.keeper = Keeper(self.path, key, save_checkpoint, self.start, command)
        if self.start is not None:
            log(f"  resuming from the checkpoint {self.path}: {self.start.outer} finished "
                f"outer iteration(s){self.what} kept, continuing at iteration "
                f"{self.start.outer + 1}")

    @property
    def kept(self) -> int:
        """Outer iterations resumed from the checkpoint (0 if none)."""
        return self.start.outer if self.start is not None else 0

    def interrupted(self):
        """Save the finished iterations and say so (call on KeyboardInterrupt)."""
        saved = self.keeper.flush()
        if saved is not None and saved.outer:
            say_kept(f"{saved.outer} finished outer iteration(s){self.what}", self.path,
                     self.log)

    def train(self, problem, settings=None, progress=None):
        """``problem.train`` from the checkpoint, keeping its iterations; the controller."""
        try:
            return problem.train(settings, progress=progress, start=self.start,
                                 checkpoint=self.keeper.keep)
        except KeyboardInterrupt:
            self.interrupted()
            raise

    def discard(self):
        """Remove the checkpoint (the result is written)."""
        self.keeper.discard()


LINE_SECONDS = 10.0  # without a terminal, a progress line at most this often


def outer_bar(initial: int, tol: float, desc="  training", lines=False, disable=None):
    """A progress bar (stderr, only on a terminal) counting outer iterations; returns
    ``(bar, update(record))``. With ``lines``, when there is no terminal (output to a
    file or a pipe) a line on stdout says how far the training is every
    :data:`LINE_SECONDS`. ``disable``: tqdm's (``True`` with ``--quiet``/``--no-progress``,
    which also silence the lines)."""
    from tqdm.auto import tqdm

    bar = tqdm(desc=desc, unit=" outer it", leave=False, disable=disable, initial=initial)
    lines = lines and disable is not True
    last = [time.monotonic()]

    def update(rec):
        bar.update(1)
        bar.set_postfix_str(f"max|Δu| {rec.max_du:.2e} → δu {tol:g}", refresh=False)
        if lines and bar.disable and time.monotonic() - last[0] >= LINE_SECONDS:
            last[0] = time.monotonic()
            print(f"{desc}: outer iteration {rec.outer}, max|Δu| {rec.max_du:.2e} → δu "
                  f"{tol:g}", flush=True)
    return bar, update
