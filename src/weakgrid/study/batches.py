"""A study sweep's runs in batches of one grid: the seam for a batched simulator.

A batched simulator advances many scenarios of the same grid at once (issue #21). A sweep
hands it the runs that share :func:`batch_key` — the study, the load level and UPQC structure
of the run's scenario, the controller, the design load, the simulated time and the step
factor — and they may differ in anything else (the UPQC rating, fault times, ...).
:func:`simulate_many` is the hook: today it runs the batch's runs one by one with
:func:`weakgrid.study.sweep.run_point` (the scalar path); a batched simulator replaces its body
and nothing else changes (the cache, the table, the maps). The grouping itself is
:func:`weakgrid.sweep.batches.group` (pure, order-preserving), used by
:func:`weakgrid.sweep.run_sweep` with ``batch = STUDY_BATCHES``.
"""

from __future__ import annotations

from ..dotted import get_path

__all__ = ["batch_key", "simulate_many", "STUDY_BATCHES"]


def batch_key(inputs: dict) -> tuple:
    """The grid a sweep run (the input of :func:`weakgrid.study.sweep.run_point`) needs:
    ``(study name, scenario's load level, UPQC structure, controller, design load, t_end
    [s], step factor)``. Runs with equal keys can share one batched simulation."""
    study = inputs["study"]
    sc = get_path(study, f"scenarios.{inputs['scenario']}")
    t_end = inputs.get("t_end") or sc.get("t_end")
    return (study["study"]["name"], sc.get("load"), sc.get("upqc"), inputs["controller"],
            inputs.get("design_load"), None if t_end is None else float(t_end),
            float(inputs.get("dt_factor") or 1.0))


def simulate_many(runs: list) -> list:
    """Run a batch of sweep runs (inputs of :func:`weakgrid.study.sweep.run_point`, one grid:
    equal :func:`batch_key`) and return one result per run, in order: what ``run_point``
    returns (metrics, or metrics and signals), or the exception the run raised (a failed run
    stays its own row). Today one by one, the scalar path; the batched simulator plugs in
    here."""
    from .sweep import run_point

    out = []
    for inputs in runs:
        try:
            out.append(run_point(inputs))
        except Exception as exc:  # a failing run is its own row, whatever it raised
            out.append(exc)
    return out


#: ``batch`` argument of :func:`weakgrid.sweep.run_sweep` for a study's sweep.
STUDY_BATCHES = (batch_key, simulate_many)
