"""SiO2 polymorphs for training sets, built from published crystallographic data.

Every entry states the source of its space group, lattice parameters and
Wyckoff positions, and the experimental density that :func:`check_polymorph`
compares with. Settings are ASE's default for the space group
(:func:`ase.spacegroup.crystal`).

=============  ======  ==========================================================
polymorph      Si CN   source
=============  ======  ==========================================================
alpha_quartz   4       Levien, Prewitt & Weidner, Am. Mineral. 65, 920 (1980);
                       positions in ASE's P3_221 setting (see NOTES: the usual
                       Si (0.4697, 0, 0) origin gives a wrong 12-atom cell here)
cristobalite   4       alpha-cristobalite, Downs & Palmer, Am. Mineral. 79, 9 (1994)
coesite        4       Levien & Prewitt, Am. Mineral. 66, 324 (1981), 1 atm
                       (AMCSD 0000816)
stishovite     6       Ross, Shu, Hazen & Gasparik, Am. Mineral. 75, 739 (1990),
                       P = 0 (AMCSD 0001306)
=============  ======  ==========================================================
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from ase import Atoms
from ase.neighborlist import neighbor_list
from ase.spacegroup import crystal

from flatcontact.foundation.errors import InputError

#: Si-O bond cutoff used to count coordination (Å).
SI_O_BOND_CUTOFF = 2.0
#: g/mol of SiO2 and Avogadro's number, for densities.
_AMU_TO_G = 1.66053906660e-24
_A3_TO_CM3 = 1.0e-24


@dataclass(frozen=True)
class Polymorph:
    """Crystallographic description of one SiO2 polymorph."""

    spacegroup: int
    cellpar: tuple[float, float, float, float, float, float]
    basis: tuple[tuple[float, float, float], ...]
    symbols: tuple[str, ...]
    density_g_cm3: float
    si_coordination: int
    source: str


POLYMORPHS: dict[str, Polymorph] = {
    "alpha_quartz": Polymorph(
        154,
        (4.916, 4.916, 5.405, 90.0, 90.0, 120.0),
        ((0.4697, 0.0, 2.0 / 3.0), (0.4135, 0.2669, 0.7858)),
        ("Si", "O"),
        2.648,
        4,
        "Levien, Prewitt & Weidner, Am. Mineral. 65, 920 (1980)",
    ),
    "cristobalite": Polymorph(
        92,
        (4.9709, 4.9709, 6.9278, 90.0, 90.0, 90.0),
        ((0.3003, 0.3003, 0.0), (0.2392, 0.1044, 0.1787)),
        ("Si", "O"),
        2.334,
        4,
        "Downs & Palmer, Am. Mineral. 79, 9 (1994)",
    ),
    "coesite": Polymorph(
        15,
        (7.1356, 12.3692, 7.1736, 90.0, 120.34, 90.0),
        (
            (0.14033, 0.10833, 0.07227),
            (0.50682, 0.15799, 0.54077),
            (0.0, 0.0, 0.0),
            (0.5, 0.1163, 0.75),
            (0.2660, 0.1234, 0.9401),
            (0.3114, 0.1038, 0.3282),
            (0.0172, 0.2117, 0.4782),
        ),
        ("Si", "Si", "O", "O", "O", "O", "O"),
        2.921,
        4,
        "Levien & Prewitt, Am. Mineral. 66, 324 (1981); AMCSD 0000816",
    ),
    "stishovite": Polymorph(
        136,
        (4.1801, 4.1801, 2.6678, 90.0, 90.0, 90.0),
        ((0.0, 0.0, 0.0), (0.3067, 0.3067, 0.0)),
        ("Si", "O"),
        4.281,
        6,
        "Ross, Shu, Hazen & Gasparik, Am. Mineral. 75, 739 (1990); AMCSD 0001306",
    ),
}


def build_polymorph(name: str) -> Atoms:
    """Conventional cell of the SiO2 polymorph ``name`` (one of :data:`POLYMORPHS`)."""
    if name not in POLYMORPHS:
        raise InputError(f"polymorph '{name}': expected one of {sorted(POLYMORPHS)}")
    p = POLYMORPHS[name]
    atoms = crystal(
        list(p.symbols), basis=list(p.basis), spacegroup=p.spacegroup, cellpar=list(p.cellpar)
    )
    atoms.info["polymorph"] = name
    return atoms


def density_g_cm3(atoms: Atoms) -> float:
    """Mass density (g/cm³)."""
    return float(atoms.get_masses().sum() * _AMU_TO_G / (atoms.get_volume() * _A3_TO_CM3))


def coordination(atoms: Atoms, cutoff: float = SI_O_BOND_CUTOFF) -> np.ndarray:
    """Number of unlike (Si-O / O-Si) neighbours within ``cutoff`` (Å) of every atom."""
    i, j = neighbor_list("ij", atoms, cutoff)
    symbols = np.array(atoms.get_chemical_symbols())
    unlike = symbols[i] != symbols[j]
    return np.bincount(i[unlike], minlength=len(atoms))


def check_polymorph(name: str, atoms: Atoms | None = None) -> dict:
    """Density, stoichiometry and coordination of a built polymorph vs its reference data."""
    atoms = build_polymorph(name) if atoms is None else atoms
    p = POLYMORPHS[name]
    symbols = np.array(atoms.get_chemical_symbols())
    cn = coordination(atoms)
    return {
        "n_atoms": len(atoms),
        "o_per_si": float((symbols == "O").sum() / (symbols == "Si").sum()),
        "density_g_cm3": density_g_cm3(atoms),
        "density_ref_g_cm3": p.density_g_cm3,
        "si_coordination": sorted(set(cn[symbols == "Si"].tolist())),
        "o_coordination": sorted(set(cn[symbols == "O"].tolist())),
        "si_coordination_ref": p.si_coordination,
        "min_distance_angstrom": float(neighbor_list("d", atoms, 3.0).min()),
    }
