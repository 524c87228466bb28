"""Logging: the package's logger and a scoped silencer for other libraries (layer-neutral).

weakgrid never changes a logger that is not its own for longer than one call:
:func:`quiet_loggers` lowers the chatter of a library (e.g. pandapower's conversion notes,
ANDES's parser) while weakgrid calls it and restores the previous level afterwards.
"""

from __future__ import annotations

import contextlib
import logging

__all__ = ["logger", "quiet_loggers"]

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
