"""Slab materials as stackable sources: a 2D sheet, a 3D crystal cut, an fcc(111) metal.

A :class:`SlabSource` makes a slab of any number of layers in the material's natural
stacking (``arrays["layer"]`` 1..n from the bottom) on its primitive in-plane cell, and
knows the natural distance between two adjacent layers (``spacing_by="planes"``: between
the layers' mean planes, the interlayer distance of sheets; ``"atoms"``: between the
highest atom of one layer and the lowest of the next, the bulk gap of a crystal cut).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from ase import Atoms

from flatcontact.structures.crystal import crystal_slab, fcc111_slab, passivated_crystal_slab
from flatcontact.structures.sheets import parse_stacking, stack_sheets


@dataclass
class SlabSource:
    """One slab material (see the module docstring)."""

    material: str
    make: Callable[[int], Atoms]
    spacing_angstrom: float
    spacing_by: str
    record: dict = field(default_factory=dict)
    #: slab 2 made of slab 1's material (a passivated copy), not another material
    same_material: bool = False
    _one: Atoms | None = None

    @property
    def unit(self) -> Atoms:
        """One layer of the material (cached)."""
        if self._one is None:
            self._one = self.make(1)
        return self._one

    @property
    def cell2(self) -> np.ndarray:
        """In-plane primitive cell (2×2 rows, Å)."""
        return self.unit.cell.array[:2, :2].copy()

    @property
    def atoms_per_layer(self) -> int:
        return len(self.unit)


def sheet_source(
    sheet: Atoms,
    material: str,
    stacking: str,
    interlayer_angstrom: float,
    record: dict,
    field_name: str,
) -> SlabSource:
    """A stack of ``sheet`` monolayers with ``stacking`` letters and interlayer distance."""
    parse_stacking(stacking, field_name)
    return SlabSource(
        material=material,
        make=lambda n: stack_sheets(sheet, n, stacking, interlayer_angstrom, field_name),
        spacing_angstrom=interlayer_angstrom,
        spacing_by="planes",
        record=record,
    )


def crystal_source(
    oriented, termination: int, material: str, record: dict, field_name: str
) -> SlabSource:
    """Cuts of an oriented bulk crystal at one termination (bulk repeats as layers)."""

    def make(n: int) -> Atoms:
        return crystal_slab(oriented, n, termination, field_name)

    two = make(2)
    layer = np.asarray(two.arrays["layer"])
    z = two.positions[:, 2]
    gap = float(z[layer == 2].min() - z[layer == 1].max())
    return SlabSource(material, make, gap, "atoms", record)


def passivated_crystal_source(
    oriented,
    termination: int,
    faces: tuple[str, ...],
    species: str,
    material: str,
    record: dict,
    field_name: str,
    same_material: bool = False,
) -> SlabSource:
    """Cuts of an oriented bulk crystal with ``faces`` (bottom, top) passivated by ``species``.

    The spacing is the bulk's gap (as :func:`crystal_source`); a recipe with a passivated face
    gives its own gap. ``record["passivation"]`` is the record of a one-layer slab.
    """

    def make(n: int) -> Atoms:
        return passivated_crystal_slab(oriented, n, termination, faces, species, field_name)[0]

    _, passivation = passivated_crystal_slab(oriented, 1, termination, faces, species, field_name)
    plain = crystal_source(oriented, termination, material, record, field_name)
    return SlabSource(
        material,
        make,
        plain.spacing_angstrom,
        "atoms",
        {**record, "passivation": passivation},
        same_material,
    )


def fcc111_source(element: str, a_angstrom: float | None, record: dict) -> SlabSource:
    """fcc(111) close-packed planes in ABC stacking, spacing a/√3."""
    _, a = fcc111_slab(element, 1, a_angstrom)
    record = {**record, "a_angstrom": a}
    return SlabSource(
        material=f"{element}(111)",
        make=lambda n: fcc111_slab(element, n, a)[0],
        spacing_angstrom=a / np.sqrt(3.0),
        spacing_by="planes",
        record=record,
    )
