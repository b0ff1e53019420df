"""Slabs of 3D crystals: a bulk file (any format ASE reads) or fcc(111) metals, Miller index, terminations.

Route (:func:`crystal_slab`):

1. The bulk is reduced to its primitive cell (pymatgen ``Structure.get_primitive_structure``)
   and the Miller index transformed with it (h_prim ∝ M·h for a_prim = M·a_conv, rows), so
   the in-plane cell of the slab is the primitive 2D cell of the plane.
2. ``ase.build.surface`` orients the primitive cell (a unimodular basis change: the oriented
   cell holds the atoms of one primitive cell); its repeat along the normal is ``d``.
3. Terminations: the distinct cuts are the gaps between atomic planes within one repeat
   ``d`` (:func:`flatcontact.structures.slab.cleavage_heights`, widest gap first);
   ``termination`` picks one.
4. The slab of ``layers`` layers holds the atoms with z_cut ≤ z < z_cut + layers·d; layer k
   is the k-th window of height d (one bulk repeat, stoichiometric).

pymatgen's ``SlabGenerator`` is not used for step 3-4 because its slab thickness counts
d_hkl planes of the conventional cell and its terminations come from a clustering
tolerance; the window rule above ties terminations and layers to the same repeat ``d``.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction
from math import gcd
from pathlib import Path

import numpy as np
from ase import Atoms
from ase.build import fcc111
from ase.build import surface as ase_surface
from ase.data import atomic_numbers, reference_states

from flatcontact.foundation.errors import InputError, require
from flatcontact.foundation.fileio import file_sha256
from flatcontact.structures.cell2d import standard_slab
from flatcontact.structures.layers import repeat_layers
from flatcontact.structures.passivate import passivate_window
from flatcontact.structures.site_checks import check_bond_lengths
from flatcontact.structures.slab import cleavage_heights
from flatcontact.structures.structure_file import read_structure


@dataclass
class OrientedBulk:
    """A bulk crystal oriented for a surface: in-plane primitive cell, repeat ``d`` along z."""

    atoms: Atoms  # one repeat, from ase.build.surface (layers=1, non-periodic z)
    miller: tuple[int, int, int]  # as given by the user (cell of the file)
    miller_primitive: tuple[int, int, int]
    repeat_angstrom: float
    cuts_angstrom: np.ndarray  # distinct cleavage heights within one repeat, widest gap first
    record: dict = field(default_factory=dict)


def file_record(path: str | Path) -> dict:
    """Name and sha256 of an input file (for ``info["recipe"]``)."""
    path = Path(path)
    return {"file": path.name, "sha256": file_sha256(path)}


def read_bulk(path: str | Path, field_name: str = "bulk") -> Atoms:
    """A fully periodic bulk crystal from any file ASE reads, checked by
    :func:`~flatcontact.structures.structure_file.read_structure`; one-line InputError otherwise."""
    path = Path(path)
    require(path.is_file(), f"{field_name}: file '{path}' not found")
    atoms = read_structure(path, field_name)
    require(
        abs(atoms.cell.volume) > 1e-6,
        f"{field_name}: '{path}' has no 3D cell (a bulk crystal needs three lattice vectors)",
    )
    atoms.pbc = True
    check_bond_lengths(atoms, f"{field_name}: {path}")  # before any relaxation
    return atoms


def check_miller(miller, field_name: str = "miller") -> tuple[int, int, int]:
    """Three integers, not all zero; InputError naming ``field_name``."""
    ok = (
        isinstance(miller, list | tuple)
        and len(miller) == 3
        and all(isinstance(v, int | np.integer) and not isinstance(v, bool) for v in miller)
        and any(miller)
    )
    require(
        ok,
        f"{field_name}={list(miller) if isinstance(miller, tuple) else miller!r}: expected three integers, not all zero",
    )
    g = gcd(gcd(int(miller[0]), int(miller[1])), int(miller[2]))
    return tuple(int(v) // g for v in miller)


def primitive_with_miller(
    bulk: Atoms, miller: tuple[int, int, int]
) -> tuple[Atoms, tuple[int, int, int]]:
    """The primitive cell of ``bulk`` and the Miller index of the same plane in it.

    Plane normals transform like reciprocal vectors: for a_prim = M·a_conv (rows),
    h_prim ∝ M·h (reduced to coprime integers).
    """
    from pymatgen.io.ase import AseAtomsAdaptor

    structure = AseAtomsAdaptor.get_structure(bulk)
    prim = structure.get_primitive_structure()
    if len(prim) == len(structure):
        return bulk.copy(), miller
    m = prim.lattice.matrix @ np.linalg.inv(structure.lattice.matrix)
    h = m @ np.asarray(miller, float)
    fracs = [Fraction(float(v)).limit_denominator(24) for v in h]
    lcm = 1
    for f in fracs:
        lcm = lcm * f.denominator // gcd(lcm, f.denominator)
    ints = [int(f * lcm) for f in fracs]
    g = gcd(gcd(abs(ints[0]), abs(ints[1])), abs(ints[2]))
    atoms = AseAtomsAdaptor.get_atoms(prim)
    atoms.pbc = True
    return atoms, tuple(v // g for v in ints)


def orient(bulk: Atoms, miller, field_name: str = "miller") -> OrientedBulk:
    """Orient ``bulk`` for the surface ``miller`` (indices in ``bulk``'s own cell)."""
    hkl = check_miller(miller, field_name)
    prim, hkl_p = primitive_with_miller(bulk, hkl)
    try:
        one = ase_surface(prim, hkl_p, 1, periodic=True)
    except Exception as exc:  # ASE refuses the index
        raise InputError(
            f"{field_name}={list(hkl)}: no slab ({type(exc).__name__}: {exc})"
        ) from None
    d = float(one.cell.array[2, 2])
    require(d > 1e-3, f"{field_name}={list(hkl)}: no slab (zero repeat along the normal)")
    cuts = _distinct_cuts(prim, hkl_p, cleavage_heights(one, d), d)
    return OrientedBulk(
        atoms=prim,
        miller=hkl,
        miller_primitive=hkl_p,
        repeat_angstrom=d,
        cuts_angstrom=np.asarray(cuts),
        record={
            "miller": list(hkl),
            "miller_primitive_cell": list(hkl_p),
            "repeat_angstrom": d,
            "atoms_per_layer": len(prim),
            "terminations": len(cuts),
        },
    )


def _distinct_cuts(
    prim: Atoms, hkl: tuple[int, int, int], cuts: np.ndarray, d: float
) -> np.ndarray:
    """Drop cuts that give the same one-layer slab as an earlier one (same heights and species
    in the same order, e.g. the three cuts related by α-quartz's 3₂ screw axis)."""
    two = ase_surface(prim, hkl, 2, periodic=False)
    z = two.positions[:, 2]
    seen, keep = set(), []
    for cut in cuts:
        inside = (z >= cut + 1e-6) & (z < cut + d + 1e-6)
        zz = z[inside] - z[inside].min()
        order = np.lexsort((two.numbers[inside], np.round(zz, 3)))
        key = tuple(
            zip(np.round(zz[order], 3).tolist(), two.numbers[inside][order].tolist(), strict=True)
        )
        if key not in seen:
            seen.add(key)
            keep.append(cut)
    return np.asarray(keep)


def crystal_slab(
    oriented: OrientedBulk, layers: int, termination: int = 0, field_name: str = "termination"
) -> Atoms:
    """``layers`` bulk repeats of ``oriented`` cut at termination ``termination``.

    Returns a standard slab (:func:`~flatcontact.structures.cell2d.standard_slab`) with
    ``arrays["layer"]`` (1..layers from the bottom, one bulk repeat each).
    """
    n = len(oriented.cuts_angstrom)
    require(
        isinstance(termination, int) and 0 <= termination < n,
        f"{field_name}={termination}: expected 0..{n - 1} ({n} distinct terminations of "
        f"{list(oriented.miller)}, widest gap first)",
    )
    d = oriented.repeat_angstrom
    big = ase_surface(oriented.atoms, oriented.miller_primitive, layers + 1, periodic=False)
    z_cut = float(oriented.cuts_angstrom[termination])
    z = big.positions[:, 2]
    eps = 1e-6
    keep = (z >= z_cut + eps) & (z < z_cut + layers * d + eps)
    slab = big[keep]
    require(len(slab) > 0, f"miller={list(oriented.miller)}: the cut selects no atoms")
    for key in ("tags",):
        slab.arrays.pop(key, None)
    slab.arrays["layer"] = repeat_layers(slab, d, z_cut)
    expected = layers * len(oriented.atoms)
    require(
        len(slab) == expected and slab.arrays["layer"].max() == layers,
        f"miller={list(oriented.miller)}: cut gave {len(slab)} atoms, expected {expected}",
    )
    slab.cell[2] = (0.0, 0.0, float(np.ptp(slab.positions[:, 2])) + 1.0)
    return standard_slab(slab)


def passivated_crystal_slab(
    oriented: OrientedBulk,
    layers: int,
    termination: int,
    faces: tuple[str, ...],
    species: str,
    field_name: str = "passivate",
) -> tuple[Atoms, dict]:
    """:func:`crystal_slab` with the dangling bonds of ``faces`` (``bottom``, ``top``) passivated.

    The same window of ``layers`` bulk repeats, cut from a block one repeat deeper on both
    sides, so the bonds the cut breaks are the bulk's own
    (:func:`~flatcontact.structures.passivate.passivate_window`: H, or OH on oxides). An added
    atom belongs to the layer of the atom it is bonded to (a face's H is part of the face
    layer). Returns the standard slab and the passivation record.
    """
    n = len(oriented.cuts_angstrom)
    require(
        isinstance(termination, int) and 0 <= termination < n,
        f"{field_name}: termination={termination}: expected 0..{n - 1}",
    )
    d = oriented.repeat_angstrom
    big = ase_surface(oriented.atoms, oriented.miller_primitive, layers + 3, periodic=False)
    z_cut = float(oriented.cuts_angstrom[termination]) + d  # one whole repeat below
    z = big.positions[:, 2]
    eps = 1e-6
    lo, hi = z_cut + eps, z_cut + layers * d + eps
    slab, parent, record = passivate_window(
        big, (z >= lo) & (z < hi), lo, hi, faces, species, field_name
    )
    slab.arrays.pop("tags", None)
    own = parent < 0
    layer = np.zeros(len(slab), dtype=int)
    layer[own] = repeat_layers(slab[own], d, z_cut)
    layer[~own] = layer[parent[~own]]
    slab.arrays["layer"] = layer
    expected = layers * len(oriented.atoms)
    require(
        int(own.sum()) == expected and layer.max() == layers,
        f"miller={list(oriented.miller)}: cut gave {int(own.sum())} atoms, expected {expected}",
    )
    slab.cell[2] = (0.0, 0.0, float(np.ptp(slab.positions[:, 2])) + 1.0)
    return standard_slab(slab), record


def fcc111_slab(element: str, layers: int, a_angstrom: float | None = None) -> tuple[Atoms, float]:
    """An fcc(111) slab of ``layers`` close-packed planes (``ase.build.fcc111``), one layer each.

    ``a_angstrom`` defaults to ASE's reference lattice constant of ``element``
    (Cu 3.61, Ni 3.52, Al 4.05 Å); InputError if the element is unknown or not fcc there.
    Returns the slab and the lattice constant used.
    """
    require(element in atomic_numbers, f"element='{element}': not a chemical symbol")
    if a_angstrom is None:
        ref = reference_states[atomic_numbers[element]] or {}
        require(
            ref.get("symmetry") == "fcc",
            f"element='{element}': ASE has no fcc reference lattice for it; give a_angstrom",
        )
        a_angstrom = float(ref["a"])
    require(a_angstrom > 0, f"a_angstrom={a_angstrom}: expected > 0")
    slab = fcc111(element, size=(1, 1, layers), a=a_angstrom, vacuum=5.0, orthogonal=False)
    slab.arrays.pop("tags", None)
    d = a_angstrom / np.sqrt(3.0)
    slab.arrays["layer"] = repeat_layers(slab, d, slab.positions[:, 2].min() - 0.5 * d)
    return standard_slab(slab), a_angstrom
