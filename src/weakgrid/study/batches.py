"""A study sweep's runs in batches of one grid, advanced by the batched simulator.

A batched simulator (:func:`weakgrid.sim.batch.simulate_batch`) advances many scenarios of the
same grid at once (issue #21). A sweep hands it the runs that share :func:`batch_key` — the
study, the UPQC structure of the run's scenario, the grid variant of its controller (the PQ and
no-PSS baselines change the grid), the simulated time, the step factor and the event times off
the step grid (members step together) — and they may differ in anything else: the UPQC rating
(a batchable parameter of the device,
:attr:`weakgrid.sim.component.Component.batch_params`), the load level (each member holds its
own load admittances and the set-points its initialization computed from them), fault times on
the step grid, the controller and the load it is designed at. The batch simulator compares the
members' grids itself (:func:`weakgrid.sim.batch.system_fingerprint`) and splits those that
differ otherwise.

:func:`simulate_many` prepares every run of a batch (its grid, events and digital
controller: :func:`weakgrid.study.sweep.prepare_point`), simulates them together
(:func:`weakgrid.study.runner.simulate_prepared`) and finishes each (its metrics and
signals: :func:`weakgrid.study.sweep.finish_point`). A run that raises in any part is that
run's row alone, as in the one-by-one path (:func:`weakgrid.study.sweep.run_point`). The
grouping itself is :func:`weakgrid.sweep.batches.group` (pure, order-preserving), used by
:func:`weakgrid.sweep.run_sweep` with ``batch = STUDY_BATCHES``.
"""

from __future__ import annotations

import logging
import math
import os

from ..dotted import get_path

__all__ = ["batch_key", "event_breakpoints", "simulate_many", "batch_size_for",
           "balance_for", "STUDY_BATCHES"]

log = logging.getLogger(__name__)


def batch_key(inputs: dict) -> tuple:
    """The grid and the steps a sweep run (the input of :func:`weakgrid.study.sweep.run_point`)
    needs: ``(study name, scenario's UPQC structure, the controller's grid variant, t_end [s],
    step factor, event times off the step grid)`` (not the load level: the members of a batch
    hold their own loads). Runs with equal keys share one
    batched simulation, in lockstep."""
    from types import SimpleNamespace

    from .controllers import controller_variant
    from .runner import sim_settings

    study = inputs["study"]
    sc = get_path(study, f"scenarios.{inputs['scenario']}")
    t_end = inputs.get("t_end") or sc.get("t_end")
    factor = float(inputs.get("dt_factor") or 1.0)
    dt, _ = sim_settings(SimpleNamespace(data=study), factor)
    return (study["study"]["name"], sc.get("upqc"),
            controller_variant(SimpleNamespace(data=study), inputs["controller"]),
            None if t_end is None else float(t_end), factor,
            event_breakpoints(sc.get("events") or (), dt))


def event_breakpoints(events, dt: float) -> tuple:
    """The times [s] of a study scenario's events (``t_on``, ``t_off``, ``t``) off the step
    grid ``dt`` [s] (:func:`weakgrid.sim.batch.off_grid`): runs whose off-grid times differ
    do not step together, so they are batched apart."""
    from ..sim.batch import off_grid

    return off_grid([float(e[k]) for e in events for k in ("t_on", "t_off", "t")
                     if isinstance(e, dict) and e.get(k) is not None], dt)


def simulate_many(runs: list) -> list:
    """Run a batch of sweep runs (inputs of :func:`weakgrid.study.sweep.run_point`, one grid:
    equal :func:`batch_key`) and return one result per run, in order: what ``run_point``
    returns (metrics, or metrics and signals), or the exception the run raised (a failed run
    stays its own row). The runs are simulated together
    (:func:`weakgrid.study.runner.simulate_prepared`)."""
    from .runner import simulate_prepared
    from .sweep import finish_point, prepare_point

    out: list = [None] * len(runs)
    preps = {}
    for i, inputs in enumerate(runs):
        try:
            preps[i] = prepare_point(inputs)
        except Exception as exc:  # a failing run is its own row, whatever it raised
            out[i] = exc
    rows = list(preps)
    try:
        sims = simulate_prepared([preps[i] for i in rows], batched=True)
    except Exception as exc:   # not a member's failure (those are in Results.failure)
        log.warning("the batched simulation of %d runs raised %r; running them one by one",
                    len(rows), exc)
        sims = []
        for i in rows:
            try:
                prep = prepare_point(runs[i])   # fresh controller and events
                preps[i] = prep
                sims.append(simulate_prepared([prep], batched=False)[0])
            except Exception as exc1:
                sims.append(exc1)
    for i, sim in zip(rows, sims):
        if isinstance(sim, Exception):
            out[i] = sim
            continue
        try:
            out[i] = finish_point(runs[i], preps[i], *sim)
        except Exception as exc:
            out[i] = exc
    return out


def batch_size_for(n_runs: int, workers: int | None) -> int | None:
    """The largest batch of a sweep of ``n_runs`` runs on ``workers`` processes (None: one
    per core; 0: serially): at least one batch per worker, so that the batches still spread
    over the workers; None (no limit) when serial."""
    if workers == 0:
        return None
    w = workers or os.cpu_count() or 1
    return max(1, math.ceil(n_runs / w))


def balance_for(workers: int | None) -> int | None:
    """The workers a sweep's batches are balanced over by cost
    (:func:`weakgrid.sweep.run_sweep`'s ``balance``) for ``workers`` (None: one per core; 0:
    serially, no balance)."""
    if workers == 0:
        return None
    return workers or os.cpu_count() or 1


#: ``batch`` argument of :func:`weakgrid.sweep.run_sweep` for a study's sweep.
STUDY_BATCHES = (batch_key, simulate_many)
