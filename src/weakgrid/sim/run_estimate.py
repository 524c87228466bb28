"""What one simulation will cost, before it runs: steps × recorded variables, memory, time.

The mechanism of a sweep's estimate (:mod:`weakgrid.study.sweep_estimate`) for one run of a
plain case: the time is measured, not assumed — a short probe (:data:`PROBE_STEPS` steps of
the quiet grid at the operating point, on a separate :class:`~weakgrid.sim.integrate.Simulator`,
after :data:`WARM_STEPS` untimed steps: a process's first steps load or compile the
simulator's kernels, :mod:`weakgrid.sim.kernels`) gives the cost of a quiet step; a step from
the first disturbance on costs :data:`TRANSIENT_FACTOR` times as much (more Newton iterations
and Jacobians; the ratio the sweep's probes measure). The memory is the recorded
trajectories, steps × variables × 8 bytes, twice (while they grow and as the final array).
The result is a :class:`weakgrid.game.estimate.Estimate`, refused beyond its limits (30 min,
4 GiB or half the available memory, ``WEAKGRID_MAX_GIB``) by :meth:`~weakgrid.game.estimate.Estimate.check`
unless forced.
"""

from __future__ import annotations

import math
import time

from ..game.estimate import Estimate
from .results import RECORD_ALL_MAX

__all__ = ["PROBE_STEPS", "TRANSIENT_FACTOR", "WARM_STEPS", "recorded_columns", "run_estimate"]

PROBE_STEPS = 20
WARM_STEPS = 2
TRANSIENT_FACTOR = 3.0


def recorded_columns(system, record=None) -> int:
    """How many variables a run of the set-up ``system`` records with ``record`` (see
    :meth:`weakgrid.sim.results.Results.recorder`); patterns count as one."""
    if record is None:
        record = "all" if system.N <= RECORD_ALL_MAX else "machines"
    nm = len(system.machine_names)
    if record == "machines":
        return 2 * nm
    if record == "all":
        outs = sum(len(c.outputs) * c.n for c in system.comps)
        return system.nx + 4 * system.nb + 2 * nm + outs
    return len(record)


def run_estimate(system, t_end: float, dt: float, first_event: float | None = None,
                 record=None, probe: bool = True) -> Estimate:
    """The cost of simulating the set-up ``system`` from 0 to ``t_end`` [s] with step ``dt``.

    Parameters
    ----------
    system : System
        Set up (:meth:`~weakgrid.sim.system.System.setup`).
    t_end, dt : float
        Final time and step [s].
    first_event : float, optional
        Time of the first disturbance [s] (None: a quiet run).
    record
        What the run records (see :func:`recorded_columns`).
    probe : bool
        Time :data:`PROBE_STEPS` quiet steps (else the time is 0: memory only).

    Returns
    -------
    Estimate
        ``size`` = steps, ``bytes``, ``seconds``; :meth:`Estimate.describe` says it.
    """
    from .integrate import Simulator

    steps = int(math.ceil(t_end / dt))
    cols = recorded_columns(system, record) + 1
    nbytes = 2.0 * 8.0 * (steps + 1) * cols
    seconds = 0.0
    if probe:
        rec = [system.state_names()[0]] if system.nx else None
        # untimed first steps: a process's first steps load (or compile) the simulator's
        # kernels (weakgrid.sim.kernels), a cost paid once, not per step
        Simulator(system, dt=dt, record=rec).run(WARM_STEPS * dt, on_failure="return")
        sim = Simulator(system, dt=dt, record=rec)
        t0 = time.perf_counter()
        sim.run(PROBE_STEPS * dt, on_failure="return")
        per_step = (time.perf_counter() - t0) / PROBE_STEPS
        t_dist = t_end if first_event is None else min(first_event, t_end)
        quiet = int(math.ceil(t_dist / dt))
        seconds = per_step * (quiet + TRANSIENT_FACTOR * max(steps - quiet, 0))
    return Estimate(f"a run of {steps} steps × {cols} recorded variables", steps, nbytes,
                    seconds)
