"""weakgrid — game-theoretic (HJI) nonlinear optimal stabilizers with a UPQC.

Layers (imports flow one way): ``cli → study → (sim, models) → game``.

* :mod:`weakgrid.game` — control-affine systems, polynomial bases, the two-loop
  HJI policy iteration and the LQ game. Knows nothing about power systems.
* :mod:`weakgrid.models` — the paper's design models (Section II) and control laws.
* :mod:`weakgrid.sim` — the detailed phasor-domain (RMS) simulator.
* :mod:`weakgrid.study` — case studies, baselines, metrics and reports.
* :mod:`weakgrid.cli` — the ``weakgrid`` command.
"""

from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("weakgrid")
except PackageNotFoundError:  # pragma: no cover - running from a source tree
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
