"""Crystals that are not what they claim: disordered CIF sites and atoms a symmetry expansion
put on top of each other.

A CIF may describe a disordered crystal: a site occupied with probability < 1 (Cu at 0.3), or
a mixed site (Cu 0.5 and Ni 0.5 at one position). ASE's reader builds one full atom per site
(the majority species of a mixed one), so a 30 %-occupied crystal became fcc Cu and
Cu₀.₅Ni₀.₅ became pure Ni, silently. flatcontact builds ordered slabs only: such a site is
refused in one line naming it (:func:`check_cif_sites`), before the file is read; a user who
wants an alloy or a defective crystal makes the ordered supercell they mean and gives that.

A symmetry expansion (a CIF's space group applied to its sites) can also put two atoms closer
than any bond: a site given twice, or a position not on the special position it was meant to
be on. :func:`check_bond_lengths` refuses, before any relaxation, two atoms closer than
:data:`BOND_FRACTION` of their covalent bond length (ASE's covalent radii: Cu–Cu 2.64 Å, so
1.32 Å; H–H 0.62 Å, so 0.31 Å, below H₂'s 0.74 Å): a relaxation would push them apart by
tens of Å (a CIF with atoms 0.51 Å apart "relaxed" into slabs 50 Å apart).
"""

from __future__ import annotations

import os
import warnings
from collections import defaultdict

import numpy as np
from ase import Atoms
from ase.data import atomic_numbers, covalent_radii
from ase.neighborlist import neighbor_list

from flatcontact.foundation.errors import InputError

#: Occupancy within this of 1 is a full site (CIFs round to 2-4 digits).
OCCUPANCY_TOLERANCE = 0.01
#: Two sites whose fractional coordinates agree to this (mod 1) are one site.
SAME_SITE_FRACTIONAL = 1e-3
#: Two atoms closer than this fraction of the sum of their covalent radii are refused.
BOND_FRACTION = 0.5


def _number(text) -> float:
    """A CIF number without its standard uncertainty: ``0.30(2)`` → 0.30; ``.``/``?`` → 1."""
    if isinstance(text, int | float):
        return float(text)
    text = str(text).split("(")[0].strip()
    if text in (".", "?", ""):
        return 1.0
    return float(text)


def check_cif_sites(path: str | os.PathLike[str], label: str) -> None:
    """Refuse a CIF with a partly occupied or a mixed site (one line naming the site).

    Raises
    ------
    InputError
        ``label``, the site label(s), the species and occupancies, what to do instead.
    """
    from ase.io.cif import parse_cif

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            blocks = [b for b in parse_cif(str(path)) if b.has_structure()]
    except Exception:  # the reader proper says what it cannot read
        return
    for block in blocks:
        labels = block.get("_atom_site_label")
        if labels is None:
            continue
        symbols = block.get("_atom_site_type_symbol") or labels
        occupancies = block.get("_atom_site_occupancy") or [1.0] * len(labels)
        xyz = [block.get(f"_atom_site_fract_{c}") for c in "xyz"]
        try:
            occ = [_number(o) for o in occupancies]
            frac = (
                np.array([[_number(v) for v in axis] for axis in xyz]).T
                if all(a is not None for a in xyz)
                else None
            )
        except (TypeError, ValueError):
            return  # malformed numbers: ASE's reader refuses them
        if frac is not None:
            _refuse_mixed(frac, labels, symbols, occ, label)
        for name, sym, o in zip(labels, symbols, occ, strict=False):
            if abs(o - 1.0) > OCCUPANCY_TOLERANCE:
                raise InputError(
                    f"{label}: site {name} ({sym}) has occupancy {o:g}: a partly occupied "
                    "site; flatcontact builds ordered crystals only: give the ordered cell "
                    "you mean (a supercell with the vacancies placed), every site at "
                    "occupancy 1"
                )


def _refuse_mixed(frac: np.ndarray, labels, symbols, occ, label: str) -> None:
    groups: dict[tuple, list[int]] = defaultdict(list)
    steps = round(1 / SAME_SITE_FRACTIONAL)
    for k, f in enumerate(frac):
        key = tuple(np.round(np.mod(f, 1.0) * steps).astype(int) % steps)
        groups[key].append(k)
    for members in groups.values():
        if len(members) > 1:
            parts = ", ".join(f"{labels[k]} {symbols[k]} {occ[k]:g}" for k in members)
            where = ", ".join(f"{x:g}" for x in frac[members[0]])
            raise InputError(
                f"{label}: sites {' and '.join(labels[k] for k in members)} share the position "
                f"({where}): a mixed site ({parts}); flatcontact builds ordered crystals only: "
                "give the ordered cell you mean (a supercell with each species on its own site)"
            )


def check_bond_lengths(atoms: Atoms, label: str) -> None:
    """Refuse two atoms (periodic images included) closer than :data:`BOND_FRACTION` of their
    covalent bond length (one line naming both, their distance and the bound)."""
    radii = np.array(
        [BOND_FRACTION * covalent_radii[atomic_numbers[s]] for s in atoms.get_chemical_symbols()]
    )
    probe = atoms.copy()
    probe.calc = None
    i, j, d = neighbor_list("ijd", probe, radii, self_interaction=False)
    if not len(d):
        return
    k = int(np.argmin(d))
    sym = probe.get_chemical_symbols()
    bond = (radii[i[k]] + radii[j[k]]) / BOND_FRACTION
    raise InputError(
        f"{label}: atoms {i[k] + 1} ({sym[i[k]]}) and {j[k] + 1} ({sym[j[k]]}) are "
        f"{d[k]:.3g} Å apart after the file's symmetry expansion, closer than "
        f"{BOND_FRACTION:g} of their covalent bond length ({bond:.3g} Å): a site given twice "
        "or off its special position; check the file's coordinates and space group"
    )
