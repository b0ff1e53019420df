"""Tractions, contact width and slip along the contact, binned from per-atom data.

Conventions (lengths Å, forces eV/Å, tractions GPa; 1 eV/Å³ = 160.21766 GPa):

- the contact coordinate of an atom is its distance from the apex in the *flat's* frame:
  the signed y − y_apex across the cylinder's axis, or the in-plane distance r (sphere);
- bins: edges ``edges_angstrom``; a bin's area is (bin width) × (axis length) for the
  cylinder and π (r₁² − r₀²) for the sphere;
- **pressure** p = −(sum of the z force the tip exerts on the flat's atoms in the bin)/area
  (compressive > 0), **shear** q = (sum of the y force on them)/area (along the sliding);
- **contact half-width** a: the largest |coordinate| of a flat atom pushed down by the tip
  with more than ``contact_force_ev_per_angstrom`` (atoms in force contact);
- **slip** of a facing pair: the y displacement of a tip atom minus that of the flat atom it
  faces, since the pressed state (pairs fixed there: each atom of the flat's top plane and
  the tip atom nearest it); binned as the mean over the pairs of a bin;
- **stick half-width** c: the inner edge of the first bin from the centre, inside the
  contact, whose mean |slip| reaches ``slip_threshold_angstrom``; a when none does.
"""

from __future__ import annotations

import numpy as np

EV_PER_A3_GPA = 160.21766208


def contact_coordinate(
    positions_2d: np.ndarray, apex_2d: np.ndarray, cell_2d: np.ndarray, geometry: str
) -> np.ndarray:
    """Signed y − y_apex (cylinder, minimum image along the cell's y period) or the
    minimum-image in-plane distance r from the apex (sphere), Å."""
    pos = np.asarray(positions_2d, float)
    apex = np.asarray(apex_2d, float)
    cell = np.asarray(cell_2d, float)
    if geometry == "cylinder":
        ly = abs(cell[1, 1])
        return (pos[:, 1] - apex[1] + 0.5 * ly) % ly - 0.5 * ly
    best = np.full(len(pos), np.inf)
    for i in (-1, 0, 1):
        for j in (-1, 0, 1):
            d = pos - apex + i * cell[0] + j * cell[1]
            best = np.minimum(best, np.hypot(d[:, 0], d[:, 1]))
    return best


def bin_areas(edges_angstrom: np.ndarray, geometry: str, axis_length_angstrom: float):
    """Area (Å²) of each bin: width × axis length (cylinder) or an annulus (sphere)."""
    e = np.asarray(edges_angstrom, float)
    if geometry == "cylinder":
        return np.diff(e) * axis_length_angstrom
    return np.pi * np.diff(e**2)


def traction_profiles(
    coordinate: np.ndarray,
    cross_force: np.ndarray,
    edges_angstrom: np.ndarray,
    areas_angstrom2: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """(pressure, shear) per bin (GPa) from the force the tip exerts on each flat atom."""
    fz, _ = np.histogram(coordinate, edges_angstrom, weights=cross_force[:, 2])
    fy, _ = np.histogram(coordinate, edges_angstrom, weights=cross_force[:, 1])
    return -fz / areas_angstrom2 * EV_PER_A3_GPA, fy / areas_angstrom2 * EV_PER_A3_GPA


def contact_half_width(
    coordinate: np.ndarray, cross_force_z: np.ndarray, contact_force_ev_per_angstrom: float
) -> float:
    """Largest |coordinate| (Å) of an atom pushed down by more than the threshold; 0 if none."""
    pushed = -np.asarray(cross_force_z) > contact_force_ev_per_angstrom
    return float(np.max(np.abs(coordinate[pushed]))) if np.any(pushed) else 0.0


def facing_pairs(
    flat_top: np.ndarray, tip: np.ndarray, cell_2d: np.ndarray, max_distance_angstrom: float
) -> tuple[np.ndarray, np.ndarray]:
    """(flat index, tip index) pairs: each flat top-plane atom and the tip atom nearest to it
    (minimum image in the plane), kept when nearer than ``max_distance_angstrom``.

    ``flat_top``, ``tip``: positions (n×3, Å) at the pressed state.
    """
    from scipy.spatial import cKDTree

    cell = np.asarray(cell_2d, float)
    images = [i * cell[0] + j * cell[1] for i in (-1, 0, 1) for j in (-1, 0, 1)]
    shifted = np.concatenate([tip + np.array([v[0], v[1], 0.0]) for v in images])
    owner = np.tile(np.arange(len(tip)), len(images))
    dist, idx = cKDTree(shifted).query(flat_top)
    keep = dist < max_distance_angstrom
    return np.flatnonzero(keep), owner[idx[keep]]


def slip(displacement_flat: np.ndarray, displacement_tip: np.ndarray) -> np.ndarray:
    """Relative y displacement (Å) of the facing pairs: tip minus flat (arrays per pair)."""
    return np.asarray(displacement_tip)[:, 1] - np.asarray(displacement_flat)[:, 1]


def binned_mean(coordinate: np.ndarray, values: np.ndarray, edges_angstrom: np.ndarray):
    """Mean of ``values`` per bin (nan for an empty bin)."""
    total, _ = np.histogram(coordinate, edges_angstrom, weights=values)
    count, _ = np.histogram(coordinate, edges_angstrom)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, total / np.maximum(count, 1), np.nan)


def stick_half_width(
    edges_angstrom: np.ndarray,
    slip_per_bin: np.ndarray,
    half_width_angstrom: float,
    slip_threshold_angstrom: float,
) -> float:
    """c (Å): the inner edge (|coordinate|) of the first bin from the centre, inside the
    contact, whose mean |slip| reaches the threshold; ``half_width_angstrom`` when none does.

    A signed coordinate (cylinder) is read on both sides: the nearer slipping bin wins.
    """
    e = np.asarray(edges_angstrom, float)
    inner = np.minimum(np.abs(e[:-1]), np.abs(e[1:]))
    inner = np.where(np.sign(e[:-1]) != np.sign(e[1:]), 0.0, inner)
    inside = inner < half_width_angstrom
    slipping = inside & (np.abs(np.nan_to_num(slip_per_bin)) >= slip_threshold_angstrom)
    return float(np.min(inner[slipping])) if np.any(slipping) else float(half_width_angstrom)
