"""weakgrid — game-theoretic (HJI) nonlinear optimal stabilizers with a UPQC.

Layers (imports flow one way): ``cli → study → (sim, models) → game``.

* :mod:`weakgrid.game` — control-affine systems, polynomial bases, the two-loop
  HJI policy iteration and the LQ game. Knows nothing about power systems.
* :mod:`weakgrid.models` — the paper's design models (Section II) and control laws.
* :mod:`weakgrid.sim` — the detailed phasor-domain (RMS) simulator.
* :mod:`weakgrid.study` — case studies, baselines, metrics and reports.
* :mod:`weakgrid.cli` — the ``weakgrid`` command.
"""

from ._version import __version__

__all__ = ["__version__", "read_run"]


def __getattr__(name):
    # lazy: ``import weakgrid`` stays cheap (no numpy/pandas/pyarrow until a run is read)
    if name == "read_run":
        from .sim.runfile import read_run

        return read_run
    raise AttributeError(f"module 'weakgrid' has no attribute {name!r}")
