"""Logging: the package's logger and a scoped silencer for other libraries (layer-neutral).

weakgrid never changes a logger that is not its own for longer than one call:
:func:`quiet_loggers` lowers the chatter of a library (e.g. pandapower's conversion notes,
ANDES's parser) while weakgrid calls it and restores the previous level afterwards.
"""

from __future__ import annotations

import contextlib
import logging
import sys

__all__ = ["logger", "quiet_loggers", "console"]

#: the package's logger; modules use ``logging.getLogger(__name__)`` below it
logger = logging.getLogger("weakgrid")


@contextlib.contextmanager
def quiet_loggers(*names: str, level: int = logging.ERROR):
    """Raise the level of the loggers ``names`` to ``level`` inside the ``with`` block only.

    A logger already at a higher level keeps it; on exit every level is restored exactly
    (also ``NOTSET``), whatever the block raised.
    """
    saved = {n: logging.getLogger(n).level for n in names}
    try:
        for n, old in saved.items():
            if old < level:
                logging.getLogger(n).setLevel(level)
        yield
    finally:
        for n, old in saved.items():
            logging.getLogger(n).setLevel(old)


class _Stdout(logging.StreamHandler):
    """A handler writing plain messages to the *current* ``sys.stdout`` (so that a caller that
    redirects it after the handler was made, e.g. a test's capture, still receives them)."""

    def __init__(self):
        super().__init__(sys.stdout)
        self.setFormatter(logging.Formatter("%(message)s"))

    @property
    def stream(self):
        return sys.stdout

    @stream.setter
    def stream(self, value):   # StreamHandler.__init__ assigns it; the property decides
        pass


@contextlib.contextmanager
def console(verbosity: int = 0):
    """Show the package's messages on stdout for the duration of a command (the CLI's use).

    ``verbosity``: -1 warnings and errors only (``--quiet``), 0 progress messages (INFO),
    1 or more debugging details (``-v``). The handler and level are removed on exit, so a
    host that calls :func:`weakgrid.cli.main.main` keeps its own logging setup.
    """
    level = logging.WARNING if verbosity < 0 else logging.INFO if verbosity == 0 else logging.DEBUG
    handler = _Stdout()
    old_level, old_propagate = logger.level, logger.propagate
    logger.addHandler(handler)
    logger.setLevel(level)
    logger.propagate = False
    try:
        yield handler
    finally:
        logger.removeHandler(handler)
        logger.setLevel(old_level)
        logger.propagate = old_propagate
