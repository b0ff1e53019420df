"""The asperity in atoms: a cap of slab 2's crystal on a flat of slab 1's crystal.

Built from the run's own interface (the two crystals, their orientation, the registry and
the spacing of the flat ISPES at zero shift), made deeper by the recipe's ``layers``:

- the **flat**: slab 1 repeated laterally (n1 × n2 primitive cells), ``flat_layers`` planes;
- the **tip**: slab 2 repeated the same way, ``tip_layers`` planes, keeping the atoms inside a
  cylinder (axis along a1, the cell's x; quasi-2D, periodic along the axis) or a sphere of
  radius R whose lowest point lies half a plane spacing below slab 2's facing plane, so the
  apex terrace is the ISPES's facing plane at zero shift (terraced, as a crystal is);
- **rigid blocks**: the tip's top ``rigid_angstrom`` and the flat's bottom ``rigid_angstrom``
  (per-atom array ``block``: 1 flat rigid, 2 tip rigid, 0 free).

Coordinates: z normal (the tip above), the contact coordinate is y for the cylinder (the
distance from the axis, across it) and the in-plane distance r from the apex for the sphere.
The apex lies at an atom of the tip's facing plane nearest the cell centre. Lengths in Å.

Sizes (:func:`plan_sizes`) follow from R, the largest target load and E*: the Hertz half-width
a (line: a = 2 R p0 / E*; sphere: a = π R p0 / (2 E*)), the depth of each body and the lateral
period several a. The finite-size error is stated as the two ratios a/D and 2a/L: the Hertz
(half-space) solution holds for a/D, 2a/L → 0; at a/D = 0.25 the half-width of a layer on a
rigid base is a few per cent below Hertz's (Johnson §5.9 for a bonded layer), and periodic
images at 2a/L = 0.25 add a pressure of the same order at the centre.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np
from ase import Atoms

from flatcontact.asperity.binning import contact_coordinate
from flatcontact.foundation.errors import InputError, require
from flatcontact.structures.layers import atomic_planes

#: Bytes per atom of a LAMMPS run (positions, forces, minimiser vectors, ghosts) besides the
#: neighbour list; the neighbour list costs 4 bytes per neighbour (half list).
BYTES_PER_ATOM = 2000
#: Fraction of the available memory a run may take.
MEMORY_FRACTION = 0.5
#: Atoms per run above which the builder refuses (raise it with FLATCONTACT_MAX_ASPERITY_ATOMS).
MAX_ATOMS_DEFAULT = 2_000_000

BLOCK_FREE, BLOCK_FLAT, BLOCK_TIP = 0, 1, 2
GEOMETRIES = ("cylinder", "sphere")


@dataclass(frozen=True)
class Sizes:
    """The box of one asperity run (Å, counts).

    Attributes
    ----------
    geometry : ``cylinder`` or ``sphere``
    radius_angstrom : R
    hertz_half_width_angstrom : a at the largest target load (Hertz, E*)
    repeats : (n1, n2) primitive cells along a1 and a2
    flat_layers, tip_layers : atomic planes of the flat and of the tip
    rigid_angstrom : thickness of each rigid block
    """

    geometry: str
    radius_angstrom: float
    hertz_half_width_angstrom: float
    repeats: tuple[int, int]
    flat_layers: int
    tip_layers: int
    rigid_angstrom: float

    def to_json(self) -> dict:
        return {
            "geometry": self.geometry,
            "radius_angstrom": self.radius_angstrom,
            "hertz_half_width_angstrom": self.hertz_half_width_angstrom,
            "repeats": list(self.repeats),
            "flat_layers": self.flat_layers,
            "tip_layers": self.tip_layers,
            "rigid_angstrom": self.rigid_angstrom,
        }


def hertz_half_width_angstrom(
    geometry: str, radius_angstrom: float, p0_gpa: float, contact_modulus_gpa: float
) -> float:
    """Hertz a (Å) at peak pressure p0: line 2 R p0 / E*, sphere π R p0 / (2 E*)."""
    if geometry == "cylinder":
        return 2.0 * radius_angstrom * p0_gpa / contact_modulus_gpa
    return math.pi * radius_angstrom * p0_gpa / (2.0 * contact_modulus_gpa)


def plan_sizes(
    geometry: str,
    radius_angstrom: float,
    p0_gpa_max: float,
    contact_modulus_gpa: float,
    cell_2d: np.ndarray,
    plane_spacing_angstrom: float,
    *,
    depth_factor: float = 2.0,
    lateral_factor: float = 4.0,
    axis_repeats: int = 2,
    rigid_angstrom: float = 6.0,
    edge_gap_angstrom: float = 6.0,
    tip_plane_spacing_angstrom: float | None = None,
) -> Sizes:
    """Sizes from R, the largest load and E*: depth ``depth_factor``·a per body (at least a
    few planes above the rigid block), lateral period ``lateral_factor``·2a (cylinder: across
    the axis only; ``axis_repeats`` cells along it), and at least wide enough that the cap
    rises ``edge_gap_angstrom`` above the flat at the period's edge (L/2 >= √(2 R h)): an
    adhesive coupling (LJ across, range ~ its σ and beyond) would otherwise pull the whole
    period into contact and the "asperity" would be a flat.

    ``tip_plane_spacing_angstrom``: the tip crystal's mean plane spacing when it differs from
    the flat's (a hetero interface: graphite on diamond); the tip gets the same depth in its
    own planes.

    Raises
    ------
    InputError
        ``geometry`` not cylinder/sphere, or R, p0, E* not > 0.
    """
    require(geometry in GEOMETRIES, f"geometry: expected one of {GEOMETRIES}, got {geometry!r}")
    for name, v in (
        ("radius_angstrom", radius_angstrom),
        ("p0_gpa", p0_gpa_max),
        ("contact_modulus_gpa", contact_modulus_gpa),
    ):
        require(math.isfinite(v) and v > 0, f"{name} must be > 0, got {v!r}")
    a = hertz_half_width_angstrom(geometry, radius_angstrom, p0_gpa_max, contact_modulus_gpa)
    a1, a2 = np.asarray(cell_2d, float)
    # the periods across: a1 along x; a2's component perpendicular to a1 (the cell's y)
    width_2 = abs(a2[1])
    width_1 = abs(a1[0])
    period = max(
        lateral_factor * 2.0 * a,
        4.0 * rigid_angstrom,
        2.0 * math.sqrt(2.0 * radius_angstrom * edge_gap_angstrom),
    )
    n2 = max(2, math.ceil(period / width_2))
    n1 = (
        max(1, int(axis_repeats)) if geometry == "cylinder" else max(2, math.ceil(period / width_1))
    )
    depth = max(depth_factor * a, 2.0 * rigid_angstrom)
    layers = max(3, math.ceil(depth / plane_spacing_angstrom) + 1)
    # the tip: the same depth in its own planes, plus its rigid block
    tip_spacing = tip_plane_spacing_angstrom or plane_spacing_angstrom
    tip_layers = max(3, math.ceil(depth / tip_spacing) + 1)
    rigid_planes = math.ceil(rigid_angstrom / tip_spacing)
    return Sizes(
        geometry,
        float(radius_angstrom),
        float(a),
        (n1, n2),
        layers,
        tip_layers + rigid_planes,
        float(rigid_angstrom),
    )


def estimate_atoms(sizes: Sizes, atoms_per_cell_plane: float) -> int:
    """Upper bound of the atom count: both bodies full (the cap removes part of the tip)."""
    n1, n2 = sizes.repeats
    return math.ceil(n1 * n2 * atoms_per_cell_plane * (sizes.flat_layers + sizes.tip_layers))


def available_memory_bytes() -> int:
    """MemAvailable of /proc/meminfo, or the physical memory where that is not readable."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def check_machine(
    n_atoms: int, neighbours_per_atom: int, field: str = "asperity", ranks: int = 1
) -> int:
    """Refuse in one line a run whose atoms or memory exceed the machine; return the bytes.

    Memory ≈ n (BYTES_PER_ATOM + 4 · neighbours/2), plus over ``ranks`` > 1 MPI ranks what
    each rank's Python holds (:func:`flatcontact.asperity.ranks.rank_memory_bytes`); refused
    above MEMORY_FRACTION of MemAvailable or above FLATCONTACT_MAX_ASPERITY_ATOMS atoms.
    """
    from flatcontact.asperity.ranks import rank_memory_bytes

    need = int(n_atoms * (BYTES_PER_ATOM + 2 * neighbours_per_atom))
    need += rank_memory_bytes(n_atoms, ranks)
    have = available_memory_bytes()
    limit = int(os.environ.get("FLATCONTACT_MAX_ASPERITY_ATOMS", MAX_ATOMS_DEFAULT))
    if n_atoms > limit:
        raise InputError(
            f"{field}: {n_atoms:,} atoms exceed the bound {limit:,} "
            "(smaller radius_angstrom or loads, or raise FLATCONTACT_MAX_ASPERITY_ATOMS)"
        )
    if need > MEMORY_FRACTION * have:
        raise InputError(
            f"{field}: {n_atoms:,} atoms need ~{need / 1e9:.2f} GB"
            + (f" over {ranks} MPI ranks" if ranks > 1 else "")
            + ", more than "
            f"{MEMORY_FRACTION:.0%} of the {have / 1e9:.2f} GB available"
        )
    return need


def plane_spacing(interface: Atoms, slab: int = 1) -> float:
    """Mean spacing (Å) of slab ``slab``'s atomic planes (heights grouped within 0.3 Å)."""
    z = np.sort(interface.positions[np.asarray(interface.arrays["slab"]) == slab, 2])
    planes = [z[0]]
    for v in z[1:]:
        if v - planes[-1] > 0.3:
            planes.append(v)
    require(len(planes) >= 2, "structure: the asperity needs slabs of at least 2 atomic planes")
    return float((planes[-1] - planes[0]) / (len(planes) - 1))


def carve(interface: Atoms, sizes: Sizes, gap_angstrom: float | None = None) -> Atoms:
    """The asperity from a deep interface (slab 1 with >= ``flat_layers`` planes, slab 2 with
    >= ``tip_layers``): laterally repeated, trimmed to the planes, the tip cut to the cap.

    Per-atom arrays: ``slab`` (1 flat, 2 tip), ``block`` (0 free, 1 flat rigid, 2 tip rigid),
    ``contact_coordinate`` (y − y_apex or r, Å, in the built geometry). ``info``: ``apex``
    (x, y), ``geometry``, ``radius_angstrom``, ``plane_spacing_angstrom``.
    """
    slab = np.asarray(interface.arrays["slab"])
    z = interface.positions[:, 2]
    z1 = atomic_planes(np.where(slab == 1, z, np.nan)[slab == 1])
    z2 = atomic_planes(z[slab == 2])
    require(
        z1.max() + 1 >= sizes.flat_layers and z2.max() + 1 >= sizes.tip_layers,
        f"structure: the interface has {z1.max() + 1} and {z2.max() + 1} planes, the asperity "
        f"needs {sizes.flat_layers} and {sizes.tip_layers}",
    )
    keep = np.zeros(len(interface), dtype=bool)
    idx1 = np.flatnonzero(slab == 1)
    idx2 = np.flatnonzero(slab == 2)
    keep[idx1[z1 >= z1.max() + 1 - sizes.flat_layers]] = True
    keep[idx2[z2 < sizes.tip_layers]] = True
    base = interface[keep]
    if gap_angstrom is not None:
        s = np.asarray(base.arrays["slab"])
        lift = gap_angstrom - (base.positions[s == 2, 2].min() - base.positions[s == 1, 2].max())
        base.positions[s == 2, 2] += lift
    n1, n2 = sizes.repeats
    big = base.repeat((n1, n2, 1))
    cell2 = big.cell.array[:2, :2]
    slab = np.asarray(big.arrays["slab"])
    pos = big.positions
    spacing = plane_spacing(interface)
    tip_bottom = pos[slab == 2, 2].min()
    centre = 0.5 * (cell2[0] + cell2[1])
    facing = np.flatnonzero((slab == 2) & (pos[:, 2] < tip_bottom + 0.3))
    apex = pos[facing[np.argmin(np.linalg.norm(pos[facing, :2] - centre, axis=1))], :2].copy()
    d = contact_coordinate(pos[:, :2], apex, cell2, sizes.geometry)
    R = sizes.radius_angstrom
    z_centre = tip_bottom - 0.5 * spacing + R
    inside = (pos[:, 2] - z_centre) ** 2 + d**2 <= R * R
    # above the sphere's equator every atom of the tip body is kept (the cap's top is flat)
    inside |= pos[:, 2] >= z_centre
    keep = (slab == 1) | inside
    out = big[keep]
    cell = out.cell.array.copy()
    cell[np.abs(cell) < 1e-9] = 0.0  # a1 exactly along x: LAMMPS's frame is the caller's
    out.set_cell(cell)
    slab = np.asarray(out.arrays["slab"])
    z = out.positions[:, 2]
    block = np.zeros(len(out), dtype=int)
    block[(slab == 1) & (z < z[slab == 1].min() + sizes.rigid_angstrom - 1e-6)] = BLOCK_FLAT
    block[(slab == 2) & (z > z[slab == 2].max() - sizes.rigid_angstrom + 1e-6)] = BLOCK_TIP
    out.arrays["block"] = block
    out.arrays["contact_coordinate"] = d[keep]
    for name in ("surface", "held", "layer"):
        out.arrays.pop(name, None)
    out.info.update(
        apex=[float(apex[0]), float(apex[1])],
        geometry=sizes.geometry,
        radius_angstrom=R,
        plane_spacing_angstrom=spacing,
    )
    require(
        bool(np.any((block == 0) & (slab == 2))),
        f"asperity: rigid_angstrom {sizes.rigid_angstrom} leaves no free atom in the tip",
    )
    return out


TIPS = ("slab2", "slab1")


def flipped(interface: Atoms) -> Atoms:
    """The interface turned upside down, slab 1 on top: a rotation by 180° about x
    ((x, y, z) → (x, −y, z_min + z_max − z)), a proper rotation, so each crystal, its
    termination and the registry of the facing planes are the same; the slab labels swap.
    The cell's a2 is negated after the rotation (the same lattice, a2 back in the upper
    half-plane as LAMMPS wants). Sliding along +y here is sliding along −y there."""
    out = interface.copy()
    pos = out.positions
    pos[:, 1] *= -1.0
    pos[:, 2] = pos[:, 2].min() + pos[:, 2].max() - pos[:, 2]
    out.positions = pos
    cell = out.cell.array.copy()
    cell[1, 1] *= -1.0
    cell[1] *= -1.0
    out.set_cell(cell)
    out.arrays["slab"] = 3 - np.asarray(out.arrays["slab"])
    for name in ("surface", "held", "layer"):
        out.arrays.pop(name, None)
    return out


def oriented(interface: Atoms, tip: str) -> Atoms:
    """The interface with the tip's crystal on top: slab 2 as built (``tip="slab2"``) or the
    flipped interface (``tip="slab1"``, :func:`flipped`)."""
    require(tip in TIPS, f"tip must be one of {', '.join(TIPS)}, got {tip!r}")
    return interface if tip == "slab2" else flipped(interface)


def deep_recipe(recipe, layers: int):
    """The run's structure recipe with ``layers`` planes per slab (slab 2's own ``layers`` too).

    Raises
    ------
    InputError
        When the recipe has no ``layers`` (a finished interface file cannot be made deeper).
    """
    require(
        hasattr(recipe, "layers"),
        f"structure.kind={getattr(recipe, 'kind', '?')}: the asperity needs a recipe with "
        "layers (fcc111, crystal, slab, ...) to make the two bodies deep enough",
    )
    update = {"layers": int(layers)}
    slab2 = getattr(recipe, "slab2", None)
    if slab2 is not None and hasattr(slab2, "layers"):
        update["slab2"] = slab2.model_copy(update={"layers": int(layers)})
    return recipe.model_copy(update=update)


def build_asperity(
    recipe,
    geometry: str,
    radius_angstrom: float,
    p0_gpa_max: float,
    contact_modulus_gpa: float,
    *,
    sizes: Sizes | None = None,
    gap_angstrom: float | None = None,
    neighbours_per_atom: int = 100,
    ranks: int = 1,
    tip: str = "slab2",
    **plan,
) -> tuple[Atoms, Sizes]:
    """The asperity of ``recipe`` (the run's structure): sizes planned (or given), the atom
    count and memory (run over ``ranks`` MPI ranks) checked against the machine before
    anything is built, then carved. ``tip``: the crystal cut to the cap (:func:`oriented`)."""
    # imported here: building needs the structures core, planning does not
    from flatcontact.structures.construct import build_interface

    small = oriented(build_interface(deep_recipe(recipe, 3))[0], tip)
    spacing = plane_spacing(small)
    if sizes is None:
        sizes = plan_sizes(
            geometry,
            radius_angstrom,
            p0_gpa_max,
            contact_modulus_gpa,
            small.cell.array[:2, :2],
            spacing,
            tip_plane_spacing_angstrom=plane_spacing(small, 2),
            **plan,
        )
    per_plane = float(np.sum(np.asarray(small.arrays["slab"]) == 1)) / 3.0
    check_machine(estimate_atoms(sizes, per_plane), neighbours_per_atom, ranks=ranks)
    deep, _ = build_interface(deep_recipe(recipe, max(sizes.flat_layers, sizes.tip_layers)))
    return carve(oriented(deep, tip), sizes, gap_angstrom), sizes
