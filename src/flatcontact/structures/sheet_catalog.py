"""The built-in monolayers of the ``sheets`` recipe (graphene, h-BN, MoS₂): their names, lattice
constants and bulk interlayer distances, as plain data.

The settings check a sheet name against :data:`BUILTIN_SHEETS` without building anything;
:mod:`.sheets` builds the sheets from it.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class SheetData:
    """A built-in monolayer: ASE builder arguments and its bulk interlayer distance."""

    formula: str
    a_angstrom: float
    interlayer_angstrom: float
    thickness_angstrom: float = 0.0


BUILTIN_SHEETS: dict[str, SheetData] = {
    "graphene": SheetData("C2", 2.46, 3.35),
    "h-BN": SheetData("BN", 2.504, 3.33),
    "MoS2": SheetData("MoS2", 3.16, 6.15, 3.17),
}
