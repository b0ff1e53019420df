"""Two slabs on one in-plane cell → the tagged interface (``interface.extxyz`` contract).

Conventions: slab 1 lies below slab 2; slab 2 is the one the scan moves
(``place_slab2``); each slab carries ``arrays["layer"]`` (1..L within the slab, from the
bottom); the held outer layers and the surface tags follow
:func:`flatcontact.structures.interface.tag_interface`.
"""

from __future__ import annotations

import json

import numpy as np
from ase import Atoms

from flatcontact.errors import require
from flatcontact.structures.cell2d import standard_slab
from flatcontact.structures.interface import (
    DEFAULT_VACUUM_ANGSTROM,
    in_plane_vectors,
    tag_interface,
)


def layer_plane(atoms: Atoms, k: int) -> float:
    """Mean height (Å) of layer ``k`` of a slab."""
    layer = np.asarray(atoms.arrays["layer"])
    return float(atoms.positions[layer == k, 2].mean())


def stack_pair(slab1: Atoms, slab2: Atoms, spacing_angstrom: float, by: str = "planes") -> Atoms:
    """Slab 2 put above slab 1 (same in-plane cell), ``arrays["slab"]`` set.

    ``by="planes"``: the mean plane of slab 2's bottom layer lies ``spacing_angstrom`` above
    that of slab 1's top layer (the interlayer distance of 2D sheets); ``by="atoms"``: the
    lowest atom of slab 2 lies ``spacing_angstrom`` above the highest atom of slab 1.
    """
    require(spacing_angstrom > 0, f"interface spacing must be > 0 Å, got {spacing_angstrom}")
    require(
        np.allclose(slab1.cell.array[:2, :2], slab2.cell.array[:2, :2], atol=1e-6),
        "the two slabs must share one in-plane cell",
    )
    lower, upper = slab1.copy(), slab2.copy()
    if by == "planes":
        top = layer_plane(lower, int(np.max(lower.arrays["layer"])))
        bottom = layer_plane(upper, 1)
    else:
        top, bottom = float(lower.positions[:, 2].max()), float(upper.positions[:, 2].min())
    upper.positions[:, 2] += top + spacing_angstrom - bottom
    upper.set_cell(lower.cell, scale_atoms=False)
    lower.arrays["slab"] = np.ones(len(lower), dtype=int)
    upper.arrays["slab"] = np.full(len(upper), 2)
    return lower + upper


def split_stack(stack: Atoms, layers_in_slab1: int, extra_gap_angstrom: float = 0.0) -> Atoms:
    """A stack of layers (``arrays["layer"]`` 1..L) cut into slab 1 (the lowest ``layers_in_slab1``) and slab 2.

    Slab 2 is raised by ``extra_gap_angstrom``; with 0 the interface is the perfect stack
    (bulk continuation for a crystal, the stacking sequence for sheets). Layer ids are
    renumbered within each slab.
    """
    atoms = stack.copy()
    layer = np.asarray(atoms.arrays["layer"], dtype=int)
    upper = layer > layers_in_slab1
    require(bool(upper.any()) and bool((~upper).any()), "the stack must hold both slabs")
    atoms.positions[upper, 2] += extra_gap_angstrom
    atoms.arrays["slab"] = np.where(upper, 2, 1)
    atoms.arrays["layer"] = np.where(upper, layer - layers_in_slab1, layer)
    return atoms


def finish_interface(
    atoms: Atoms,
    held_layers: int,
    material: str,
    recipe: dict,
    vacuum_angstrom: float = DEFAULT_VACUUM_ANGSTROM,
) -> Atoms:
    """Tag (slab/surface/layer/held), set the vertical cell and the info keys.

    ``atoms`` has ``arrays["slab"]`` and per-slab ``arrays["layer"]``. Atoms are reordered
    slab 1 first, then slab 2, each by layer (stable).
    """
    slab = np.asarray(atoms.arrays["slab"], dtype=int)
    layer = np.asarray(atoms.arrays["layer"], dtype=int)
    order = np.lexsort((layer, slab))
    out = atoms[order]
    out.calc = None
    for key in ("tags", "momenta", "initial_magmoms", "initial_charges", "spacegroup_kinds"):
        out.arrays.pop(key, None)
    tags = tag_interface(out.arrays["slab"], out.arrays["layer"], held_layers)
    out.arrays.update(tags)
    require(
        np.cross(out.cell.array[0], out.cell.array[1])[2] > 0,
        "the common in-plane cell must be right-handed (a1 × a2 along +z)",
    )
    out = standard_slab(out, vacuum_angstrom)
    a1, a2 = in_plane_vectors(out)
    out.info = {
        "a1": a1,
        "a2": a2,
        "recipe": json.dumps(recipe, sort_keys=True),
        "material": material,
    }
    return out
