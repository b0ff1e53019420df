"""Building a tagged interface (:mod:`~flatcontact.structures.interface_contract`) from slabs.

Two ways in: two slabs on one in-plane cell (:func:`stack_pair`, :func:`split_stack`,
then :func:`finish_interface`), or one slab and a translated copy of it
(:func:`make_interface`, faces tagged by :func:`face_tags`). The tags (``slab``,
``surface``, ``layer``, ``held``) come from :func:`tag_interface`.

Conventions: slab 1 lies below slab 2; slab 2 is the one the scan moves
(:func:`~flatcontact.structures.placement.place_slab2`); each slab carries
``arrays["layer"]`` (1..L within the slab, from the bottom).
"""

from __future__ import annotations

import json

import numpy as np
from ase import Atoms

from flatcontact.foundation.errors import InputError, require
from flatcontact.structures.cell2d import standard_slab
from flatcontact.structures.interface_contract import (
    DEFAULT_VACUUM_ANGSTROM,
    FIXED_SURFACES,
    SURFACE_INNER_1,
    SURFACE_INNER_2,
    SURFACE_OUTER_1,
    SURFACE_OUTER_2,
    in_plane_vectors,
    require_in_plane_cell,
    set_vertical_cell,
)
from flatcontact.structures.layers import atomic_planes


def face_tags(
    slab: Atoms, face_atoms: int | None = None, face_depth_angstrom: float | None = None
) -> np.ndarray:
    """Tag the two faces of a single slab by height: 1 = bottom face, 2 = top face, 0 = inner.

    Exactly one of ``face_atoms`` (the ``n`` lowest and ``n`` highest atoms, e.g.
    one O–Si–O unit of a 1×1 quartz cell = 3) or ``face_depth_angstrom`` (atoms
    within this depth of the lowest/highest atom) selects the faces.
    """
    z = slab.positions[:, 2]
    n = len(slab)
    tags = np.zeros(n, dtype=int)
    if (face_atoms is None) == (face_depth_angstrom is None):
        raise InputError("give exactly one of face_atoms or face_depth_angstrom to tag slab faces")
    if face_atoms is not None:
        require(
            0 < face_atoms and 2 * face_atoms < n,
            f"face_atoms={face_atoms}: expected 1 <= face_atoms < {n}/2 for a {n}-atom slab",
        )
        order = np.argsort(z, kind="stable")
        tags[order[:face_atoms]] = 1
        tags[order[-face_atoms:]] = 2
    else:
        require(
            face_depth_angstrom > 0, f"face_depth_angstrom must be > 0, got {face_depth_angstrom}"
        )
        bottom = z <= z.min() + face_depth_angstrom
        top = z >= z.max() - face_depth_angstrom
        require(
            not np.any(bottom & top),
            f"face_depth_angstrom={face_depth_angstrom} is more than half the slab height {np.ptp(z):.2f} Å",
        )
        tags[bottom] = 1
        tags[top] = 2
    return tags


def tag_interface(
    slab_of_atom: np.ndarray, layer_in_slab: np.ndarray, held_layers: int = 1
) -> dict[str, np.ndarray]:
    """The contract's arrays ``slab``, ``surface``, ``layer``, ``held`` from per-slab layers.

    Parameters
    ----------
    slab_of_atom
        1 or 2 per atom (slab 1 below slab 2).
    layer_in_slab
        Layer index of each atom within its own slab, 1..L from the bottom.
    held_layers
        Outer layers held per slab (surface 1 = the ``held_layers`` lowest layers of slab
        1, surface 4 = the highest of slab 2); the layer facing the other slab is surface
        2 (slab 1) or 3 (slab 2), the rest 0. A one-layer slab is its own inner face
        (2 or 3) and is held. A slab of more layers needs ``L >= held_layers + 1``.
    """
    slab_of_atom = np.asarray(slab_of_atom, dtype=int)
    layer_in_slab = np.asarray(layer_in_slab, dtype=int)
    n = slab_of_atom.size
    surface = np.zeros(n, dtype=int)
    held = np.zeros(n, dtype=bool)
    layer = np.zeros(n, dtype=int)
    offset = 0
    for which, inner_tag, outer_tag in (
        (1, SURFACE_INNER_1, SURFACE_OUTER_1),
        (2, SURFACE_INNER_2, SURFACE_OUTER_2),
    ):
        mine = slab_of_atom == which
        require(bool(mine.any()), f"slab {which} has no atoms")
        k = layer_in_slab[mine]
        count = int(k.max())
        require(
            set(np.unique(k).tolist()) == set(range(1, count + 1)),
            f"slab {which}: layer indices must be 1..{count} without gaps",
        )
        layer[mine] = k + offset
        offset += count
        if count == 1:
            surface[mine] = inner_tag
            held[mine] = True
            continue
        require(
            count >= held_layers + 1,
            f"slab {which}: {count} layers cannot hold {held_layers} outer layer(s) and keep a "
            "free face layer; use one layer or at least held_layers + 1",
        )
        outer = k <= held_layers if which == 1 else k > count - held_layers
        inner = k == count if which == 1 else k == 1
        tags = np.zeros(k.size, dtype=int)
        tags[outer] = outer_tag
        tags[inner] = inner_tag
        surface[mine] = tags
        held[mine] = outer
    return {"slab": slab_of_atom.copy(), "surface": surface, "layer": layer, "held": held}


def make_interface(
    slab: Atoms,
    gap_angstrom: float,
    *,
    face_atoms: int | None = None,
    face_depth_angstrom: float | None = None,
    vacuum_angstrom: float = DEFAULT_VACUUM_ANGSTROM,
    recipe: dict | None = None,
    slab_layers: np.ndarray | None = None,
    material: str = "",
) -> Atoms:
    """Two identical slabs facing each other: slab 2 is slab 1 translated along z.

    Parameters
    ----------
    slab
        One slab, periodic in x, y with cell vectors 1, 2 in the x-y plane.
        For α-quartz (0001) the two faces are related by the crystal's in-plane
        2-fold axes, so a translated copy presents the same surface to slab 1.
    gap_angstrom
        Vertical distance between the highest atom of slab 1 and the lowest of slab 2.
    face_atoms, face_depth_angstrom
        How the faces are tagged (see :func:`face_tags`).
    vacuum_angstrom
        Vacuum kept below and above along z in the stored cell.
    recipe
        JSON-serialisable record of how the slab was built; stored in ``info["recipe"]``.
    slab_layers
        Layer index (1..L from the bottom) of each atom of ``slab`` (``arrays["layer"]``);
        default: the bottom face is layer 1, the top face layer L, and each atomic plane
        between (heights within 0.3 Å) a layer. The bottom face of slab 1 and the top
        face of slab 2 are held (``arrays["held"]`` = surfaces 1 and 4).
    material
        Short name of the slab material, stored in ``info["material"]``.
    """
    require_in_plane_cell(slab, "slab")
    require(gap_angstrom > 0, f"gap_angstrom must be > 0, got {gap_angstrom}")
    tags = face_tags(slab, face_atoms=face_atoms, face_depth_angstrom=face_depth_angstrom)
    if slab_layers is None:
        slab_layers = _layers_from_faces(slab, tags)
    lower = slab.copy()
    lower.positions[:, 2] -= lower.positions[:, 2].min()
    height = float(lower.positions[:, 2].max())
    upper = lower.copy()
    upper.positions[:, 2] += height + gap_angstrom
    atoms = lower + upper
    n = len(slab)
    atoms.arrays["slab"] = np.repeat([1, 2], n)
    surface = np.zeros(2 * n, dtype=int)
    surface[:n][tags == 1] = SURFACE_OUTER_1
    surface[:n][tags == 2] = SURFACE_INNER_1
    surface[n:][tags == 1] = SURFACE_INNER_2
    surface[n:][tags == 2] = SURFACE_OUTER_2
    atoms.arrays["surface"] = surface
    slab_layers = np.asarray(slab_layers, dtype=int)
    atoms.arrays["layer"] = np.concatenate([slab_layers, slab_layers + slab_layers.max()])
    atoms.arrays["held"] = np.isin(surface, FIXED_SURFACES)
    for key in ("tags", "momenta", "initial_magmoms", "initial_charges"):
        atoms.arrays.pop(key, None)
    atoms.positions[:, 2] += vacuum_angstrom
    set_vertical_cell(atoms, vacuum_angstrom)
    a1, a2 = in_plane_vectors(atoms)
    atoms.info = {
        "a1": a1,
        "a2": a2,
        "recipe": json.dumps(recipe or {}, sort_keys=True),
        "material": material,
    }
    return atoms


def _layers_from_faces(slab: Atoms, tags: np.ndarray) -> np.ndarray:
    """Layers of a slab tagged by faces: bottom face 1, each inner atomic plane, top face last."""
    layers = np.ones(len(slab), dtype=int)
    inner = tags == 0
    count = 1
    if inner.any():
        planes = atomic_planes(slab.positions[inner, 2])
        layers[inner] = planes + 2
        count = int(planes.max()) + 2
    layers[tags == 2] = count + 1
    return layers


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
