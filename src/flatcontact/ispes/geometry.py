"""Geometry of a scan point: where slab 2 goes and how a warm start is carried over.

The interface contract (``interface.extxyz``) is implemented by
:mod:`flatcontact.structures.interface_contract` (``fixed_mask``, ``thickness``) and
:mod:`flatcontact.structures.placement` (``place_slab2``). This module re-exports those
three functions and adds what only the scan needs: the fractional lateral displacement between two grid points with the
periodic minimum image, and the transfer of a relaxed neighbour's free-atom positions
to a new point (:func:`warm_start_positions`).

Conventions
-----------
Shifts ``(shift_a, shift_b)`` are fractions of the in-plane primitive vectors
``a1``, ``a2``; slab 2 is displaced laterally by ``shift_a * a1 + shift_b * a2``
relative to the reference interface. The thickness ``z`` (Å) is the distance between
the mean planes of the held layers of slab 1 and slab 2 (surfaces 1 and 4 by default: the
paper's z, Fig. 1; the interlayer distance of a bilayer of held monolayers). ``fixed_mask``
is the contract's ``arrays["held"]`` (default surfaces 1 and 4): whole layers, each a rigid
body placed by ``place_slab2``.
"""

from __future__ import annotations

import numpy as np
from ase import Atoms

from flatcontact.structures.interface_contract import (
    fixed_mask,
    in_plane_vectors,
    thickness,
    validate_interface,
)
from flatcontact.structures.placement import place_slab2

__all__ = [
    "fixed_mask",
    "in_plane_vectors",
    "lateral_displacement",
    "place_slab2",
    "thickness",
    "validate_interface",
    "warm_start_positions",
]


def lateral_displacement(
    shift_from: tuple[float, float], shift_to: tuple[float, float], a1: np.ndarray, a2: np.ndarray
) -> np.ndarray:
    """Cartesian in-plane displacement (Å, 3-vector with z = 0) from one shift to another.

    The fractional difference is taken with the periodic minimum image (each
    component in [-1/2, 1/2)), so neighbours across the cell boundary are one grid
    step apart, not a whole cell.
    """
    d = np.asarray(shift_to, dtype=float) - np.asarray(shift_from, dtype=float)
    d = d - np.floor(d + 0.5)
    out = np.zeros(3)
    out[:2] = d[0] * np.asarray(a1)[:2] + d[1] * np.asarray(a2)[:2]
    return out


def warm_start_positions(
    placed: Atoms,
    neighbour_positions: np.ndarray,
    shift_neighbour: tuple[float, float],
    shift_new: tuple[float, float],
    thickness_neighbour: float,
    thickness_new: float,
    fixed: np.ndarray,
) -> np.ndarray:
    """Start positions for a new point from the relaxed positions of a neighbouring point.

    Slab 2's atoms of the neighbour are translated rigidly by the lateral
    displacement (minimum image) and by ``thickness_new - thickness_neighbour``
    along z; slab 1's atoms are kept. The fixed atoms are then set exactly to
    their positions in ``placed`` (the new point built from the reference by
    :func:`place_slab2`), so the constraint of a point never depends on the path
    that led to it, only the initial guess of the free atoms does.

    Parameters
    ----------
    placed
        The new point as built by ``place_slab2(reference, shift_new, thickness_new)``.
    neighbour_positions
        Relaxed Cartesian positions (Å) of the neighbour, same atom order.
    shift_neighbour, shift_new
        Fractional shifts ``(shift_a, shift_b)`` of the two points.
    thickness_neighbour, thickness_new
        Thicknesses z (Å) of the two points.
    fixed
        Boolean mask of the held atoms (``fixed_mask``: ``arrays["held"]``, default surfaces 1
        and 4).
    """
    a1, a2 = in_plane_vectors(placed)
    d = lateral_displacement(shift_neighbour, shift_new, a1, a2)
    d[2] = thickness_new - thickness_neighbour
    pos = np.array(neighbour_positions, dtype=float, copy=True)
    slab2 = np.asarray(placed.arrays["slab"]) == 2
    pos[slab2] += d
    pos[fixed] = placed.positions[fixed]
    return pos


def extrapolated_positions(
    placed: Atoms,
    parent: tuple[float, np.ndarray],
    grandparent: tuple[float, np.ndarray],
    thickness_angstrom: float,
    fixed: np.ndarray,
) -> np.ndarray:
    """Linear extrapolation in z of two relaxed points of the same column.

    x_start = x1 + (z - z1)/(z1 - z0) (x1 - x0), with ``parent`` = (z1, x1) and
    ``grandparent`` = (z0, x0) the thicknesses (Å) and relaxed positions of two points at
    the same lateral shift; the difference is taken with the lateral minimum image of
    ``placed``'s cell. The ``fixed`` atoms are then placed exactly as in ``placed``.
    """
    z1, x1 = float(parent[0]), np.asarray(parent[1], dtype=float)
    z0, x0 = float(grandparent[0]), np.asarray(grandparent[1], dtype=float)
    d = x1 - x0
    cell = placed.cell.array
    frac = np.linalg.solve(cell.T, d.T).T
    frac[:, :2] -= np.round(frac[:, :2])
    d = frac @ cell
    pos = x1 + (thickness_angstrom - z1) / (z1 - z0) * d
    pos[fixed] = placed.positions[fixed]
    return pos
