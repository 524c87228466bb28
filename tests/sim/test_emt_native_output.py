"""DPsim's C++ console output goes to logging, not to the process's stdout/stderr.

DPsim 1.4 prints ``<t>: Handle event time`` on stdout (``std::cout``) at every switch event and a
``MnaSolverFactory info`` line on stderr (spdlog) per run. weakgrid.sim.emt.native_output
redirects file descriptors 1 and 2 during each DPsim call and re-emits the lines at DEBUG.
"""

import ctypes
import logging
import os

import pytest

from weakgrid.sim.emt.native_output import NativeOutput
from weakgrid.sim.events import Fault

from sim_cases import classical_smib

LOGGER = "weakgrid.sim.emt.dpsim"


def _c_printf(text: str):
    """Write through the C library's buffered stdout (as ``std::cout`` does), no flush."""
    libc = ctypes.CDLL(None)
    libc.printf.argtypes = [ctypes.c_char_p]
    libc.printf(text.encode())


def test_only_the_calls_are_captured(capfd, caplog):
    caplog.set_level(logging.DEBUG, logger=LOGGER)
    with NativeOutput() as out:
        os.write(1, b"before\n")
        r = out.call(lambda: (os.write(1, b"inside-out\n"), os.write(2, b"inside-err\n"),
                              _c_printf("inside-c\n"), 42)[-1])
        os.write(2, b"between\n")
        out.call(_c_printf, "no-newline")      # still in C's buffer when the call returns
        os.write(1, b"after\n")
    got = capfd.readouterr()
    assert r == 42
    assert got.out == "before\nafter\n"
    assert got.err == "between\n"
    logged = [rec.getMessage() for rec in caplog.records if rec.name == LOGGER]
    assert logged == ["inside-out", "inside-err", "inside-c", "no-newline"]
    assert all(rec.levelno == logging.DEBUG for rec in caplog.records if rec.name == LOGGER)


def test_exception_in_a_call_restores_the_descriptors(capfd):
    with pytest.raises(RuntimeError):
        with NativeOutput() as out:
            out.call(lambda: (_ for _ in ()).throw(RuntimeError("boom")))
    os.write(1, b"visible\n")
    assert capfd.readouterr().out == "visible\n"


@pytest.mark.emt
@pytest.mark.parametrize("engine", ["dpsim-dp", "dpsim-emt"])
def test_a_dpsim_run_leaves_stdout_and_stderr_clean(engine, capfd, caplog):
    pytest.importorskip("dpsimpy")
    from weakgrid.sim.emt import simulate_dpsim

    caplog.set_level(logging.DEBUG, logger=LOGGER)
    r = simulate_dpsim(classical_smib(p=0.8, M=6.0), 0.05, engine=engine, dt=1e-4,
                       events=[Fault(bus=1, t_on=0.01, t_off=0.02)])
    assert r.failure is None
    got = capfd.readouterr()
    assert got.out == "" and got.err == ""
    logged = [rec.getMessage() for rec in caplog.records if rec.name == LOGGER]
    assert sum("Handle event time" in m for m in logged) == 2       # the fault's two switchings
    assert any("MnaSolverFactory" in m for m in logged)
