"""The two-slab interface (the ``interface.extxyz`` contract of DESIGN.md).

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
"""

from __future__ import annotations

import json
import os
from pathlib import Path

import numpy as np
from ase import Atoms

from flatcontact.errors import InputError, require
from flatcontact.fileio import atomic_path

#: Closest allowed distance (Å) between an atom of slab 1 and one of slab 2 in
#: :func:`place_slab2`; shorter means the slabs overlap (a Si–O bond is 1.6 Å).
MIN_INTERSLAB_DISTANCE_ANGSTROM = 1.0
#: Largest compressive strain −dz/z_ref of the stack between the held layers that
#: :func:`place_slab2` spreads homogeneously when a rigid placement would overlap (10 %: a
#: stack of quartz slabs carries about 5 GPa at 5 %; beyond, the request is a mistake).
MAX_SPREAD_STRAIN = 0.10
#: Vacuum (Å) kept above and below the interface along z in the stored cell.
DEFAULT_VACUUM_ANGSTROM = 10.0

SURFACE_INNER = 0
SURFACE_OUTER_1 = 1
SURFACE_INNER_1 = 2
SURFACE_INNER_2 = 3
SURFACE_OUTER_2 = 4
FIXED_SURFACES = (SURFACE_OUTER_1, SURFACE_OUTER_2)


# --------------------------------------------------------------------------- tags and geometry
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
    slab = _array(atoms, "slab")
    z = atoms.positions[:, 2]
    return float(z[held & (slab == 2)].mean() - z[held & (slab == 1)].mean())


def fixed_mask(atoms: Atoms) -> np.ndarray:
    """Boolean mask of the atoms held during a scan: ``arrays["held"]``, else surfaces 1 and 4."""
    if "held" in atoms.arrays:
        return np.asarray(atoms.arrays["held"]).astype(bool)
    return np.isin(_array(atoms, "surface"), FIXED_SURFACES)


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


def interslab_min_distance(atoms: Atoms, cutoff_angstrom: float = 4.0) -> float:
    """Closest distance (Å) between an atom of slab 1 and one of slab 2 (lateral PBC).

    Returns ``inf`` if no pair is closer than ``cutoff_angstrom``.

    Only cross pairs are searched (a k-d tree over slab 1's atoms within ``cutoff_angstrom``
    in z of slab 2 and their periodic images, queried with the facing atoms of slab 2): the
    scan runs this for every grid point, and a neighbour list of all pairs cost more than a
    force call on small cells.
    """
    from scipy.spatial import cKDTree

    slab = _array(atoms, "slab")
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
    d, _ = cKDTree(images).query(p2, k=1, distance_upper_bound=cutoff_angstrom)
    closest = float(d.min())
    return closest if closest < cutoff_angstrom else float("inf")


# --------------------------------------------------------------------------- construction
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
    _require_in_plane_cell(slab, "slab")
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
    _set_vertical_cell(atoms, vacuum_angstrom)
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
    from flatcontact.structures.layers import atomic_planes

    layers = np.ones(len(slab), dtype=int)
    inner = tags == 0
    count = 1
    if inner.any():
        planes = atomic_planes(slab.positions[inner, 2])
        layers[inner] = planes + 2
        count = int(planes.max()) + 2
    layers[tags == 2] = count + 1
    return layers


def place_slab2(
    reference: Atoms,
    shift_a: float,
    shift_b: float,
    thickness_angstrom: float,
    *,
    min_distance_angstrom: float = MIN_INTERSLAB_DISTANCE_ANGSTROM,
    spread_compression: bool = True,
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

    Raises
    ------
    InputError
        If the shifts or thickness are not finite, or the slabs would overlap (closest
        inter-slab distance below ``min_distance_angstrom``) with the allowed placement.
    """
    validate_interface(reference, "reference interface")
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
    _set_vertical_cell(atoms, DEFAULT_VACUUM_ANGSTROM, keep_at_least=reference.cell.array[2, 2])
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


# --------------------------------------------------------------------------- I/O and validation
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
    _require_in_plane_cell(atoms, source)
    z = atoms.positions[:, 2]
    require(z[slab == 1].mean() < z[slab == 2].mean(), f"{source}: slab 1 must lie below slab 2")


def write_interface(atoms: Atoms, path: str | os.PathLike[str]) -> Path:
    """Write the interface as extended XYZ (arrays and info kept), atomically."""
    validate_interface(atoms, str(path))
    out = atoms.copy()
    out.calc = None
    a1, a2 = in_plane_vectors(out)
    out.info = {
        "a1": np.asarray(a1, dtype=float),
        "a2": np.asarray(a2, dtype=float),
        "recipe": str(atoms.info.get("recipe", "{}")),
    }
    if atoms.info.get("material"):
        out.info["material"] = str(atoms.info["material"])
    out.arrays["slab"] = np.asarray(out.arrays["slab"], dtype=int)
    out.arrays["surface"] = np.asarray(out.arrays["surface"], dtype=int)
    if "layer" in out.arrays:
        out.arrays["layer"] = np.asarray(out.arrays["layer"], dtype=int)
    if "held" in out.arrays:
        out.arrays["held"] = np.asarray(out.arrays["held"], dtype=bool)
    with atomic_path(path) as tmp:
        # imported here: ase.io costs 0.3-0.5 s, and scan workers never write a file
        from ase.io import write

        write(tmp, out, format="extxyz")
    return Path(path)


def read_interface(path: str | os.PathLike[str]) -> Atoms:
    """Read an ``interface.extxyz`` and validate it (one-line :class:`InputError` if not valid).

    A file without ``layer`` gets one found from the structure
    (:func:`flatcontact.structures.layers.interface_layers`); without ``held`` the
    contract's default (surfaces 1 and 4) is stored explicitly.
    """
    path = Path(path)
    require(path.is_file(), f"{path}: interface file not found")
    try:
        from ase.io import read

        atoms = read(path, format="extxyz", index=-1)
    except Exception as exc:  # malformed file: report it as the user's to fix
        raise InputError(
            f"{path}: not a readable extended XYZ file ({type(exc).__name__}: {exc})"
        ) from None
    validate_interface(atoms, str(path))
    atoms.arrays["slab"] = np.asarray(atoms.arrays["slab"], dtype=int)
    atoms.arrays["surface"] = np.asarray(atoms.arrays["surface"], dtype=int)
    atoms.arrays["held"] = fixed_mask(atoms)
    if "layer" in atoms.arrays:
        atoms.arrays["layer"] = np.asarray(atoms.arrays["layer"], dtype=int)
    else:
        from flatcontact.structures.layers import interface_layers

        atoms.arrays["layer"] = interface_layers(atoms)
        validate_interface(atoms, str(path))
    a1, a2 = in_plane_vectors(atoms)
    recipe = atoms.info.get("recipe", "{}")
    if not isinstance(recipe, str):
        recipe = json.dumps(recipe)
    info = {"a1": a1, "a2": a2, "recipe": recipe}
    if atoms.info.get("material"):
        info["material"] = str(atoms.info["material"])
    atoms.info = info
    return atoms


# --------------------------------------------------------------------------- helpers
def _array(atoms: Atoms, key: str) -> np.ndarray:
    if key not in atoms.arrays:
        raise InputError(
            f"interface Atoms has no per-atom array '{key}' (see interface.extxyz contract)"
        )
    return np.asarray(atoms.arrays[key])


def _require_in_plane_cell(atoms: Atoms, source: str) -> None:
    cell = atoms.cell.array
    require(
        abs(cell[0, 2]) < 1e-8 and abs(cell[1, 2]) < 1e-8,
        f"{source}: cell vectors 1 and 2 must lie in the x-y plane (z-components 0)",
    )
    require(
        abs(cell[0, 0] * cell[1, 1] - cell[0, 1] * cell[1, 0]) > 1e-8,
        f"{source}: in-plane cell vectors are degenerate",
    )


def _set_vertical_cell(atoms: Atoms, vacuum_angstrom: float, keep_at_least: float = 0.0) -> None:
    """Make cell vector 3 = (0, 0, max(height + 2·vacuum, keep_at_least)) and pbc = (T, T, F)."""
    z = atoms.positions[:, 2]
    height = float(z.max() - z.min())
    c = max(height + 2.0 * vacuum_angstrom, keep_at_least)
    cell = atoms.cell.array.copy()
    cell[2] = (0.0, 0.0, c)
    atoms.set_cell(cell, scale_atoms=False)
    atoms.pbc = (True, True, False)
