"""Group a sweep's runs into batches (runs a batched simulator can advance together).

Knows nothing about power systems: a batch is the runs whose ``key(inputs)`` is equal (for a
study's sweep, the same grid: :func:`weakgrid.study.batches.batch_key`). :func:`group` is
pure — the batches come in the order of their first run, each run keeps its order inside
its batch, every run is in exactly one batch — and :func:`scatter` puts the batches'
results back on the runs' rows.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..game.errors import ParameterError

__all__ = ["Batch", "group", "balanced", "finite_cost", "scatter"]


@dataclass(frozen=True)
class Batch:
    """Runs that share a key.

    Attributes
    ----------
    key : hashable
        The key every member shares.
    rows : tuple of int
        The members' positions in the list given to :func:`group`, increasing.
    """

    key: object
    rows: tuple

    def __len__(self):
        return len(self.rows)


def group(items, key, max_size: int | None = None, weight=None,
          max_weight: float | None = None) -> list[Batch]:
    """The batches of ``items`` by ``key(item)``.

    Parameters
    ----------
    items : sequence
        The runs (any objects; ``key`` reads them).
    key : callable
        ``key(item)`` → a hashable value; equal values share a batch.
    max_size : int, optional
        Largest batch (a larger group is split, so that batches can still be spread over
        workers). Default: no limit.
    weight : callable, optional
        ``weight(item)`` → the item's cost (a finite number ≥ 0), with ``max_weight``.
    max_weight : float, optional
        Largest summed ``weight`` of a batch: a costlier group is split too (e.g. a worker's
        share of the whole cost, so that one group does not run on one worker while the
        others idle). Default: no limit.

    Returns
    -------
    list of Batch
        In the order of each batch's first member; members in their order in ``items``. A
        group that must be split is cut into the fewest consecutive parts that satisfy both
        limits (by count; by weight, the parts' count assuming equal weights), of sizes that
        differ by one at most.
    """
    if max_size is not None and (isinstance(max_size, bool) or not isinstance(max_size, int)
                                 or max_size < 1):
        raise ParameterError("max_size", max_size, "give a whole number ≥ 1, or None (no "
                             "limit)")
    if max_weight is not None and (weight is None or isinstance(max_weight, bool)
                                   or not isinstance(max_weight, (int, float))
                                   or not max_weight > 0 or math.isinf(max_weight)):
        raise ParameterError("max_weight", max_weight, "give a finite number > 0 with a "
                             "weight function, or None (no limit)")
    rows: dict = {}
    for i, it in enumerate(items):
        rows.setdefault(key(it), []).append(i)
    out = []
    for k, r in rows.items():
        parts = 1 if max_size is None else -(-len(r) // max_size)
        if max_weight is not None:
            w = sum(float(weight(items[i])) for i in r)
            if math.isfinite(w):
                parts = max(parts, math.ceil(w / max_weight - 1e-9))
        parts = max(1, min(parts, len(r)))
        q, extra = divmod(len(r), parts)
        a = 0
        for j in range(parts):
            b = a + q + (1 if j < extra else 0)
            out.append(Batch(k, tuple(r[a:b])))
            a = b
    out.sort(key=lambda b: b.rows[0])
    return out


def finite_cost(cost, item) -> float:
    """``cost(item)``, 0 where it is not a finite number ≥ 0."""
    c = float(cost(item))
    return c if math.isfinite(c) and c >= 0 else 0.0


def balanced(items, key, max_size: int | None = None, cost=None,
             balance: int | None = None, other_cost: float = 0.0) -> list[Batch]:
    """:func:`group` with no batch above ``1/balance`` of the items' summed ``cost(item)``
    (``balance``: the workers the batches are spread over; None, or no ``cost``: by count
    alone), so that no worker is left with one long batch while the others idle.

    ``other_cost`` (in ``cost``'s unit, ≥ 0): what the same workers run besides these items (the
    scenario runs beside the maps of ``weakgrid reproduce``); it counts in the workers'
    shares. A batch cut in two costs its fixed part twice (case 2's 90 map runs: 47 s as
    one batch, 57 s as two of 45, 64 s as three of 30, serially, 2026-12-07), so a group is
    cut only where the workers' whole load needs it."""
    if balance is not None and (isinstance(balance, bool) or not isinstance(balance, int)
                                or balance < 1):
        raise ParameterError("balance", balance, "give a whole number ≥ 1 of workers, or "
                             "None (no limit by cost)")
    if isinstance(other_cost, bool) or not isinstance(other_cost, (int, float)) \
            or not (math.isfinite(other_cost) and other_cost >= 0):
        raise ParameterError("other_cost", other_cost, "give the cost of the workers' other tasks as a "
                             "finite number ≥ 0 (0: none)")
    share = None
    if balance is not None and cost is not None and len(items):
        total = sum(finite_cost(cost, it) for it in items) + float(other_cost)
        share = total / balance if total > 0 else None
    return group(items, key, max_size, weight=(lambda it: finite_cost(cost, it)) if share
                 else None, max_weight=share)


def scatter(batches, results, n: int) -> list:
    """Each batch's results (one list per batch, in its members' order) on the rows
    ``0..n-1`` they came from."""
    out = [None] * n
    seen = [False] * n
    if len(results) != len(batches):
        raise ParameterError("results", len(results), f"give one list of results per batch "
                             f"({len(batches)})")
    for b, res in zip(batches, results):
        res = list(res)
        if len(res) != len(b.rows):
            raise ParameterError("results", len(res), f"batch {b.key!r} has {len(b.rows)} "
                                 "runs: give one result per run")
        for i, r in zip(b.rows, res):
            if seen[i]:
                raise ParameterError("batches", i, "a row is in two batches")
            out[i], seen[i] = r, True
    if not all(seen):
        raise ParameterError("batches", seen.index(False), "a row is in no batch")
    return out
