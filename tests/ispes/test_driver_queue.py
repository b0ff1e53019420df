"""The scan driver's ready queue and positions cache (scheduling bookkeeping, no physics)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from flatcontact.ispes.order import search_tree
from flatcontact.ispes.scan_scheduler import PositionsCache, ReadyQueue


@settings(max_examples=30, deadline=None)
@given(
    shape=st.tuples(st.integers(1, 4), st.integers(1, 4), st.integers(1, 5)),
    order=st.sampled_from(["columns", "planes", "cold"]),
    seed=st.integers(0, 1000),
)
def test_queue_releases_children_after_parents_in_tree_order(shape, order, seed):
    """Completing points in a random order among those handed out: every point is handed
    out once, after its parent is stored, and with one worker the order is the tree's."""
    root = (0, 0, shape[2] // 2)
    parent = search_tree(shape, root, order)
    rank = {idx: k for k, idx in enumerate(parent)}
    for workers in (1, 3):
        rng = np.random.default_rng(seed)
        stored: set = set()
        pending = set(parent)
        queue = ReadyQueue(parent, rank, stored, pending)
        handed, in_flight = [], []
        while pending or in_flight:
            while queue and len(in_flight) < workers:
                idx = queue.pop()
                assert parent[idx] is None or parent[idx] in stored
                pending.discard(idx)
                handed.append(idx)
                in_flight.append(idx)
            done = in_flight.pop(int(rng.integers(len(in_flight))))
            stored.add(done)
            queue.stored(done)
        assert sorted(handed) == sorted(parent)
        if workers == 1:
            assert handed == list(parent)


def test_queue_resumes_from_a_partly_stored_grid():
    parent = search_tree((3, 3, 4), (0, 0, 1), "columns")
    rank = {idx: k for k, idx in enumerate(parent)}
    stored = set(list(parent)[:10])
    pending = set(parent) - stored
    queue = ReadyQueue(parent, rank, stored, pending)
    first = queue.pop()
    assert parent[first] in stored and first == min(
        (i for i in pending if parent[i] in stored), key=rank.__getitem__
    )


def test_positions_cache_keeps_recent_points_within_budget():
    one = np.arange(12.0).reshape(4, 3)
    cache = PositionsCache(budget_bytes=3 * one.nbytes)
    for k in range(5):
        cache.put((k, 0, 0), one + k)
    assert cache.get((0, 0, 0)) is None and cache.get((1, 0, 0)) is None  # evicted, oldest first
    got = cache.get((4, 0, 0))
    assert np.array_equal(got, one + 4)
    got[0, 0] = -1.0  # a copy: the cached array is not changed by the caller
    assert np.array_equal(cache.get((4, 0, 0)), one + 4)
    cache.get((2, 0, 0))  # used now: the next eviction takes (3, 0, 0)
    cache.put((5, 0, 0), one + 5)
    assert cache.get((3, 0, 0)) is None and cache.get((2, 0, 0)) is not None
    big = PositionsCache(budget_bytes=8)
    big.put((0, 0, 0), one)  # larger than the budget: not kept
    assert big.get((0, 0, 0)) is None
