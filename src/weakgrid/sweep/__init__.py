"""Sweeps: many independent runs on ``dask.distributed``, cached and resumable.

Knows nothing about power systems: a sweep is a list of inputs (a base input
with some fields varied along axes, :mod:`weakgrid.sweep.axes`), a function
that runs one input and returns its metrics, and a cache of finished runs keyed
by a hash of their full input and the code (:mod:`weakgrid.sweep.cache`).
:func:`run_sweep` runs them on a local cluster (one worker process per core) or
an existing one, with a progress bar, and returns one table, a row per run;
:func:`submit_sweep` submits them to an open cluster beside the caller's own tasks and
returns at once (its :class:`PendingSweep` collects the table); :class:`TaskFeed` feeds a
cluster a task per free worker thread, the highest priority first.
"""

from .axes import Axis, Point, expand, get_path, set_path
from .cache import ResultCache, canonical_json, code_fingerprint, run_key
from .batches import Batch, group, scatter
from .feed import TaskFeed
from .engine import (PendingSweep, SweepInterrupted, execute, execute_batch, open_client,
                     results_table, run_sweep, submit_sweep)

__all__ = ["Axis", "Point", "expand", "get_path", "set_path", "ResultCache", "canonical_json",
           "code_fingerprint", "run_key", "SweepInterrupted", "execute", "execute_batch",
           "results_table", "Batch", "group", "scatter",
           "run_sweep", "submit_sweep", "PendingSweep", "TaskFeed", "open_client"]
