"""The scan's scheduler: relax the points of a warm-start tree missing from the store.

A point runs as soon as its warm-start parent (:mod:`flatcontact.ispes.order`) is stored
(:class:`ReadyQueue`); it starts from the parent's relaxed positions (kept in memory for a
while, :class:`PositionsCache`, else read back from the store: the same float64 array) and,
where parent and grandparent lie in its column, from their linear extrapolation in z. The
start of every point is therefore fixed by the tree, whatever order the points finish in,
and the worker's calculator starts afresh at every point
(:func:`flatcontact.ispes.relax.start_afresh`): a point's numbers are a function of the
grid alone.
:class:`Scheduler` keeps twice as many points in flight as the executor has workers, stores
each result as it arrives and commits the store when the points stored are due, also while
it waits (:data:`COMMIT_INTERVAL_S`).
"""

from __future__ import annotations

import collections
import heapq
import math
import os
from collections.abc import Callable

import numpy as np

from flatcontact.foundation.errors import InputError
from flatcontact.ispes.executors import Executor
from flatcontact.ispes.relax import PointTask, ScanContext, run_task
from flatcontact.ispes.scan_probe import MANY_WORKERS
from flatcontact.ispes.store import PointStore

#: The grid's stored points are committed this long (s) after the first of them was
#: stored, whether results keep arriving or the driver waits for the next one (it waits at
#: most until then: :meth:`PointStore.commit_due_in_s`); with the serial executor, which
#: relaxes the next point in the driver, before a point the last one's duration says would
#: end past that deadline; and at the end. A ``kill -9`` loses at most the points stored in
#: the last ``COMMIT_INTERVAL_S`` (and the points in flight); SIGINT and a normal end lose
#: none (the store commits when it closes). A commit costs ≈ 0.55 ms of the driver's CPU:
#: when the driver committed before every wait, points of 2-3 force calls (≈ 9 ms) made it
#: commit after almost every point (1,242 commits for 1,296 points, 0.7 s of the driver's
#: 2.5 s on a 2-worker quartz scan; docs/performance.md).
COMMIT_INTERVAL_S = 0.5
#: The environment variable that sets another interval (s, ≥ 0; 0 commits every point as it
#: is stored: what a test that kills the driver mid-scan and reads the store needs)
COMMIT_INTERVAL_ENV = "FLATCONTACT_COMMIT_INTERVAL_S"


def commit_interval_s() -> float:
    """The store's commit interval: ``FLATCONTACT_COMMIT_INTERVAL_S`` if set, else
    :data:`COMMIT_INTERVAL_S`; a value that is no number ≥ 0 is one InputError naming it."""
    raw = os.environ.get(COMMIT_INTERVAL_ENV)
    if raw is None or raw.strip() == "":
        return COMMIT_INTERVAL_S
    try:
        value = float(raw)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value >= 0):
        raise InputError(f"{COMMIT_INTERVAL_ENV}={raw!r}: expected seconds >= 0 (e.g. 0.5)")
    return value


#: From this many workers on, the ready points are ranked deepest branch first
#: (:func:`deepest_first`); below, in the tree's visiting order. The probe's threshold.
DEEPEST_FIRST_WORKERS = MANY_WORKERS


class Scheduler:
    """Relaxes the points of warm-start trees into ``store`` on ``executor``.

    Parameters
    ----------
    store
        The point store: every result is written as it arrives.
    executor
        Where the points run (:class:`~flatcontact.ispes.executors.Executor`).
    context
        The reference, factory and relaxation settings the workers need.
    shifts
        The lateral grid's ``(shift_a, shift_b)`` values (:meth:`GridSpec.shifts`).
    progress
        ``progress(done, total)`` after every stored point, or None.
    max_new_points
        Stop after this many new points (benchmarks), or None.

    ``computed_calls`` lists the force calls of every point this scheduler computed.
    """

    def __init__(
        self,
        store: PointStore,
        executor: Executor,
        context: ScanContext,
        shifts: tuple[np.ndarray, np.ndarray],
        progress: Callable[[int, int], None] | None = None,
        max_new_points: int | None = None,
    ):
        self.store, self.executor, self.context = store, executor, context
        self.sa, self.sb = shifts
        self.progress = progress
        self.max_new_points = max_new_points
        self.recent = PositionsCache()
        self.computed_calls: list[int] = []
        #: wall seconds of the last point relaxed (a serial scan commits before relaxing the
        #: next one if it would take the store past its commit deadline)
        self.last_point_s = 0.0

    def run(
        self,
        parent: dict,
        z: np.ndarray,
        weight: dict | None = None,
        total: int | None = None,
    ) -> None:
        """Relax the points of the tree ``parent`` (thicknesses ``z``) missing from the store.

        Progress counts ``weight[idx]`` (default 1) per stored point out of ``total``
        (default: the tree's points): a representative of a reduced scan counts the grid
        points it fills, so one bar runs to the grid.
        """
        store, executor = self.store, self.executor
        weight = weight or {}
        rank = {idx: k for k, idx in enumerate(parent)}
        if executor.workers >= DEEPEST_FIRST_WORKERS:
            rank = deepest_first(parent, rank)
        pending = {idx for idx in parent if idx not in store}
        total = len(parent) if total is None else total
        stored = sum(weight.get(idx, 1) for idx in parent if idx in store)
        self._report(stored, total)
        in_flight: dict = {}
        cap = 2 * max(1, executor.workers)
        queue = ReadyQueue(parent, rank, store, pending)
        while pending or in_flight:
            if not in_flight and not self._may_start(0):
                break
            while queue and len(in_flight) < cap and self._may_start(len(in_flight)):
                idx = queue.pop()
                if executor.inline and self.last_point_s >= store.commit_due_in_s():
                    store.flush()  # the submit relaxes the point here: it would be overdue
                handle = executor.submit(run_task, self.context, self.task(parent, z, idx))
                in_flight[handle] = idx
                pending.discard(idx)
            if not in_flight:
                break
            done, _ = executor.wait_first(in_flight, timeout=store.commit_due_in_s())
            if not done:  # the written points are due while the driver waits: commit them
                store.flush()
                done, _ = executor.wait_first(in_flight)
            for handle in done:
                idx = in_flight.pop(handle)
                result = executor.result(handle)
                self.last_point_s = result.seconds
                store.write(result)
                self.recent.put(idx, result.positions)
                queue.stored(idx)
                self.computed_calls.append(result.force_calls)
                stored += weight.get(idx, 1)
                self._report(stored, total)
        store.flush()  # before the assembly and the checks that follow

    def _may_start(self, in_flight: int) -> bool:
        """Whether one more point may start under ``max_new_points``."""
        return (
            self.max_new_points is None
            or len(self.computed_calls) + in_flight < self.max_new_points
        )

    def _report(self, stored: int, total: int) -> None:
        if self.progress is not None:
            self.progress(stored, total)

    def task(self, parent: dict, z: np.ndarray, idx) -> PointTask:
        """The task of point ``idx``: warm-started from its parent in the tree if that
        converged, with the grandparent's positions too when all three share a column."""
        par = parent[idx]
        ia, ib, iz = idx
        if not self._converged(par):
            return PointTask(idx, float(self.sa[ia]), float(self.sb[ib]), float(z[iz]))
        pa, pb, pz = par
        grand = parent[par]
        previous = {}
        if self._converged(grand) and grand[:2] == par[:2] == idx[:2]:
            previous = {
                "previous_positions": self._positions(grand),
                "previous_thickness": float(z[grand[2]]),
            }
        return PointTask(
            idx,
            float(self.sa[ia]),
            float(self.sb[ib]),
            float(z[iz]),
            self._positions(par),
            (float(self.sa[pa]), float(self.sb[pb])),
            float(z[pz]),
            par,
            **previous,
        )

    def _converged(self, idx) -> bool:
        return idx is not None and idx in self.store and self.store.record(idx)["converged"]

    def _positions(self, idx) -> np.ndarray:
        cached = self.recent.get(idx)
        return cached if cached is not None else self.store.positions(idx)


def deepest_first(parent: dict, rank: dict) -> dict:
    """Ranks for :class:`ReadyQueue` that put, of the ready points, the one with the longest
    chain of descendants below it first (ties: the tree's visiting order ``rank``).

    With many workers the warm-start tree's long branches then start early and the grid's
    last points leave fewer workers idle (the paper preset at 16 workers: 0.15 s of a 15.7 s
    round, ``benchmarks/schedule_model.py``). Each point keeps its warm-start parent, so the
    numbers do not change; only the order in which points are computed does.
    """
    children: dict = {}
    for idx, par in parent.items():
        children.setdefault(par, []).append(idx)
    order, stack = [], list(children.get(None, []))
    while stack:  # parents before children
        idx = stack.pop()
        order.append(idx)
        stack.extend(children.get(idx, []))
    height: dict = {}
    for idx in reversed(order):
        height[idx] = 1 + max((height[c] for c in children.get(idx, [])), default=0)
    ranked = sorted(parent, key=lambda idx: (-height.get(idx, 1), rank[idx]))
    return {idx: k for k, idx in enumerate(ranked)}


class ReadyQueue:
    """The points whose warm-start parent is stored, in the search tree's visiting order.

    A heap keyed by the point's rank in the tree: each stored point pushes its children,
    so scheduling costs O(log n) per point (scanning every pending point for readiness
    after each stored point cost O(n) each, O(n²) per scan: seconds of driver CPU on a
    paper-size grid, taken from the workers' cores).
    """

    def __init__(self, parent: dict, rank: dict, store, pending: set):
        self._rank = rank
        self._pending = pending
        self._children: dict = {}
        for idx, par in parent.items():
            if par is not None:
                self._children.setdefault(par, []).append(idx)
        self._heap = [
            (rank[idx], idx) for idx in pending if parent[idx] is None or parent[idx] in store
        ]
        heapq.heapify(self._heap)

    def __bool__(self) -> bool:
        return bool(self._heap)

    def pop(self):
        """The earliest ready point in visiting order."""
        return heapq.heappop(self._heap)[1]

    def stored(self, idx) -> None:
        """``idx`` is stored: its pending children become ready."""
        for child in self._children.get(idx, ()):
            if child in self._pending:
                heapq.heappush(self._heap, (self._rank[child], child))


class PositionsCache:
    """Relaxed positions of recently stored points, kept in memory for the warm starts.

    The driver has each result's positions in hand when it stores it; its children and
    grandchildren start from them moments later. Keeping them (least recently used out,
    at most ``budget_bytes``) spares a database read per submitted point; a point not in
    the cache is read from the store (the same float64 array, bit for bit).
    """

    def __init__(self, budget_bytes: int = 64 * 2**20):
        self._budget = int(budget_bytes)
        self._bytes = 0
        self._items: collections.OrderedDict = collections.OrderedDict()

    def put(self, idx, positions: np.ndarray) -> None:
        arr = np.asarray(positions, dtype=float)
        if arr.nbytes > self._budget:
            return
        self._items[idx] = arr
        self._bytes += arr.nbytes
        while self._bytes > self._budget:
            _, old = self._items.popitem(last=False)
            self._bytes -= old.nbytes

    def get(self, idx) -> np.ndarray | None:
        arr = self._items.get(idx)
        if arr is not None:
            self._items.move_to_end(idx)
            return arr.copy()
        return None
