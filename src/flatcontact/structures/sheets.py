"""2D monolayers (built in or read from a file) and stacks of them.

Built-in monolayers (``ase.build.graphene`` / ``ase.build.mx2``), lattice constants and
the interlayer distance of their bulk (distance between the mean planes of adjacent
layers):

============  ==========  =====================  ==========================================
name          a (Å)       interlayer (Å)         source
============  ==========  =====================  ==========================================
graphene      2.46        3.35                   graphite (Baskin & Meyer, PR 100, 544 (1955))
h-BN          2.504       3.33                   h-BN (Pease, Acta Cryst. 5, 356 (1952))
MoS2          3.16        6.15 (Mo–Mo)           2H-MoS₂ (Wakabayashi et al., PRB 12, 659
                                                 (1975)); S–S height 3.17 Å within a layer
============  ==========  =====================  ==========================================

Stacking letters
----------------
A stack of layers is written as a sequence of letters, one per layer, repeated
cyclically: ``A`` = the monolayer as given, ``B`` = shifted by (2/3, 1/3) of (a1, a2),
``C`` = by (1/3, 2/3) (the two other high-symmetry sites of a hexagonal lattice in the
120° convention); a prime (``A'``, ``B'``, ``C'``) means the layer rotated by 180° about
the z axis through the midpoint of its shortest bond between unlike atoms (any bond for
one species) before the shift: B and N (Mo and S) exchange sites, so ``AA'`` is h-BN's
AA′ (B over N) and 2H-MoS₂ (Mo over S), while graphene's ``A'`` is ``A``. ``B``/``C`` need
a hexagonal lattice.
"""

from __future__ import annotations

import re

import numpy as np
from ase import Atoms
from ase.build import graphene, mx2
from ase.neighborlist import neighbor_list

from flatcontact.foundation.errors import InputError
from flatcontact.structures.cell2d import (
    is_hexagonal,
    lattice_is_invariant,
    rotation,
    standard_slab,
)
from flatcontact.structures.layers import bonded_components
from flatcontact.structures.sheet_catalog import BUILTIN_SHEETS

_TOKEN = re.compile(r"([ABC])('?)")
#: fractional in-plane offsets of the stacking letters (120° hexagonal convention)
_OFFSETS = {"A": (0.0, 0.0), "B": (2.0 / 3.0, 1.0 / 3.0), "C": (1.0 / 3.0, 2.0 / 3.0)}


def builtin_sheet(name: str) -> Atoms:
    """The built-in monolayer ``name`` (see :data:`BUILTIN_SHEETS`) in the standard cell."""
    if name not in BUILTIN_SHEETS:
        raise InputError(f"sheet '{name}': expected one of {', '.join(BUILTIN_SHEETS)} or a file")
    data = BUILTIN_SHEETS[name]
    if data.formula == "MoS2":
        atoms = mx2("MoS2", kind="2H", a=data.a_angstrom, thickness=data.thickness_angstrom)
    else:
        atoms = graphene(formula=data.formula, a=data.a_angstrom)
    atoms.cell[2] = (0.0, 0.0, 1.0)
    return standard_slab(atoms)


def check_sheet(atoms: Atoms, source: str) -> Atoms:
    """``atoms`` as a standard monolayer cell, or InputError if it is not one bonded sheet.

    The sheet must lie in the plane of cell vectors 1 and 2 (periodic along both).
    """
    atoms = atoms.copy()
    atoms.pbc = (True, True, False)
    try:
        atoms = standard_slab(atoms)
    except InputError as exc:
        raise InputError(f"{source}: {exc}") from None
    labels = bonded_components(atoms)
    if labels.max() > 0:
        raise InputError(
            f"{source}: {labels.max() + 1} separate bonded pieces in the cell; expected one "
            "2D sheet (one layer) periodic along cell vectors 1 and 2"
        )
    return atoms


def parse_stacking(stacking: str, field: str = "stacking") -> list[tuple[str, bool]]:
    """``"AB"`` → [("A", False), ("B", False)]; ``"AA'"`` → [("A", False), ("A", True)]."""
    text = stacking.replace("′", "'").strip()
    tokens = _TOKEN.findall(text)
    if not text or "".join(a + p for a, p in tokens) != text:
        raise InputError(
            f"{field}='{stacking}': expected letters A, B, C, each optionally primed (e.g. AB, ABC, AA')"
        )
    return [(a, bool(p)) for a, p in tokens]


def rotation_centre(sheet: Atoms) -> np.ndarray:
    """In-plane midpoint of the sheet's shortest bond between unlike atoms (any bond if one species)."""
    i, j, d, vec = neighbor_list("ijdD", sheet, 4.0)
    numbers = sheet.numbers
    unlike = numbers[i] != numbers[j]
    pick = unlike if unlike.any() else np.ones_like(unlike)
    if not pick.any():
        return sheet.positions[0, :2].copy()
    k = np.flatnonzero(pick)[np.argmin(d[pick])]
    return sheet.positions[i[k], :2] + 0.5 * vec[k, :2]


def rotate_in_plane(atoms: Atoms, angle_deg: float, centre_xy: np.ndarray) -> Atoms:
    """``atoms`` rotated about the z axis through ``centre_xy``, kept in the same cell (wrapped).

    InputError unless the rotation maps the in-plane lattice onto itself.
    """
    rot = rotation(angle_deg)
    if not lattice_is_invariant(atoms.cell.array[:2, :2], rot):
        raise InputError(
            f"rotation by {angle_deg:g}°: the in-plane lattice is not mapped onto itself; "
            "use a commensurate twist (twist: [m, n]) or a coincidence lattice (slab2)"
        )
    out = atoms.copy()
    xy = out.positions[:, :2] - centre_xy
    out.positions[:, :2] = xy @ rot.T + centre_xy
    out.wrap()
    return out


def stack_sheets(
    sheet: Atoms, n_layers: int, stacking: str, interlayer_angstrom: float, field: str = "stacking"
) -> Atoms:
    """``n_layers`` copies of ``sheet`` stacked along z with ``stacking`` letters (cyclic).

    Layer k's mean height is (k − 1)·``interlayer_angstrom``; ``arrays["layer"]`` = k.
    """
    tokens = parse_stacking(stacking, field)
    hexagonal = is_hexagonal(sheet.cell.array)
    if not hexagonal and any(letter != "A" for letter, _ in tokens):
        raise InputError(
            f"{field}='{stacking}': B and C need a hexagonal lattice; this sheet's is not"
        )
    if not interlayer_angstrom > 0:
        raise InputError(f"interlayer_angstrom={interlayer_angstrom}: expected > 0")
    centre = rotation_centre(sheet)
    cell = sheet.cell.array
    z0 = sheet.positions[:, 2].mean()
    parts = []
    for k in range(n_layers):
        letter, primed = tokens[k % len(tokens)]
        layer = rotate_in_plane(sheet, 180.0, centre) if primed else sheet.copy()
        fa, fb = _OFFSETS[letter]
        layer.positions[:, :2] += fa * cell[0, :2] + fb * cell[1, :2]
        layer.positions[:, 2] += k * interlayer_angstrom - z0
        layer.arrays["layer"] = np.full(len(layer), k + 1)
        parts.append(layer)
    stack = parts[0]
    for part in parts[1:]:
        stack += part
    stack.wrap()
    return stack
