"""Feed a Dask cluster from the client, a task per free worker thread, highest priority first.

Dask's scheduler gives a task to a worker as soon as it is submitted unless the task's group
(the tasks whose keys share a prefix) holds more tasks than twice the cluster's threads; only
such groups wait on the scheduler, each to the first worker that frees. So a few long
batches submitted at once were spread over the workers' own queues at submission, whatever
their priorities and however long each turned out: in a full ``weakgrid reproduce`` on 2
workers the maps' batches started in the order 45, 30, 6, 45, 30, 30, 6 runs against a
cost order of 45, 45, 30, 30, 30, 6, 6, and a run could end with one worker on a long batch
while the other idled (about 20 s of 160 s, 2026-12-07). :class:`TaskFeed` keeps no more
tasks on the cluster than it has threads and submits the next, by priority, when one ends:
the free worker always takes the highest-priority task left (the greedy longest-first
schedule when the priorities order the tasks by cost).
"""

from __future__ import annotations

import heapq
import itertools
from collections import defaultdict, deque

__all__ = ["TaskFeed"]


class TaskFeed:
    """Tasks for the cluster of ``client``, submitted a free thread at a time.

    Parameters
    ----------
    client : distributed.Client
    slots : int, optional
        Tasks on the cluster at once. Default: the cluster's worker threads, asked of the
        scheduler at each submission (a worker that joins is used; at least 1).

    Tasks belong to a *group* (any hashable: the scenario runs, a sweep); :meth:`take`
    yields one group's results as its tasks end, submitting the other groups' tasks too
    as threads free, and keeps those results for their own :meth:`take`.
    """

    def __init__(self, client, slots: int | None = None):
        from distributed import as_completed

        self.client, self._slots = client, slots
        self._queue = []                     # (-priority, order, group, tag, fn, args, key)
        self._order = itertools.count()
        self._running = {}                   # future -> (group, tag)
        self._ended = defaultdict(deque)     # group -> (tag, future) ended, not yet taken
        self._left = defaultdict(int)        # group -> tasks queued or running
        self._completed = as_completed(loop=client.loop)   # (not the default client's)

    def slots(self) -> int:
        """Tasks the feed keeps on the cluster at once (see ``slots`` above)."""
        if self._slots is not None:
            return max(1, int(self._slots))
        return max(1, sum(self.client.nthreads().values()))

    def add(self, group, tag, fn, *args, priority: float = 0, key: str | None = None):
        """Queue ``fn(*args)`` (submitted at once if a thread is free); ``tag`` comes back
        with its result from :meth:`take`."""
        heapq.heappush(self._queue, (-priority, next(self._order), group, tag, fn, args, key))
        self._left[group] += 1
        self._fill()

    def _fill(self):
        free = self.slots() - len(self._running) if self._queue else 0
        for _ in range(free):
            if not self._queue:
                break
            neg, _, group, tag, fn, args, key = heapq.heappop(self._queue)
            kw = {} if key is None else {"key": key}
            fut = self.client.submit(fn, *args, pure=False, priority=-neg, **kw)
            self._running[fut] = (group, tag)
            self._completed.add(fut)

    def _wait_one(self):
        self._fill()
        while True:
            fut = next(self._completed)
            if fut in self._running:          # (not already taken by :meth:`ended`)
                break
        group, tag = self._running.pop(fut)
        self._ended[group].append((tag, fut))
        self._fill()

    def take(self, group):
        """``(tag, result)`` of each task of ``group`` as it ends (results raise as
        ``Future.result`` does), until the group has none left."""
        while self._left[group]:
            if not self._ended[group]:
                self._wait_one()
                continue
            tag, fut = self._ended[group].popleft()
            self._left[group] -= 1
            yield tag, fut.result()

    def ended(self, group):
        """``(tag, result)`` of the tasks of ``group`` that have ended successfully so far,
        without waiting (for an interrupted caller to keep them)."""
        for fut in [f for f in self._running if f.done()]:
            grp, tag = self._running.pop(fut)
            self._ended[grp].append((tag, fut))
        self._fill()
        out = []
        for tag, fut in list(self._ended[group]):
            if fut.status == "finished":
                self._ended[group].remove((tag, fut))
                self._left[group] -= 1
                out.append((tag, fut.result()))
        return out

    def cancel(self):
        """Drop the queued tasks and cancel the running ones."""
        self._queue.clear()
        for fut in self._running:
            fut.cancel()
        self._running.clear()
        self._left.clear()
