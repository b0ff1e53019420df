"""The two-slab interface file contract (``interface.extxyz``): what it holds and its checks.

Conventions (paper, Fig. 1):

- ASE ``Atoms``, periodic in x and y, non-periodic in z; cell vectors 1 and 2
  are the primitive in-plane lattice vectors a1, a2 (z-component 0); slab 1
  lies below slab 2.
- ``atoms.arrays["slab"]`` ∈ {1, 2}.
- ``atoms.arrays["surface"]`` ∈ {0, 1, 2, 3, 4}: 0 inner atoms, 1 outer (bottom)
  face of slab 1, 2 inner face of slab 1, 3 inner face of slab 2, 4 outer (top)
  face of slab 2.
- ``atoms.arrays["layer"]`` int ≥ 1: one id per physical layer across the whole
  interface, numbered from the bottom (slab 1's layers first); the molecule IDs of
  interlayer potentials and the unit of rigid-layer relaxation
  (:mod:`flatcontact.structures.layers` finds them from the structure).
- ``atoms.arrays["held"]`` bool (optional; default surface ∈ {1, 4}): the outer layers
  held by the scan. A held layer moves as a rigid body: its lateral shift and height are
  imposed and its shape is that of the reference, so whole layers are held, never some
  atoms of a layer. A one-layer slab (a 2D monolayer) is tagged 2 (slab 1) or 3 (slab 2)
  and held.
- ``atoms.info["a1"]``, ``atoms.info["a2"]``: in-plane primitive vectors (Å,
  2-vectors); ``atoms.info["recipe"]``: JSON string of how it was built;
  ``atoms.info["material"]``: short name of the slab material(s).
- The thickness z is mean z(held atoms of slab 2) − mean z(held atoms of slab 1) (Å):
  the paper's "distance between surface 1 and 4" for the quartz slabs, the interlayer
  distance for a bilayer of monolayers.
- Held atoms never move during a scan (``fixed_mask``).
- The stored cell: vector 3 is (0, 0, c), ``pbc = (True, True, False)``, with
  :data:`DEFAULT_VACUUM_ANGSTROM` kept above and below the atoms.

Reading and writing the file: :mod:`flatcontact.structures.interface_io`; building an
interface: :mod:`flatcontact.structures.assemble`; placing slab 2 for a scan point:
:mod:`flatcontact.structures.placement`.
"""

from __future__ import annotations

import numpy as np
from ase import Atoms

from flatcontact.foundation.errors import InputError, require

#: Vacuum (Å) kept above and below the interface along z in the stored cell.
DEFAULT_VACUUM_ANGSTROM = 10.0

SURFACE_INNER = 0
SURFACE_OUTER_1 = 1
SURFACE_INNER_1 = 2
SURFACE_INNER_2 = 3
SURFACE_OUTER_2 = 4
FIXED_SURFACES = (SURFACE_OUTER_1, SURFACE_OUTER_2)


#: ``slab2_operation`` of a recipe whose slab 2 continues slab 1's stacking (the builder's).
CONTINUATION = "continuation of slab 1's stacking"
#: Recipe kinds cut from a 3-D crystal: their continuation at zero shift is the perfect crystal.
CRYSTAL_KINDS = ("crystal", "fcc111")


def continues_crystal(recipe: dict) -> bool:
    """Whether an interface's recipe record (``info["recipe"]``, ``build.json["recipe"]``) is
    a 3-D crystal continued across the cut: its zero shift is the **perfect stacking** by
    construction, whatever its energy (a potential may favour the stacking fault)."""
    return recipe.get("kind") in CRYSTAL_KINDS and recipe.get("slab2_operation") == CONTINUATION


def recipe_record(atoms: Atoms) -> dict:
    """The recipe record of an interface (``info["recipe"]``, JSON), ``{}`` if absent."""
    import json

    raw = atoms.info.get("recipe")
    if isinstance(raw, dict):
        return raw
    try:
        out = json.loads(raw) if isinstance(raw, str) else {}
    except ValueError:
        return {}
    return out if isinstance(out, dict) else {}


def in_plane_vectors(atoms: Atoms) -> tuple[np.ndarray, np.ndarray]:
    """The primitive in-plane vectors (a1, a2) as 2-vectors (Å) from the cell."""
    cell = atoms.cell.array
    return cell[0, :2].copy(), cell[1, :2].copy()


def thickness(atoms: Atoms) -> float:
    """The paper's z (Å): mean z of slab 2's held atoms minus mean z of slab 1's held atoms.

    With the default held atoms (surfaces 1 and 4) this is mean z(surface 4) − mean
    z(surface 1); for a bilayer of monolayers (each layer held) the interlayer distance.
    """
    held = fixed_mask(atoms)
    slab = per_atom_array(atoms, "slab")
    z = atoms.positions[:, 2]
    return float(z[held & (slab == 2)].mean() - z[held & (slab == 1)].mean())


def fixed_mask(atoms: Atoms) -> np.ndarray:
    """Boolean mask of the atoms held during a scan: ``arrays["held"]``, else surfaces 1 and 4."""
    if "held" in atoms.arrays:
        return np.asarray(atoms.arrays["held"]).astype(bool)
    return np.isin(per_atom_array(atoms, "surface"), FIXED_SURFACES)


def atoms_content(atoms: Atoms, arrays: tuple[str, ...]) -> tuple | None:
    """``atoms``' numbers, positions, cell, pbc and those of the per-atom ``arrays`` it has
    (name, dtype, shape, values) as bytes: equal for two structures exactly when all of these
    are, so a key for what is computed from them once per structure; None when one of those
    arrays holds objects (its bytes are pointers, not values)."""
    names = [k for k in arrays if k in atoms.arrays]
    values = [np.asarray(atoms.arrays[k]) for k in names]
    if any(a.dtype.hasobject for a in values):
        return None
    return (
        tuple((k, a.dtype.str, a.shape, a.tobytes()) for k, a in zip(names, values, strict=True)),
        atoms.numbers.tobytes(),
        atoms.positions.tobytes(),
        atoms.cell.array.tobytes(),
        np.asarray(atoms.pbc).tobytes(),
    )


def validate_interface(atoms: Atoms, source: str = "interface") -> None:
    """Check the interface contract; raise a one-line :class:`InputError` naming ``source``.

    Surfaces 2 and 3 must be present; each slab must have held atoms (surface 1/4, or
    ``arrays["held"]``); when ``arrays["layer"]`` is given, slab 1's layers lie below slab
    2's and a held layer is held whole (never some of its atoms).
    """
    for key in ("slab", "surface"):
        require(key in atoms.arrays, f"{source}: missing per-atom array '{key}'")
    slab = np.asarray(atoms.arrays["slab"])
    surface = np.asarray(atoms.arrays["surface"])
    require(bool(np.all(np.isin(slab, (1, 2)))), f"{source}: array 'slab' must hold only 1 and 2")
    require(
        bool(np.all(np.isin(surface, (0, 1, 2, 3, 4)))),
        f"{source}: array 'surface' must hold only 0..4",
    )
    for tag, owner in ((1, 1), (2, 1), (3, 2), (4, 2)):
        members = surface == tag
        require(tag in (1, 4) or bool(np.any(members)), f"{source}: no atoms tagged surface={tag}")
        require(
            bool(np.all(slab[members] == owner)),
            f"{source}: surface={tag} atoms must belong to slab {owner}",
        )
    if "held" in atoms.arrays:
        held = np.asarray(atoms.arrays["held"])
        require(
            held.dtype == bool or bool(np.all(np.isin(held, (0, 1)))),
            f"{source}: array 'held' must be boolean",
        )
    held = fixed_mask(atoms)
    for which, outer in ((1, 1), (2, 4)):
        require(
            bool(np.any(held & (slab == which))),
            f"{source}: slab {which} has no held atoms (surface={outer} or array 'held')",
        )
    if "layer" in atoms.arrays:
        layer = np.asarray(atoms.arrays["layer"])
        require(
            np.issubdtype(layer.dtype, np.integer) and bool(np.all(layer >= 1)),
            f"{source}: array 'layer' must hold integers >= 1",
        )
        require(
            layer[slab == 1].max() < layer[slab == 2].min(),
            f"{source}: array 'layer': slab 1's layers must be numbered below slab 2's",
        )
        for k in np.unique(layer[held]):
            require(
                bool(np.all(held[layer == k])),
                f"{source}: layer {k} is partly held; a held layer is held whole (rigid body)",
            )
    require(bool(atoms.pbc[0] and atoms.pbc[1]), f"{source}: must be periodic in x and y")
    require_in_plane_cell(atoms, source)
    z = atoms.positions[:, 2]
    require(z[slab == 1].mean() < z[slab == 2].mean(), f"{source}: slab 1 must lie below slab 2")


def per_atom_array(atoms: Atoms, key: str) -> np.ndarray:
    """The contract's per-atom array ``key`` of ``atoms``; :class:`InputError` if it is missing."""
    if key not in atoms.arrays:
        raise InputError(
            f"interface Atoms has no per-atom array '{key}' (see interface.extxyz contract)"
        )
    return np.asarray(atoms.arrays[key])


def require_in_plane_cell(atoms: Atoms, source: str) -> None:
    """Cell vectors 1 and 2 in the x-y plane and not degenerate, else :class:`InputError` naming ``source``."""
    cell = atoms.cell.array
    require(
        abs(cell[0, 2]) < 1e-8 and abs(cell[1, 2]) < 1e-8,
        f"{source}: cell vectors 1 and 2 must lie in the x-y plane (z-components 0)",
    )
    require(
        abs(cell[0, 0] * cell[1, 1] - cell[0, 1] * cell[1, 0]) > 1e-8,
        f"{source}: in-plane cell vectors are degenerate",
    )


def set_vertical_cell(atoms: Atoms, vacuum_angstrom: float, keep_at_least: float = 0.0) -> None:
    """Make cell vector 3 = (0, 0, max(height + 2·vacuum, keep_at_least)) and pbc = (T, T, F)."""
    z = atoms.positions[:, 2]
    height = float(z.max() - z.min())
    c = max(height + 2.0 * vacuum_angstrom, keep_at_least)
    cell = atoms.cell.array.copy()
    cell[2] = (0.0, 0.0, c)
    atoms.set_cell(cell, scale_atoms=False)
    atoms.pbc = (True, True, False)
