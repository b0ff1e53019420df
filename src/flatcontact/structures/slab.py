"""Cutting slabs from a bulk crystal whose third cell vector is along the surface normal z.

A slab of ``layers`` layers is the set of atoms of the z-repeated bulk with
z_cut ≤ z < z_cut + layers·layer_height. For α-quartz (0001) one layer is one
O–Si–O unit (1 Si + 2 O per 1×1 cell) of height c/3: the 3₂ screw axis makes the
set of atomic heights c/3-periodic, so every window of length layers·c/3 is
stoichiometric, and the distinct cleavage planes are the gaps between
consecutive atomic heights within one c/3 period (three for quartz).
"""

from __future__ import annotations

import numpy as np
from ase import Atoms

from flatcontact.foundation.errors import InputError, require
from flatcontact.structures.bulk import QUARTZ_A_ANGSTROM, QUARTZ_C_ANGSTROM, alpha_quartz

#: Heights closer than this (Å) count as one atomic plane when listing cleavage planes.
PLANE_TOLERANCE_ANGSTROM = 0.05


def cleavage_heights(bulk: Atoms, layer_height_angstrom: float) -> np.ndarray:
    """Distinct cleavage heights (Å) within one layer period: mid-points of the gaps between planes.

    Sorted by decreasing gap width (the widest gap first, i.e. the cut that
    breaks the longest bonds first), ties by height. Deterministic.
    """
    require(
        layer_height_angstrom > 0, f"layer_height_angstrom must be > 0, got {layer_height_angstrom}"
    )
    z = np.mod(bulk.positions[:, 2], layer_height_angstrom)
    z = np.sort(z)
    planes = [z[0]]
    for value in z[1:]:
        if value - planes[-1] > PLANE_TOLERANCE_ANGSTROM:
            planes.append(value)
    planes = np.array(planes)
    if (
        planes.size > 1
        and planes[0] + layer_height_angstrom - planes[-1] <= PLANE_TOLERANCE_ANGSTROM
    ):
        planes = planes[:-1]
    upper = np.append(planes[1:], planes[0] + layer_height_angstrom)
    gaps = upper - planes
    mids = np.mod(planes + 0.5 * gaps, layer_height_angstrom)
    order = np.lexsort((mids, -np.round(gaps, 6)))
    return mids[order]


def cut_slab(
    bulk: Atoms,
    layers: int,
    z_cut_angstrom: float,
    layer_height_angstrom: float,
    vacuum_angstrom: float = 10.0,
) -> Atoms:
    """Slab of ``layers`` layers from ``bulk`` (cell vector 3 along z), starting at height ``z_cut``.

    Returns a slab periodic in x, y (pbc = T, T, F) with ``vacuum_angstrom`` above
    and below, lowest atom at z = vacuum.
    """
    require(
        isinstance(layers, int | np.integer) and layers >= 1,
        f"layers={layers}: expected an integer >= 1",
    )
    cell = bulk.cell.array
    require(
        abs(cell[0, 2]) < 1e-8
        and abs(cell[1, 2]) < 1e-8
        and abs(cell[2, 0]) < 1e-8
        and abs(cell[2, 1]) < 1e-8,
        "bulk cell: vectors 1, 2 must lie in the x-y plane and vector 3 along z",
    )
    c = cell[2, 2]
    total = layers * layer_height_angstrom
    z0 = z_cut_angstrom % c
    reps = int(np.ceil((z0 + total) / c)) + 1
    big = bulk.repeat((1, 1, reps))
    z = big.positions[:, 2]
    eps = 1e-6
    keep = (z >= z0 + eps) & (z < z0 + total + eps)
    slab = big[keep]
    if len(slab) == 0:
        raise InputError(f"cut at z={z_cut_angstrom} Å with {layers} layers selects no atoms")
    slab.positions[:, 2] -= slab.positions[:, 2].min() - vacuum_angstrom
    new_cell = cell.copy()
    new_cell[2] = (0.0, 0.0, float(np.ptp(slab.positions[:, 2])) + 2.0 * vacuum_angstrom)
    slab.set_cell(new_cell, scale_atoms=False)
    slab.pbc = (True, True, False)
    slab.wrap()
    return slab


def quartz_0001_slab(
    layers: int = 6,
    cut: int = 0,
    a_angstrom: float = QUARTZ_A_ANGSTROM,
    c_angstrom: float = QUARTZ_C_ANGSTROM,
    vacuum_angstrom: float = 10.0,
) -> Atoms:
    """Unrelaxed α-quartz (0001) slab in the primitive 1×1 cell, ``layers`` O–Si–O units.

    ``cut`` ∈ {0, 1, 2} picks one of the three distinct cleavage planes in the order
    of :func:`cleavage_heights` (0 = the widest gap). 3·layers atoms, stoichiometric.
    """
    bulk = alpha_quartz(a_angstrom, c_angstrom)
    heights = cleavage_heights(bulk, c_angstrom / 3.0)
    require(
        0 <= cut < len(heights),
        f"cut={cut}: expected 0..{len(heights) - 1} (distinct cleavage planes)",
    )
    return cut_slab(bulk, layers, float(heights[cut]), c_angstrom / 3.0, vacuum_angstrom)
