"""The order of grid points and which finished neighbour each one starts from.

The grid graph joins each point to its lateral neighbours (periodic in shift_a and
shift_b: the last shift is next to the first) and to its neighbours in thickness
(not periodic). A breadth-first search from a root gives every point a *parent*, a
neighbour one step closer to the root; a point is relaxed starting from its parent's
relaxed structure (a warm start) and can run as soon as its parent is finished, so the
search tree is also the dependency graph of the scan. The tree is a pure function of
the grid shape, the root and the preference, so every executor and every resumed run
starts each point from the same neighbour and gives the same numbers.

Preferences
-----------
``"columns"`` (default): the root's thickness plane is spread first, then every
lateral point's column is walked along z, so almost every parent is a thickness
neighbour at the same stacking (the cheaper warm start, measured in
``benchmarks/bench_scan.py``), and a parent-grandparent pair in one column allows a
linear extrapolation in z.
``"planes"``: the root's column is walked first, then each thickness plane is spread
laterally (parents are lateral neighbours, except along the root column).
``"cold"``: no parents; every point starts from the reference structure.
"""

from __future__ import annotations

from collections import deque
from typing import Literal

import numpy as np

Index = tuple[int, int, int]
Preference = Literal["columns", "planes", "cold"]
PREFERENCES = ("columns", "planes", "cold")


def neighbours(
    index: Index, shape: tuple[int, int, int], prefer: Preference = "columns"
) -> list[Index]:
    """Grid neighbours of ``index`` (periodic laterally), in the preferred order, without repeats."""
    ia, ib, iz = index
    na, nb, nz = shape
    lateral = [
        ((ia - 1) % na, ib, iz),
        ((ia + 1) % na, ib, iz),
        (ia, (ib - 1) % nb, iz),
        (ia, (ib + 1) % nb, iz),
    ]
    normal = [(ia, ib, k) for k in (iz - 1, iz + 1) if 0 <= k < nz]
    ordered = normal + lateral if prefer == "planes" else lateral + normal
    return [n for n in dict.fromkeys(ordered) if n != index]


def search_tree(
    shape: tuple[int, int, int],
    root: Index,
    prefer: Preference = "columns",
    allowed: set[Index] | None = None,
) -> dict[Index, Index | None]:
    """Parent of every grid point in a breadth-first search from ``root`` (``None`` for roots).

    The returned dict is in visiting order. With ``prefer="cold"`` every point is a root.
    ``allowed`` (the points a symmetry-reduced scan computes, :mod:`.shift_symmetry`)
    restricts the tree to those points: the search walks only through them, and an allowed
    point it cannot reach becomes a further root (a cold start), searched from in turn.
    """
    na, nb, nz = shape
    if prefer not in PREFERENCES:
        raise ValueError(f"order: expected one of {PREFERENCES}, got {prefer!r}")
    every = [(a, b, z) for z in range(nz) for a in range(na) for b in range(nb)]
    if allowed is not None:
        every = [idx for idx in every if idx in allowed]
    if prefer == "cold":
        return dict.fromkeys(every)
    parent: dict[Index, Index | None] = {}
    for start in [root, *every]:
        if start in parent or (allowed is not None and start not in allowed):
            continue
        parent[start] = None
        queue = deque([start])
        while queue:
            node = queue.popleft()
            for nxt in neighbours(node, shape, prefer):
                if nxt not in parent and (allowed is None or nxt in allowed):
                    parent[nxt] = node
                    queue.append(nxt)
    return parent


def depth(parent: dict[Index, Index | None]) -> int:
    """Length of the longest chain of warm starts (the critical path in points)."""
    level: dict[Index, int] = {}
    for node, par in parent.items():  # visiting order: parents come first
        level[node] = 0 if par is None else level[par] + 1
    return max(level.values()) + 1


def tree_in_store_order(
    z: np.ndarray, shape: tuple, root: tuple, order: str, allowed: set | None = None
) -> dict:
    """The warm-start tree (:func:`search_tree`) over the thicknesses ``z`` in ascending
    order, in the store's indices (``root``, ``allowed`` and the result): ``i_z`` is the
    position in the resolved list, which a thickness added below the smallest after the
    scan (:func:`flatcontact.ispes.scan_extend.extend_grid`) joins at its end. For an
    ascending list (every scan before such an addition) this is the tree itself."""
    rank = np.argsort(z, kind="stable")  # sorted position -> store index
    if np.array_equal(rank, np.arange(z.size)):
        return search_tree(shape, root, order, allowed=allowed)
    position = np.empty_like(rank)
    position[rank] = np.arange(z.size)  # store index -> sorted position

    def to_sorted(idx):
        return (idx[0], idx[1], int(position[idx[2]]))

    def to_store(idx):
        return None if idx is None else (idx[0], idx[1], int(rank[idx[2]]))

    sorted_allowed = None if allowed is None else {to_sorted(i) for i in allowed}
    tree = search_tree(shape, to_sorted(root), order, allowed=sorted_allowed)
    return {to_store(idx): to_store(par) for idx, par in tree.items()}
