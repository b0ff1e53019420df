"""The symmetry the ISPES must have because the two slabs have it, and how far a landscape
keeps each such operation.

Slab 2 displaced by ``s`` (Å, in-plane) over slab 1 is the configuration
``C(s) = B ∪ (T + s)``. Let ``R`` be a point operation of the in-plane lattice (rotation
about z or vertical mirror, z unchanged) that maps each slab onto itself up to an in-plane
translation: ``R B + t_B ≡ B`` and ``R T + t_T ≡ T`` (modulo the lattice, same species,
same heights). Applying ``R`` and translating by ``t_B`` turns ``C(s)`` into
``C(R s + t_B − t_T)``, so an energy that depends only on the configuration obeys

.. math:: E(s) = E(R\\,s + t_B - t_T)

for every ``s``: a **shift-space operation** of the structure (:func:`shift_operations`).
The relaxation at each point does not change this (the relaxed minimum of an equivalent
configuration is equivalent), unless the relaxation found different minima at equivalent
points (e.g. planes of a slab slipping at some points and not at others).

:func:`operation_deviation` measures ``‖e∘T − e‖/‖e − ē‖`` over the cell exactly from the
Fourier coefficients of the interpolant (Parseval; the construction of
:func:`flatcontact.analysis.stackings.kept_operations`): 0 keeps the operation, 1.41 is an
uncorrelated landscape.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flatcontact.analysis.periodic import PeriodicSurface
from flatcontact.analysis.symmetry import lattice_point_operations

#: Atoms match under an operation when they land within this distance (Å) of an atom of
#: the same species (in-plane minimum image, and in height).
POSITION_TOLERANCE_ANGSTROM = 0.05


@dataclass(frozen=True)
class ShiftOperation:
    """``s -> R s + t`` of shift space (Å), with the lattice form ``R L = L M``."""

    name: str  #: e.g. "C3 (rotation 120°)", "mirror at 30°"
    matrix: np.ndarray  #: Cartesian 2×2 R
    integer_matrix: np.ndarray  #: M
    translation_angstrom: np.ndarray  #: t = t_B − t_T


def _name(r: np.ndarray) -> str:
    if np.linalg.det(r) > 0:
        angle = float(np.degrees(np.arctan2(r[1, 0], r[0, 0]))) % 360
        return f"rotation by {angle:.0f}°"
    line = float(np.degrees(0.5 * np.arctan2(r[1, 0], r[0, 0]))) % 180
    return f"mirror at {line:.0f}°"


def _self_translation(
    xy: np.ndarray,
    z: np.ndarray,
    numbers: np.ndarray,
    r: np.ndarray,
    lattice: np.ndarray,
    tol: float,
) -> np.ndarray | None:
    """A translation t with ``R X + t ≡ X`` (module docstring), or None."""
    inv = np.linalg.inv(lattice)
    moved = xy @ r.T
    candidates = np.flatnonzero((numbers == numbers[0]) & (np.abs(z - z[0]) < tol))
    for j in candidates:
        t = xy[j] - moved[0]
        image = moved + t
        d = (image[:, None, :] - xy[None, :, :]) @ inv.T
        d -= np.round(d)
        dist = np.linalg.norm(d @ lattice.T, axis=-1)
        same = (numbers[:, None] == numbers[None, :]) & (np.abs(z[:, None] - z[None, :]) < tol)
        dist = np.where(same, dist, np.inf)
        if np.all(dist.min(axis=1) < tol):
            return t
    return None


def shift_operations(
    positions: np.ndarray,
    numbers: np.ndarray,
    slab: np.ndarray,
    a1: np.ndarray,
    a2: np.ndarray,
    tolerance_angstrom: float = POSITION_TOLERANCE_ANGSTROM,
) -> list[ShiftOperation]:
    """The shift-space operations of an interface (module docstring), identity excluded.

    Parameters
    ----------
    positions
        Cartesian positions (Å), shape (N, 3), of the reference interface.
    numbers
        Atomic numbers, shape (N,).
    slab
        1 or 2 per atom (``arrays["slab"]`` of the interface contract).
    a1, a2
        In-plane cell vectors (Å).
    tolerance_angstrom
        Largest distance between an atom's image and an atom of the same species.
    """
    pos = np.asarray(positions, float)
    numbers = np.asarray(numbers)
    slab = np.asarray(slab)
    lattice = np.column_stack([np.asarray(a1, float)[:2], np.asarray(a2, float)[:2]])
    ops = []
    for r, m in lattice_point_operations(a1, a2):
        shifts = []
        for s in (1, 2):
            sel = slab == s
            t = _self_translation(
                pos[sel, :2], pos[sel, 2], numbers[sel], r, lattice, tolerance_angstrom
            )
            if t is None:
                break
            shifts.append(t)
        if len(shifts) == 2:
            ops.append(ShiftOperation(_name(r), r, np.rint(m).astype(int), shifts[0] - shifts[1]))
    return ops


def operation_deviation(surface: PeriodicSurface, op: ShiftOperation) -> float:
    """Relative L2 deviation ``‖e∘T − e‖/‖e − ē‖`` of ``surface`` under ``op`` (exact for
    the band-limited interpolant; a coefficient mapped outside its index set counts as a
    mismatch). 0 for a flat landscape."""
    c = surface.coefficients.ravel()
    kk, ll = np.meshgrid(surface.k, surface.l, indexing="ij")
    idx = np.stack([kk.ravel(), ll.ravel()], -1).astype(int)
    position = {(int(a), int(b)): q for q, (a, b) in enumerate(idx)}
    mean = np.all(idx == 0, axis=1)
    norm2 = float(np.sum(np.abs(c[~mean]) ** 2))
    if norm2 <= 0:
        return 0.0
    target = np.array([position.get(tuple(int(v) for v in g @ op.integer_matrix), -1) for g in idx])
    inside = target >= 0
    s_t = surface.fractional(np.asarray(op.translation_angstrom, float))
    moved = np.zeros_like(c)
    moved[target[inside]] = c[inside] * np.exp(2j * np.pi * (idx[inside] @ s_t))
    lost = float(np.sum(np.abs(c[~inside & ~mean]) ** 2))
    diff2 = float(np.sum(np.abs(moved - c)[~mean] ** 2))
    return float(np.sqrt((diff2 + lost) / norm2))
