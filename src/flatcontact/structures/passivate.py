"""Passivated surfaces: hydrogen or hydroxyl on the dangling bonds of a cut crystal.

A dangling bond is a bond of the bulk that the cut broke: in a block of the oriented bulk
that extends at least one bulk repeat beyond both faces of the slab window, atoms i (inside
the window) and j (outside) are bonded when ``d_ij < 1.2 (r_i + r_j)`` (covalent radii,
:func:`flatcontact.structures.topology.bond_radii`), so the missing bonds, their number per
atom and their directions ``u = (r_j − r_i)/|r_j − r_i|`` are the bulk's own first shell
(diamond: one per C of the (111) face along the normal, two per C of (100)).

Species (``passivate``):

``H``   one H per dangling bond, at ``r_i + L(i, H) u``;
``OH``  hydroxyl on oxides: a dangling bond whose missing partner is O gets an O at
        ``r_i + L(i, O) u`` and an H on it at ``L(O, H)``, with the angle i–O–H =
        :data:`HYDROXYL_ANGLE_DEG` in the plane of ``u`` and the x axis (the H leaning
        along +x, away from the surface); a dangling bond whose missing partner is not O
        (a cation) gets an H at ``r_i + L(i, H) u``. Each broken cation–O bond thus gets one
        H₂O (OH on the cation side, H on the O side): the slab stays charge-neutral and its
        stoichiometry is the bulk's + n H₂O. α-quartz: silanol Si–OH and Si–O–H.

Bond lengths ``L`` (Å): :data:`BOND_LENGTH_ANGSTROM` (C–H 1.09, Si–H 1.48, Ge–H 1.53,
O–H 0.96, Si–O 1.63: the molecular values of CH₄/diamond-H, SiH₄/Si-H, H₂O/silanol and a
silanol Si–O), else the sum of the two covalent radii. The added atoms are not relaxed here:
the build relaxes the interface with the run's potential.
"""

from __future__ import annotations

import numpy as np
from ase import Atoms
from ase.data import atomic_numbers, covalent_radii
from ase.neighborlist import neighbor_list

from flatcontact.foundation.errors import InputError
from flatcontact.structures.topology import bond_radii

#: Species a face can be passivated with.
SPECIES = ("H", "OH")
#: Which faces: ``interface`` (the face towards the other slab) or ``both``.
FACES = ("interface", "both")
#: Bond lengths of the added atoms (Å), unordered element pairs.
BOND_LENGTH_ANGSTROM = {
    frozenset(("C", "H")): 1.09,
    frozenset(("Si", "H")): 1.48,
    frozenset(("Ge", "H")): 1.53,
    frozenset(("O", "H")): 0.96,
    frozenset(("Si", "O")): 1.63,
}
#: Angle cation–O–H of an added hydroxyl (deg; silanol Si–O–H ≈ 118°).
HYDROXYL_ANGLE_DEG = 118.0
#: Two atoms closer than this (Å) after passivation: the faces are too crowded (refused).
MIN_DISTANCE_ANGSTROM = 0.9


def bond_length_angstrom(a: str, b: str) -> float:
    """Length (Å) of an added a–b bond: the table, else the sum of the covalent radii."""
    known = BOND_LENGTH_ANGSTROM.get(frozenset((a, b)))
    if known is not None:
        return known
    return float(covalent_radii[atomic_numbers[a]] + covalent_radii[atomic_numbers[b]])


def dangling_bonds(block: Atoms, inside: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Bonds from atoms ``inside`` to atoms outside: (inside index, unit vector, outside index).

    ``block`` is periodic in-plane and extends beyond the window on both sides (module
    docstring); bonds by :func:`~flatcontact.structures.topology.bond_radii`, periodic images
    included. Sorted by inside index, then outside index, then direction (deterministic).
    """
    inside = np.asarray(inside, bool)
    i, j, d = neighbor_list("ijD", block, bond_radii(block))
    cut = inside[i] & ~inside[j]
    i, j, d = i[cut], j[cut], d[cut]
    order = np.lexsort((np.round(d[:, 1], 6), np.round(d[:, 0], 6), j, i))
    i, j, d = i[order], j[order], d[order]
    u = d / np.linalg.norm(d, axis=1)[:, None]
    return i, u, j


def _in_plane_perpendicular(u: np.ndarray) -> np.ndarray:
    """Unit vector ⊥ ``u`` in the plane of ``u`` and x (y if ``u`` ∥ x)."""
    for axis in (np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])):
        w = axis - (axis @ u) * u
        if np.linalg.norm(w) > 1e-3:
            return w / np.linalg.norm(w)
    raise AssertionError("unreachable: u cannot be parallel to both x and y")


def passivate_window(
    block: Atoms,
    inside: np.ndarray,
    z_bottom: float,
    z_top: float,
    faces: tuple[str, ...],
    species: str,
    field_name: str = "passivate",
) -> tuple[Atoms, np.ndarray, dict]:
    """The atoms ``inside`` of ``block`` with the dangling bonds of the chosen faces passivated.

    Parameters
    ----------
    block
        The oriented bulk, one repeat or more beyond both faces of the window, z along the
        surface normal, periodic in-plane.
    inside
        Mask of the slab's atoms (the window ``z_bottom <= z < z_top``).
    z_bottom, z_top
        The window (Å): a dangling bond belongs to the top face when its missing partner
        (outside the window) lies above the window's middle, else to the bottom face.
    faces
        Subset of ``("bottom", "top")``.
    species
        ``"H"`` or ``"OH"`` (module docstring).

    Returns
    -------
    (slab, parent, record)
        The slab (the window's atoms in block order, then the added atoms), for each atom
        of it the index *within the slab* of the atom it was added to (−1 for the crystal's
        own atoms; an hydroxyl H names its O's parent), and a JSON-ready record.
    """
    if species not in SPECIES:
        raise InputError(f"{field_name}={species!r}: expected one of none, {', '.join(SPECIES)}")
    elements = sorted(set(block.get_chemical_symbols()))
    if species == "OH" and "O" not in elements:  # it would build the H termination, called OH
        raise InputError(
            f"{field_name}=OH: the crystal has no O (elements {', '.join(elements)}): hydroxyl "
            "caps the bonds an oxide's cut breaks to O; passivate this crystal with H"
        )
    inside = np.asarray(inside, bool)
    keep = np.flatnonzero(inside)
    slot = -np.ones(len(block), dtype=int)
    slot[keep] = np.arange(keep.size)
    i, u, j = dangling_bonds(block, inside)
    z = block.positions[:, 2]
    face = np.where(z[j] >= 0.5 * (z_bottom + z_top), "top", "bottom")  # j is outside
    chosen = np.isin(face, faces)
    sym = np.array(block.get_chemical_symbols())
    added_sym: list[str] = []
    added_pos: list[np.ndarray] = []
    parent: list[int] = []
    per_face = {f: 0 for f in ("bottom", "top")}
    for a, v, b, f in zip(i[chosen], u[chosen], j[chosen], face[chosen], strict=True):
        per_face[str(f)] += 1
        ra, sa = block.positions[a], str(sym[a])
        if species == "OH" and sym[b] == "O":
            o = ra + bond_length_angstrom(sa, "O") * v
            bend = np.radians(180.0 - HYDROXYL_ANGLE_DEG)
            h_dir = np.cos(bend) * v + np.sin(bend) * _in_plane_perpendicular(v)
            added_sym += ["O", "H"]
            added_pos += [o, o + bond_length_angstrom("O", "H") * h_dir]
            parent += [int(slot[a]), int(slot[a])]
        else:
            added_sym.append("H")
            added_pos.append(ra + bond_length_angstrom(sa, "H") * v)
            parent.append(int(slot[a]))
    slab = block[keep]
    if added_sym:
        slab += Atoms(added_sym, positions=np.array(added_pos), cell=block.cell, pbc=block.pbc)
    parents = np.concatenate([-np.ones(keep.size, dtype=int), np.array(parent, dtype=int)])
    if added_sym:
        dist = neighbor_list("d", slab, MIN_DISTANCE_ANGSTROM)
        if dist.size:
            raise InputError(
                f"{field_name}={species}: two atoms {dist.min():.2f} Å apart after passivation "
                f"(< {MIN_DISTANCE_ANGSTROM} Å): the face's dangling bonds crowd each other; "
                "choose another termination or cut"
            )
    labels = sorted(
        {
            (str(sym[a]), "O" if species == "OH" and sym[b] == "O" else "H")
            for a, b in zip(i[chosen], j[chosen], strict=True)
        }
    )
    record = {
        "species": species,
        "faces": list(faces),
        **{f"{k}_dangling_bonds": per_face[k] for k in faces},
        "added_atoms": {s: added_sym.count(s) for s in sorted(set(added_sym))},
        "bond_lengths_angstrom": {f"{a}-{b}": bond_length_angstrom(a, b) for a, b in labels},
    }
    if species == "OH" and "O" in added_sym:
        record["hydroxyl_angle_deg"] = HYDROXYL_ANGLE_DEG
        record["O-H_angstrom"] = bond_length_angstrom("O", "H")
    return slab, parents, record
