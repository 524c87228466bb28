"""DPsim's own console output, taken off the process's stdout/stderr and re-emitted as logging.

DPsim 1.4 writes from C++ whatever its log level: ``std::cout`` a line per switch event
(``1.000000e-01: Handle event time``) and spdlog a ``MnaSolverFactory info`` line on stderr.
A library speaks through :mod:`logging`, so :class:`NativeOutput` points the file descriptors
1 and 2 at a temporary file *only while a DPsim call runs* (``out.call(sim.next)``)
and, when the run ends, logs every captured line at DEBUG on ``weakgrid.sim.emt.dpsim``.

The redirect is at the level of the process's file descriptors (the only place C++ output can
be caught), so it is kept as short as one DPsim call: weakgrid's Python code between the calls
(controllers, machine controls, its own logging) writes to the real stdout/stderr. Another
thread of the same process writing to fd 1 or 2 during a DPsim call would have its text logged
at DEBUG instead; weakgrid runs a simulation in one thread.
"""

from __future__ import annotations

import ctypes
import logging
import os
import tempfile

#: the logger DPsim's captured lines are re-emitted on (at DEBUG)
log = logging.getLogger("weakgrid.sim.emt.dpsim")

__all__ = ["NativeOutput"]


def _c_fflush():
    """``fflush(NULL)`` of the C library (``std::cout`` is synchronized with C stdio), or a no-op."""
    try:
        f = ctypes.CDLL(None).fflush
    except (OSError, AttributeError):      # no C library to reach: nothing buffered there
        return lambda: None
    f.argtypes = [ctypes.c_void_p]
    return lambda: f(None)


class NativeOutput:
    """Capture the C/C++ output of DPsim calls; re-emit it through :mod:`logging` on exit.

    Use as ``with NativeOutput() as out: ... out.call(sim.next) ...``. Outside a ``call`` the
    process's stdout and stderr are untouched.
    """

    def __init__(self, logger: logging.Logger = log):
        self.logger = logger
        self._tmp = None
        self._saved = None
        self._fflush = _c_fflush()

    def __enter__(self):
        self._tmp = tempfile.TemporaryFile(prefix="weakgrid-dpsim-out-")
        try:
            self._saved = (os.dup(1), os.dup(2))
        except OSError:           # no stdout/stderr descriptors (a daemon): nothing to capture
            self._saved = None
        return self

    def call(self, fn, *args):
        """``fn(*args)`` with file descriptors 1 and 2 writing to the capture file; its result.

        Python's own buffered output needs no flush here: no Python code runs inside a DPsim
        call. The C library's buffers are flushed before (text written outside a call stays
        outside) and after (DPsim's text goes into the capture file).
        """
        if self._saved is None:
            return fn(*args)
        fd = self._tmp.fileno()
        self._fflush()
        os.dup2(fd, 1)
        os.dup2(fd, 2)
        try:
            return fn(*args)
        finally:
            self._fflush()
            os.dup2(self._saved[0], 1)
            os.dup2(self._saved[1], 2)

    def __exit__(self, *exc):
        try:
            if self._saved is not None:
                for fd in self._saved:
                    os.close(fd)
            self._tmp.seek(0)
            text = self._tmp.read().decode("utf-8", errors="replace")
        finally:
            self._tmp.close()
        for line in text.splitlines():
            if line.strip():
                self.logger.debug("%s", line.rstrip())
        return False
