"""Stand-in for :mod:`flatcontact.structures.interface` until that module lands.

Implements the three functions of the shared interface API (``fixed_mask``,
``thickness``, ``place_slab2``) exactly as specified there; it is only imported when
``flatcontact.structures.interface`` does not exist.
"""

from __future__ import annotations

import numpy as np
from ase import Atoms
from ase.geometry import get_distances

from flatcontact.errors import InputError

MIN_INTERFACIAL_GAP_ANGSTROM = 1.0


def fixed_mask(atoms: Atoms) -> np.ndarray:
    """Atoms held fixed during a scan: surfaces 1 and 4."""
    return np.isin(np.asarray(atoms.arrays["surface"]), (1, 4))


def thickness(atoms: Atoms) -> float:
    """Mean z of surface-4 atoms minus mean z of surface-1 atoms (Å)."""
    s = np.asarray(atoms.arrays["surface"])
    z = atoms.positions[:, 2]
    return float(z[s == 4].mean() - z[s == 1].mean())


def place_slab2(
    reference: Atoms, shift_a: float, shift_b: float, thickness_angstrom: float
) -> Atoms:
    """Copy of ``reference`` with slab 2 shifted laterally (fractions) and to thickness z."""
    atoms = reference.copy()
    slab2 = np.asarray(atoms.arrays["slab"]) == 2
    cell = atoms.cell.array
    d = shift_a * cell[0] + shift_b * cell[1]
    d[2] = float(thickness_angstrom) - thickness(reference)
    pos = atoms.positions
    pos[slab2] += d
    atoms.positions = pos
    pbc = atoms.pbc.copy()
    atoms.pbc = [True, True, False]
    atoms.wrap()
    atoms.pbc = pbc
    _, dist = get_distances(
        atoms.positions[~slab2], atoms.positions[slab2], cell=atoms.cell, pbc=[True, True, False]
    )
    if dist.min() < MIN_INTERFACIAL_GAP_ANGSTROM:
        raise InputError(
            f"thickness {thickness_angstrom:.4g} Å overlaps the slabs (closest inter-slab distance "
            f"{dist.min():.3g} Å < {MIN_INTERFACIAL_GAP_ANGSTROM} Å)"
        )
    return atoms
