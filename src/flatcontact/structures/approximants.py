"""Commensurate approximant cells of an incommensurate contact, smallest first.

An incommensurate contact (one hexagonal lattice twisted against itself by a generic angle,
or two lattices of different constants) has no periodic cell. A commensurate approximant is
a periodic cell close to it: a commensurate twist angle near the target, or a coincidence
lattice that strains the slabs a little. Each :class:`Approximant` carries the
``structure:`` keys that build exactly its cell through the normal build path
(:func:`flatcontact.structures.construct.build_interface`).

Same lattice (slab 2 of slab 1's material; recipes ``sheets``, ``crystal``, ``fcc111``)
    The commensurate twist (m, n), 1 ≤ m < n (Lopes dos Santos, Peres & Castro Neto, PRL 99,
    256802 (2007); Shallcross, Sharma, Kandelaki & Pankratov, PRB 81, 165105 (2010)):
    cos θ = (m² + 4mn + n²) / (2(m² + mn + n²)), θ ∈ (0°, 60°), built on a supercell of
    m² + mn + n² primitive cells per slab layer (:func:`~flatcontact.structures.match.twist_match`).
    Only coprime (m, n) enter (a common factor g repeats the cell of (m/g, n/g) g² times).
    This is the smallest cell of the twist when m − n is not a multiple of 3; when it is
    (e.g. (1, 4), 38.213° = 60° − 21.787°) the coincidence lattice is 3 times smaller than
    the cell built, (m² + mn + n²)/3 cells (Shallcross et al.), and the sequence counts
    the atoms of the cell that is built.

    * with a target ``twist_deg``: among all coprime (m, n) of at most ``max_atoms``
      atoms, ordered by size, every cell whose angle error |θ − target| is smaller than
      that of all smaller cells (the best approximants), at most ``max_cells``;
    * without a target: the (n, n + 1) family, n = 1, 2, ... (21.787°, 13.174°, 9.430°,
      7.341°, ...: for a given small angle the smallest cell; θ → 0, the moiré limit):
      angle and size change together.

Two materials (``slab2`` of another material, any ``rotate_deg``)
    Zur & McGill coincidence lattices (J. Appl. Phys. 55, 378 (1984); pymatgen's
    ``ZSLGenerator``) for each strain bound of the decreasing ladder ``strain_percent``:
    the smallest cell (fewest atoms, then least strain) with every principal strain of both
    slabs within the bound (:func:`~flatcontact.structures.match.coincidence_match`).
    Without ``twist_deg`` any rotation of slab 2 is accepted (the cells of the ladder may
    differ in orientation); with it only cells whose rotation of slab 2 is within
    ``angle_tolerance_deg`` of the target modulo the rotation symmetry of slab 2's lattice
    (60° hexagonal, 90° square, else 180°), e.g. 0 for the aligned pair whose mismatch
    alone makes it incommensurate; these come from a direct search over compact cells
    (:func:`~flatcontact.structures.match.oriented_coincidence_match`: reduced vectors no
    longer than √(2·A_max)), not from the ZSL enumeration. ``rotate_deg`` (a symmetry of slab 2's lattice) does
    not change the lattice's orientation and enters ``twist_deg`` only as an offset.
    A bound the previous cell already meets gives that cell again and is skipped; a bound
    with no cell within ``max_atoms`` ends the ladder. The override names the supercells
    explicitly (``match.slab1_supercell``, ``match.slab2_supercell``), so it builds that
    cell whatever the search would pick.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from flatcontact.config.approximants import DEFAULT_STRAIN_LADDER_PERCENT, ApproximantSettings
from flatcontact.foundation.errors import InputError, require
from flatcontact.foundation.limits import SearchTimeout
from flatcontact.structures.cell2d import is_hexagonal
from flatcontact.structures.construct import slab_sources
from flatcontact.structures.match import (
    atom_count,
    coincidence_match,
    orientation_error_deg,
    strain_and_rotation,
    twist_angle_deg,
    twist_match,
)
from flatcontact.structures.recipe import (
    SECTION,
    CrystalRecipe,
    Fcc111Recipe,
    SheetsRecipe,
    parse_recipe,
)

#: Name of the settings section, the prefix of every field named in an error.
APPROXIMANTS = "approximants"

#: Recipe kinds that have a second slab on a common in-plane cell (twist, coincidence).
PAIR_RECIPES = (SheetsRecipe, CrystalRecipe, Fcc111Recipe)


@dataclass(frozen=True)
class Approximant:
    """One commensurate approximant cell (see the module docstring).

    Attributes
    ----------
    label
        ``twist-<m>-<n>`` or ``zsl-<bound>pct`` (the strain bound that selected it).
    kind
        ``twist`` (same lattice) or ``coincidence`` (two materials).
    n_atoms
        Atoms of the interface built from ``structure_override``.
    cells_per_layer
        Primitive in-plane cells of slab 1 in the common cell (det P1): the cell area in
        units of slab 1's primitive cell.
    area_angstrom2
        Area of the common in-plane cell (Å²).
    twist_deg
        Rotation of slab 2's lattice against slab 1's in this cell (counter-clockwise, deg):
        θ of the (m, n) twist; for two materials ``rotate_deg`` plus the rotation the
        coincidence map puts on slab 2.
    angle_error_deg
        ``twist_deg`` − target (0 when there is no target angle).
    strain_percent_slab1, strain_percent_slab2
        Principal strains (ascending, %) the common cell puts on each slab (0 for a twist).
    structure_override
        Keys merged into the run configuration's ``structure:`` section (nested mappings
        merged key by key, :func:`flatcontact.config.merge.merge_config`) that build exactly
        this cell.
    """

    label: str
    kind: str
    n_atoms: int
    cells_per_layer: int
    area_angstrom2: float
    twist_deg: float
    angle_error_deg: float
    strain_percent_slab1: tuple[float, float]
    strain_percent_slab2: tuple[float, float]
    structure_override: dict


def coprime_twists(max_cells: int) -> list[tuple[int, int]]:
    """Every coprime (m, n), 1 ≤ m < n, with m² + mn + n² ≤ ``max_cells``, smallest cell first
    (ties: smaller m first). (0, 1), 60°, is the untwisted lattice and is left out."""
    out = []
    n = 2
    while n * n <= max_cells:
        for m in range(1, n):
            if math.gcd(m, n) == 1 and m * m + m * n + n * n <= max_cells:
                out.append((m, n))
        n += 1
    return sorted(out, key=lambda mn: (mn[0] ** 2 + mn[0] * mn[1] + mn[1] ** 2, mn[0]))


def twist_cells(target_deg: float | None, max_cells_per_layer: int) -> list[tuple[int, int]]:
    """The (m, n) of the twist sequence with at most ``max_cells_per_layer`` primitive cells
    per layer (module docstring): the record-setters of |θ − target|, or the (n, n + 1) family
    without a target."""
    if target_deg is None:
        out, n = [], 1
        while 3 * n * n + 3 * n + 1 <= max_cells_per_layer:
            out.append((n, n + 1))
            n += 1
        return out
    out, best = [], math.inf
    for m, n in coprime_twists(max_cells_per_layer):
        error = abs(twist_angle_deg(m, n) - target_deg)
        if error < best - 1e-9:
            out.append((m, n))
            best = error
    return out


def _recipe(structure: Any) -> Any:
    recipe = parse_recipe(structure) if isinstance(structure, dict) else structure
    require(
        isinstance(recipe, PAIR_RECIPES),
        f"{SECTION}.kind={getattr(recipe, 'kind', None)!r}: approximant cells need a sheets, "
        "crystal or fcc111 recipe (two slabs on a common in-plane cell)",
    )
    return recipe


def approximant_sequence(structure: Any, settings: ApproximantSettings) -> list[Approximant]:
    """The commensurate approximants of ``structure``'s contact, smallest first.

    Parameters
    ----------
    structure
        The run configuration's ``structure:`` section: a dict or a recipe model
        (:data:`flatcontact.structures.recipe.StructureRecipe`, file paths resolved) of kind
        ``sheets``, ``crystal`` or ``fcc111``. Its own ``twist`` and ``match`` are replaced
        by each approximant's override.
    settings
        The ``approximants:`` section.

    Returns
    -------
    At most ``settings.max_cells`` cells of at most ``settings.max_atoms`` atoms each,
    atom count increasing; for a target twist the angle error decreases strictly along
    the list, for two materials the largest strain does. Every check runs before the
    coincidence search; a bad value is a one-line InputError naming the field.
    """
    recipe = _recipe(structure)
    s1, s2, n1, n2 = slab_sources(recipe)
    other = s2 is not None and not s2.same_material
    src2 = s2 or s1
    na1, na2 = len(s1.make(n1)), len(src2.make(n2))  # atoms per primitive cell of each slab
    if other and not np.allclose(s1.cell2, src2.cell2, atol=1e-6):
        return _coincidence_sequence(recipe, s1.cell2, src2.cell2, na1, na2, settings)
    require(
        not other,
        f"{SECTION}.slab2: {src2.material} has the same in-plane lattice as {s1.material}; a "
        "twist needs one material in both slabs and there is no mismatch to strain away",
    )
    require(
        settings.strain_percent is None,
        f"{APPROXIMANTS}.strain_percent: both slabs have one lattice (no lattice mismatch to "
        "strain away); give approximants.twist_deg or leave it out for the (n, n+1) family",
    )
    require(
        is_hexagonal(s1.cell2),
        f"{APPROXIMANTS}: commensurate twist cells need a hexagonal in-plane lattice; "
        f"{s1.material} is not",
    )
    return _twist_sequence(recipe, s1.cell2, na1, na2, settings)


def _twist_sequence(recipe, cell2, na1: int, na2: int, settings) -> list[Approximant]:
    out = []
    for m, n in twist_cells(settings.twist_deg, settings.max_atoms // (na1 + na2)):
        match, theta = twist_match(cell2, m, n, field=f"{APPROXIMANTS}.twist_deg")
        n_atoms = atom_count(match, na1, na2)
        if n_atoms > settings.max_atoms:  # pragma: no cover - the cell bound ensures it
            break
        out.append(
            _approximant(
                f"twist-{m}-{n}",
                match,
                cell2,
                cell2,
                na1,
                na2,
                theta,
                0.0 if settings.twist_deg is None else theta - settings.twist_deg,
                {"twist": [m, n], "match": {"max_atoms": settings.max_atoms}},
            )
        )
        if len(out) == settings.max_cells:
            break
    require(
        bool(out),
        f"{APPROXIMANTS}.max_atoms={settings.max_atoms}: no twisted cell fits (the smallest, "
        f"(1, 2) 21.787°, has {7 * (na1 + na2)} atoms)",
    )
    return out


def _coincidence_sequence(recipe, a1, a2, na1: int, na2: int, settings) -> list[Approximant]:
    ladder = settings.strain_percent or list(DEFAULT_STRAIN_LADDER_PERCENT)
    target = settings.twist_deg
    orientation = None if target is None else (target, settings.angle_tolerance_deg)
    out: list[Approximant] = []
    for bound in ladder:
        try:
            match = coincidence_match(
                a1,
                a2,
                na1,
                na2,
                max_strain=bound / 100.0,
                max_atoms=settings.max_atoms,
                strain_on=settings.strain_on,
                field=f"{APPROXIMANTS}.strain_percent",
                orientation_deg=orientation,
            )
        except SearchTimeout:
            raise  # not "no cell": the search ran out of time, and says which setting
        except InputError:
            if not out:
                within = (
                    ""
                    if orientation is None
                    else f" at {target:g} ± {settings.angle_tolerance_deg:g}° (twist_deg)"
                )
                raise InputError(
                    f"{APPROXIMANTS}.strain_percent={bound:g}: no coincidence cell of the two "
                    f"lattices within {bound:g}% strain and {settings.max_atoms} atoms{within} "
                    "(raise approximants.max_atoms or start the ladder at a larger bound)"
                ) from None
            break
        if out and _same_cell(match, out[-1]):
            continue
        rotation = strain_and_rotation(match.deformation(2, a2))[1]
        error = 0.0 if target is None else orientation_error_deg(rotation, target, a2)
        override = {
            "match": {
                "max_strain_percent": bound,
                "max_atoms": settings.max_atoms,
                "strain_on": settings.strain_on,
                "slab1_supercell": match.p1.tolist(),
                "slab2_supercell": match.p2.tolist(),
            }
        }
        out.append(
            _approximant(
                f"zsl-{bound:g}pct",
                match,
                a1,
                a2,
                na1,
                na2,
                _wrapped(recipe.rotate_deg + rotation),
                error,
                override,
            )
        )
        if len(out) == settings.max_cells:
            break
    return out


def _wrapped(angle_deg: float) -> float:
    """``angle_deg`` in (−180°, 180°]."""
    out = -((-angle_deg + 180.0) % 360.0 - 180.0)
    return 180.0 if out == -180.0 else out + 0.0


def _same_cell(match, previous: Approximant) -> bool:
    m = previous.structure_override["match"]
    return match.p1.tolist() == m["slab1_supercell"] and match.p2.tolist() == m["slab2_supercell"]


def _approximant(label, match, a1, a2, na1, na2, twist, error, override) -> Approximant:
    rec = match.report(a1, a2, na1, na2)
    return Approximant(
        label=label,
        kind=match.kind,
        n_atoms=int(rec["n_atoms"]),
        cells_per_layer=round(abs(float(np.linalg.det(match.p1)))),
        area_angstrom2=abs(float(np.linalg.det(match.cell))),
        twist_deg=float(twist),
        angle_error_deg=float(error),
        strain_percent_slab1=tuple(float(s) + 0.0 for s in rec["slab1_strain_percent"]),
        strain_percent_slab2=tuple(float(s) + 0.0 for s in rec["slab2_strain_percent"]),
        structure_override=override,
    )
