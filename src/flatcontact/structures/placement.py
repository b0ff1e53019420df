"""Placing slab 2 of a reference interface: the geometry of one scan point.

:func:`place_slab2` moves slab 2 of the reference to a lateral shift (fractions of the
in-plane vectors a1, a2) and a thickness z (Å, :func:`~flatcontact.structures.interface_contract.thickness`);
:func:`interslab_min_distance` is the overlap guard it (and the scan, at every grid point)
applies.
"""

from __future__ import annotations

import numpy as np
from ase import Atoms

from flatcontact.foundation.errors import InputError, require
from flatcontact.structures.interface_contract import (
    DEFAULT_VACUUM_ANGSTROM,
    atoms_content,
    fixed_mask,
    in_plane_vectors,
    per_atom_array,
    set_vertical_cell,
    thickness,
    validate_interface,
)

#: Closest allowed distance (Å) between an atom of slab 1 and one of slab 2 in
#: :func:`place_slab2`; shorter means the slabs overlap (a Si–O bond is 1.6 Å).
MIN_INTERSLAB_DISTANCE_ANGSTROM = 1.0
#: Largest compressive strain −dz/z_ref of the stack between the held layers that
#: :func:`place_slab2` spreads homogeneously when a rigid placement would overlap (10 %: a
#: stack of quartz slabs carries about 5 GPa at 5 %; beyond, the request is a mistake).
MAX_SPREAD_STRAIN = 0.10
#: Most (facing atom of slab 2) × (image of an atom of slab 1) pairs that
#: :func:`interslab_min_distance` compares all at once with numpy; beyond, a k-d tree
#: (``scipy.spatial``, imported only then). A scan's cell is usually far below it (the
#: 36-atom quartz interface: 25 pairs at the scan's 2 Å), and importing scipy.spatial cost
#: every worker process ≈ 0.07 s of CPU at start, more than all its overlap checks.
BRUTE_FORCE_MAX_PAIRS = 200_000


def interslab_min_distance(atoms: Atoms, cutoff_angstrom: float = 4.0) -> float:
    """Closest distance (Å) between an atom of slab 1 and one of slab 2 (lateral PBC).

    Returns ``inf`` if no pair is closer than ``cutoff_angstrom``.

    Only cross pairs are searched (slab 1's atoms within ``cutoff_angstrom`` in z of slab 2
    and their periodic images against the facing atoms of slab 2): the scan runs this for
    every grid point, and a neighbour list of all pairs cost more than a force call on small
    cells. Up to :data:`BRUTE_FORCE_MAX_PAIRS` pairs every distance is computed
    (:func:`_closest_pair_distance`), beyond a k-d tree answers; both give the same number,
    bit for bit (``tests/ispes/test_interslab_distance.py``).
    """
    slab = per_atom_array(atoms, "slab")
    pos = atoms.positions
    p1, p2 = pos[slab == 1], pos[slab != 1]
    if not len(p1) or not len(p2):
        return float("inf")
    p1 = p1[p1[:, 2] >= p2[:, 2].min() - cutoff_angstrom]
    if not len(p1):
        return float("inf")
    p2 = p2[p2[:, 2] <= p1[:, 2].max() + cutoff_angstrom]
    if not len(p2):
        return float("inf")
    cell = atoms.cell.array
    pbc = np.asarray(atoms.pbc, dtype=bool)
    # wrap both into the cell along periodic directions; images of slab 1 covering the cutoff
    frac1, frac2 = np.linalg.solve(cell.T, p1.T).T, np.linalg.solve(cell.T, p2.T).T
    frac1[:, pbc] -= np.floor(frac1[:, pbc])
    frac2[:, pbc] -= np.floor(frac2[:, pbc])
    p1, p2 = frac1 @ cell, frac2 @ cell
    volume = abs(np.linalg.det(cell))
    reach = []
    for k in range(3):
        if not pbc[k]:
            reach.append((0,))
            continue
        height = volume / np.linalg.norm(np.cross(cell[(k + 1) % 3], cell[(k + 2) % 3]))
        n = int(np.ceil(cutoff_angstrom / height)) + 1
        reach.append(tuple(range(-n, n + 1)))
    shifts = np.array([[i, j, k] for i in reach[0] for j in reach[1] for k in reach[2]]) @ cell
    images = (p1[None, :, :] + shifts[:, None, :]).reshape(-1, 3)
    if len(images) * len(p2) <= BRUTE_FORCE_MAX_PAIRS:
        closest = _closest_pair_distance(images, p2)
    else:
        from scipy.spatial import cKDTree

        d, _ = cKDTree(images).query(p2, k=1, distance_upper_bound=cutoff_angstrom)
        closest = float(d.min())
    return closest if closest < cutoff_angstrom else float("inf")


def _closest_pair_distance(points: np.ndarray, queries: np.ndarray) -> float:
    """Smallest Euclidean distance (Å) between a row of ``points`` and one of ``queries``.

    Every pair: the squared distance summed x, y, z in that order (as scipy's k-d tree sums
    it for three dimensions), its minimum, then one square root (monotone, so the root of the
    minimum is the minimum of the roots): the tree's number exactly.
    """
    diff = queries[:, None, :] - points[None, :, :]
    squared = diff[..., 0] * diff[..., 0]
    squared += diff[..., 1] * diff[..., 1]
    squared += diff[..., 2] * diff[..., 2]
    return float(np.sqrt(squared.min()))


#: The per-atom arrays of the interface contract ``validate_interface`` reads.
_CONTRACT_ARRAYS = ("slab", "surface", "held", "layer")
#: :func:`atoms_content` of the last reference found to follow the contract.
_VALID_REFERENCE: list[tuple] = []


def _validate_once(reference: Atoms) -> None:
    """``validate_interface(reference, "reference interface")``, skipped when the last
    reference that passed had the same content (:func:`atoms_content` with the contract's
    arrays): a pure function of that content, so the verdict is the same; a failure is never
    kept, it raises every time."""
    content = atoms_content(reference, _CONTRACT_ARRAYS)
    if content is not None and content in _VALID_REFERENCE:
        return
    validate_interface(reference, "reference interface")
    if content is not None:
        _VALID_REFERENCE[:] = [content]


def place_slab2(
    reference: Atoms,
    shift_a: float,
    shift_b: float,
    thickness_angstrom: float,
    *,
    min_distance_angstrom: float = MIN_INTERSLAB_DISTANCE_ANGSTROM,
    spread_compression: bool = True,
    validate_reference: bool = True,
) -> Atoms:
    """A copy of ``reference`` with slab 2 moved to lateral shift (a, b) and thickness z.

    Slab 2 is translated by shift_a·a1 + shift_b·a2 (fractions of the primitive
    in-plane vectors; atoms wrapped back into the cell) and vertically so that
    ``thickness(result) == thickness_angstrom``. Slab 1 is untouched.

    Held atoms (``fixed_mask``) are always placed rigidly: slab 1's stay, slab 2's move by
    the lateral shift and by dz = z − z(reference). Free atoms are placed rigidly with their
    slab too, unless that would make the slabs overlap under compression (dz < 0) and
    ``spread_compression`` is true: then the compression is spread homogeneously over the
    stack between the held layers (each free atom's height h becomes h₁ + (h − h₁)·z/z_ref,
    h₁ the mean height of slab 1's held atoms; lateral positions as rigid), the
    way a compressed elastic stack shares it. A rigid placement puts the whole compression
    into the interfacial gap, which caps how far a thick (compliant) slab can be loaded;
    the spread start removes that cap. It is only a starting geometry: a relaxed point
    depends on it only through the basin it starts in, and every placement that does not
    overlap rigidly is the rigid one, so scans that ran before are unchanged.

    Parameters
    ----------
    min_distance_angstrom
        Closest allowed inter-slab distance (Å) of the placed structure.
    spread_compression
        Allow the homogeneous spread when the rigid placement overlaps (the scan passes
        false in its ``rigid`` relax mode, where the slabs are never deformed). The spread
        is refused beyond :data:`MAX_SPREAD_STRAIN` compressive strain.
    validate_reference
        Check ``reference`` against the interface contract first (``validate_interface``),
        once per reference content (:func:`_validate_once`: a scan places every point from
        one reference, and the validation was 0.07 of a placement's 0.16 ms on the 36-atom
        quartz cell); false where the caller already did. The same atoms and errors either
        way.

    Raises
    ------
    InputError
        If the shifts or thickness are not finite, or the slabs would overlap (closest
        inter-slab distance below ``min_distance_angstrom``) with the allowed placement.
    """
    if validate_reference:
        _validate_once(reference)
    for name, value in (
        ("shift_a", shift_a),
        ("shift_b", shift_b),
        ("thickness", thickness_angstrom),
    ):
        require(np.isfinite(value), f"{name}={value}: expected a finite number")
    atoms = reference.copy()
    upper = atoms.arrays["slab"] == 2
    a1, a2 = in_plane_vectors(atoms)
    lateral = shift_a * a1 + shift_b * a2
    z_reference = thickness(reference)
    dz = thickness_angstrom - z_reference
    atoms.positions[upper] += np.array([lateral[0], lateral[1], dz])
    atoms.wrap()
    set_vertical_cell(atoms, DEFAULT_VACUUM_ANGSTROM, keep_at_least=reference.cell.array[2, 2])
    closest = _closest_interslab(atoms, min_distance_angstrom)
    if closest < min_distance_angstrom and spread_compression and dz < 0:
        held = fixed_mask(reference)
        free = ~held
        if -dz / z_reference <= MAX_SPREAD_STRAIN and free.any():
            h1 = float(reference.positions[held & ~upper, 2].mean())
            heights = reference.positions[free, 2]
            spread = atoms.copy()
            spread.positions[free, 2] = h1 + (heights - h1) * (thickness_angstrom / z_reference)
            if _closest_interslab(spread, min_distance_angstrom) >= min_distance_angstrom:
                return spread
    if closest < min_distance_angstrom:
        raise InputError(
            f"thickness {thickness_angstrom:.3f} Å at shift ({shift_a:.4g}, {shift_b:.4g}) makes the slabs "
            f"overlap: closest inter-slab distance {closest:.3f} Å < {min_distance_angstrom} Å"
        )
    return atoms


def _closest_interslab(atoms: Atoms, min_distance_angstrom: float) -> float:
    return interslab_min_distance(atoms, cutoff_angstrom=max(2.0 * min_distance_angstrom, 2.0))
