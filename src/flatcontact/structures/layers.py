"""Physical layers of a slab, found from the structure (not from a depth in Å).

Two rules, one per kind of material:

- **2D sheets** (graphene, h-BN, MoS₂, ...): a layer is a connected component of the
  bond graph, bonds being pairs closer than 1.2 × the sum of the covalent radii
  (:func:`flatcontact.structures.topology.bond_radii`) with the lateral periodic images
  included. An S–Mo–S sheet is one layer; sheets 3 Å apart (van der Waals gap) are
  separate layers.
- **3D crystals** (metals, oxides): a layer is one bulk repeat along the surface
  normal: the atoms with height in ``[z0 + k·d, z0 + (k+1)·d)``, where ``d`` is the
  repeat of the oriented bulk along z and ``z0`` the cut (a height between two atomic
  planes). One fcc(111) layer is one close-packed plane; one rock-salt (111) layer is
  the cation plane plus the anion plane above it.

Layers are numbered from the bottom, starting at 1.
"""

from __future__ import annotations

from itertools import pairwise

import numpy as np
from ase import Atoms
from ase.neighborlist import neighbor_list
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from flatcontact.foundation.errors import InputError
from flatcontact.structures.interface_contract import fixed_mask
from flatcontact.structures.topology import BOND_TOLERANCE, bond_radii

#: Atomic heights closer than this (Å) belong to one atomic plane.
PLANE_TOLERANCE_ANGSTROM = 0.3


def bonded_components(atoms: Atoms, tolerance: float = BOND_TOLERANCE) -> np.ndarray:
    """Connected components of the bond graph, lateral images included.

    Bonded: closer than ``tolerance`` × the sum of the two covalent radii
    (:func:`~flatcontact.structures.topology.bond_radii`). Returns one integer label per
    atom (0, 1, ...; order of ASE's labelling).
    """
    i, j = neighbor_list("ij", atoms, bond_radii(atoms, tolerance))
    n = len(atoms)
    graph = coo_matrix((np.ones(i.size), (i, j)), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    return labels


def _numbered_by_height(atoms: Atoms, labels: np.ndarray) -> np.ndarray:
    """Relabel groups 1..L by increasing mean height."""
    z = atoms.positions[:, 2]
    groups = np.unique(labels)
    order = np.argsort([z[labels == g].mean() for g in groups], kind="stable")
    out = np.empty(len(atoms), dtype=int)
    for rank, g in enumerate(groups[order], start=1):
        out[labels == g] = rank
    return out


def sheet_layers(atoms: Atoms, source: str = "slab") -> np.ndarray:
    """Layer index (1..L from the bottom) of each atom of a stack of 2D sheets.

    A layer is a bonded component (see the module docstring). Raises InputError if
    two components overlap in height (then they are not a stack of sheets, e.g. a
    molecule intercalated in a sheet), naming ``source``.
    """
    layers = _numbered_by_height(atoms, bonded_components(atoms))
    z = atoms.positions[:, 2]
    spans = [(z[layers == k].min(), z[layers == k].max()) for k in range(1, layers.max() + 1)]
    for (lo1, hi1), (lo2, hi2) in pairwise(spans):
        if lo2 <= hi1:
            raise InputError(
                f"{source}: bonded components overlap in height ({lo1:.2f}-{hi1:.2f} and "
                f"{lo2:.2f}-{hi2:.2f} Å); expected separate 2D sheets stacked along z"
            )
    return layers


def atomic_planes(z: np.ndarray, tol_angstrom: float = PLANE_TOLERANCE_ANGSTROM) -> np.ndarray:
    """Plane index (0..P-1 from the bottom) of each height: consecutive sorted heights closer than ``tol``."""
    order = np.argsort(z, kind="stable")
    gaps = np.diff(z[order]) > tol_angstrom
    plane_sorted = np.concatenate([[0], np.cumsum(gaps)])
    planes = np.empty(z.size, dtype=int)
    planes[order] = plane_sorted
    return planes


def repeat_layers(atoms: Atoms, repeat_angstrom: float, z_cut_angstrom: float) -> np.ndarray:
    """Layer index (1..L) of each atom of a 3D-crystal slab: one bulk repeat ``d`` per layer.

    Layer k holds the atoms with ``z_cut + (k-1)·d <= z < z_cut + k·d`` (heights in the
    slab's own frame; ``z_cut`` is the height of the cut below the lowest atom).
    """
    if not repeat_angstrom > 0:
        raise InputError(f"bulk repeat along the normal must be > 0 Å, got {repeat_angstrom}")
    z = atoms.positions[:, 2]
    k = np.floor((z - z_cut_angstrom) / repeat_angstrom + 1e-6).astype(int)
    return _numbered_by_height(atoms, k)


def chunk_layers(atoms: Atoms, face_atoms: int, atoms_per_layer: int) -> np.ndarray:
    """Layers of a slab by atom counts in height order (the α-quartz convention).

    The ``face_atoms`` lowest atoms are layer 1, the ``face_atoms`` highest the last
    layer, and the atoms between are cut in height order into groups of
    ``atoms_per_layer`` (an O–Si–O unit of the 1×1 quartz (0001) cell is 3 atoms; the
    dense face layer is two units, 6 atoms).
    """
    n = len(atoms)
    inner = n - 2 * face_atoms
    if face_atoms < 1 or inner < 0 or inner % atoms_per_layer:
        raise InputError(
            f"{n}-atom slab: cannot split into two {face_atoms}-atom faces and "
            f"{atoms_per_layer}-atom inner layers"
        )
    order = np.argsort(atoms.positions[:, 2], kind="stable")
    sizes = [face_atoms] + [atoms_per_layer] * (inner // atoms_per_layer) + [face_atoms]
    layers = np.empty(n, dtype=int)
    layers[order] = np.repeat(np.arange(1, len(sizes) + 1), sizes)
    return layers


def interface_layers(atoms: Atoms) -> np.ndarray:
    """Layer ids for an interface file that has none (``arrays["layer"]`` missing).

    Per slab, bottom to top: the held atoms of each face form one layer; the other
    atoms are 2D sheets (bonded components not overlapping in height) when there are
    several, else atomic planes (heights within :data:`PLANE_TOLERANCE_ANGSTROM`).
    """
    slab = np.asarray(atoms.arrays["slab"])
    held = fixed_mask(atoms)
    z = atoms.positions[:, 2]
    out = np.zeros(len(atoms), dtype=int)
    offset = 0
    for which in (1, 2):
        idx = np.flatnonzero(slab == which)
        labels = np.zeros(idx.size, dtype=int)
        part_held = held[idx]
        zmid = z[idx].mean()
        labels[part_held & (z[idx] <= zmid)] = -1
        labels[part_held & (z[idx] > zmid)] = -2
        if part_held.all():  # a held monolayer: one layer
            labels[:] = -1
        free = np.flatnonzero(~part_held)
        if free.size:
            sub = atoms[idx[free]]
            try:
                inner = sheet_layers(sub) if bonded_components(sub).max() > 0 else None
            except InputError:
                inner = None
            if inner is None:
                inner = atomic_planes(sub.positions[:, 2]) + 1
            labels[free] = inner
        numbered = _numbered_by_height(atoms[idx], labels)
        out[idx] = numbered + offset
        offset += int(numbered.max())
    return out


def slab_layers(atoms: Atoms, source: str = "slab") -> tuple[np.ndarray, str]:
    """Layers (1..L from the bottom) of a slab of unknown kind, and the rule used.

    Separate bonded pieces stacked along z → one layer per piece (``"bonded sheets"``);
    otherwise one layer per atomic plane (``"atomic planes"``, heights within
    :data:`PLANE_TOLERANCE_ANGSTROM`).
    """
    if bonded_components(atoms).max() > 0:
        try:
            return sheet_layers(atoms, source), "bonded sheets"
        except InputError:
            pass
    return atomic_planes(atoms.positions[:, 2]) + 1, "atomic planes"
