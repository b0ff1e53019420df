"""Bonds, coordination, ring and flatness analysis of any periodic (or slab) structure.

Two bond rules (ASE neighbour lists, periodic images included):

- **Any structure** (:func:`bond_radii`, used to tell bonded pieces apart): atoms i and j
  are bonded when ``d_ij < BOND_TOLERANCE · (r_i + r_j)``, with ``r`` the covalent radii of
  ``ase.data.covalent_radii`` (Cordero et al., Dalton Trans. 2832 (2008)) and
  :data:`BOND_TOLERANCE` = 1.2. The tabulated radii are single-bond averages with a spread
  of ~0.05–0.1 Å, and real bonds are longer: diamond's C–C 1.545 Å against 2·0.76 = 1.52 Å,
  C–H 1.09 Å against 1.07 Å, Au–Au 2.88 Å against 2.72 Å; 20 % covers them (the
  tolerance of pymatgen's ``CovalentBond``) and stays below every non-bonded contact
  of the structures the tool builds: graphite's interlayer 3.35 Å (cut-off 1.82 Å),
  diamond's second neighbours 2.52 Å, quartz's Si–Si 3.06 Å (2.66 Å) and O–O 2.61 Å
  (1.58 Å), MoS₂'s interlayer S–S 3.5 Å (2.52 Å).
- **Silica** (coordination and rings): a Si–O bond for d < 2.0 Å (the first-shell minimum
  of g_SiO lies at ~2.0–2.2 Å; bulk Si–O = 1.61 Å, second neighbours Si–Si 3.06 Å, O–O
  2.61 Å), and no Si–Si or O–O bonds.

Rings: the smallest ring through an atom is the shortest cycle of the bond graph
through it, found by breadth-first search on the *unwrapped* periodic graph (nodes are
(atom, lattice image)), so a chain that merely closes on its own periodic image is
not a ring. For an alternating T–O network (silica), the ring size "in Si atoms" is
half the number of bonds in the cycle (bulk α-quartz: 6-membered rings).
"""

from __future__ import annotations

from collections import deque

import numpy as np
from ase import Atoms
from ase.data import covalent_radii
from ase.neighborlist import neighbor_list

#: Bond tolerance: bonded when closer than this times the sum of the two covalent radii.
BOND_TOLERANCE = 1.2
#: Si–O bond cutoff (Å) used for coordination and rings in silica.
SI_O_CUTOFF_ANGSTROM = 2.0
SILICA_CUTOFFS = {("Si", "O"): SI_O_CUTOFF_ANGSTROM}
#: Expected coordination in a defect-free silica network.
SILICA_COORDINATION = {"Si": 4, "O": 2}


def bond_radii(atoms: Atoms, tolerance: float = BOND_TOLERANCE) -> list[float]:
    """Per-atom bond radii (Å): ``tolerance`` × covalent radius (see the module docstring).

    As ASE's ``neighbor_list`` cutoffs, atoms i and j are bonded when
    ``d_ij < radii[i] + radii[j]``.
    """
    return (tolerance * covalent_radii[atoms.numbers]).tolist()


def bonds(atoms: Atoms, cutoffs: dict[tuple[str, str], float] = SILICA_CUTOFFS):
    """Directed bond list (i, j, image shift S) with r_j + S·cell − r_i shorter than the pair cutoff."""
    return neighbor_list("ijS", atoms, dict(cutoffs))


def coordination(
    atoms: Atoms, cutoffs: dict[tuple[str, str], float] = SILICA_CUTOFFS
) -> np.ndarray:
    """Number of bonded neighbours of each atom."""
    i, _, _ = bonds(atoms, cutoffs)
    return np.bincount(i, minlength=len(atoms))


def coordination_defects(
    atoms: Atoms,
    expected: dict[str, int] = SILICA_COORDINATION,
    cutoffs: dict[tuple[str, str], float] = SILICA_CUTOFFS,
) -> list[dict]:
    """Atoms whose coordination differs from ``expected[symbol]``: [{index, symbol, cn, expected}]."""
    cn = coordination(atoms, cutoffs)
    out = []
    for k, (sym, c) in enumerate(zip(atoms.get_chemical_symbols(), cn.tolist(), strict=True)):
        if sym in expected and c != expected[sym]:
            out.append({"index": k, "symbol": sym, "cn": c, "expected": expected[sym]})
    return out


def smallest_ring(
    atoms: Atoms,
    index: int,
    cutoffs: dict[tuple[str, str], float] = SILICA_CUTOFFS,
    max_bonds: int = 16,
    within: np.ndarray | None = None,
    _bonds=None,
) -> int | None:
    """Number of bonds in the shortest cycle through atom ``index`` (None if none ≤ ``max_bonds``).

    ``within``: optional boolean mask restricting the graph to a subset of atoms (e.g. one
    surface layer, for in-plane rings).
    """
    i, j, S = _bonds if _bonds is not None else bonds(atoms, cutoffs)
    if within is not None:
        keep = within[i] & within[j]
        i, j, S = i[keep], j[keep], S[keep]
    adjacency: dict[int, list[tuple[int, tuple[int, int, int]]]] = {}
    for a, b, s in zip(i.tolist(), j.tolist(), S.tolist(), strict=True):
        adjacency.setdefault(a, []).append((b, tuple(s)))
    root = (index, (0, 0, 0))
    dist = {root: 0}
    branch = {root: -1}
    queue = deque()
    for k, (b, s) in enumerate(adjacency.get(index, [])):
        node = (b, s)
        if node in dist:  # two bonds to the same image: a 2-cycle, not chemistry; skip
            continue
        dist[node] = 1
        branch[node] = k
        queue.append(node)
    best = None
    while queue:
        node = queue.popleft()
        d = dist[node]
        if best is not None and 2 * d + 1 > best + 1:
            break
        atom, shift = node
        for b, s in adjacency.get(atom, []):
            nxt = (b, (shift[0] + s[0], shift[1] + s[1], shift[2] + s[2]))
            if nxt == root:
                continue
            if nxt not in dist:
                if d + 1 <= max_bonds // 2 + 1:
                    dist[nxt] = d + 1
                    branch[nxt] = branch[node]
                    queue.append(nxt)
            elif branch[nxt] != branch[node] and branch[nxt] >= 0:
                length = d + dist[nxt] + 1
                if length <= max_bonds and (best is None or length < best):
                    best = length
    return best


def ring_sizes(
    atoms: Atoms,
    indices,
    cutoffs: dict[tuple[str, str], float] = SILICA_CUTOFFS,
    max_bonds: int = 16,
    within: np.ndarray | None = None,
) -> list[int | None]:
    """:func:`smallest_ring` for each of ``indices`` (bonds per ring; halve for Si count in silica)."""
    b = bonds(atoms, cutoffs)
    return [smallest_ring(atoms, int(k), cutoffs, max_bonds, within, _bonds=b) for k in indices]


def height_spread(atoms: Atoms, mask: np.ndarray) -> float:
    """Peak-to-peak spread of the z coordinates of the atoms in ``mask`` (Å)."""
    z = atoms.positions[np.asarray(mask), 2]
    return float(np.ptp(z)) if z.size else 0.0
