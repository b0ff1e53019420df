"""Bulk crystals: α-quartz in ASE's setting of space group P3₂21 (No. 154).

Wyckoff positions (ASE's origin choice for No. 154): Si 3a at
(0.4697, 0, 2/3), O 6c at (0.4135, 0.2669, 0.7858). The often-quoted
Si (0.4697, 0, 0) / O (0.4135, 0.2669, 0.1191) belong to a different origin and
give a wrong 12-atom cell in ASE's setting. Lattice: a = 4.916 Å, c = 5.405 Å
(Levien, Prewitt & Weidner, Am. Mineral. 65, 920 (1980)).
"""

from __future__ import annotations

import numpy as np
from ase import Atoms
from ase.spacegroup import crystal

from flatcontact.foundation.errors import require

#: Experimental α-quartz lattice constants (Å), Levien et al. 1980.
QUARTZ_A_ANGSTROM = 4.916
QUARTZ_C_ANGSTROM = 5.405
#: Fractional Wyckoff positions in ASE's setting of P3₂21 (No. 154).
QUARTZ_SI_3A = (0.4697, 0.0, 2.0 / 3.0)
QUARTZ_O_6C = (0.4135, 0.2669, 0.7858)
QUARTZ_SPACEGROUP = 154


def alpha_quartz(
    a_angstrom: float = QUARTZ_A_ANGSTROM, c_angstrom: float = QUARTZ_C_ANGSTROM
) -> Atoms:
    """Conventional hexagonal α-quartz cell (3 Si + 6 O).

    Parameters
    ----------
    a_angstrom, c_angstrom
        Lattice constants in Å. The fractional coordinates are kept, so a
        potential's own relaxed lattice can be used by passing its (a, c).

    Returns
    -------
    ase.Atoms
        9 atoms; cell vectors a1 = (a, 0, 0), a2 = (-a/2, a√3/2, 0), a3 = (0, 0, c);
        fully periodic. Si–O bonds 1.605 and 1.614 Å at the experimental lattice.
    """
    require(
        a_angstrom > 0 and c_angstrom > 0,
        f"lattice constants must be > 0, got a={a_angstrom}, c={c_angstrom}",
    )
    atoms = crystal(
        ["Si", "O"],
        basis=[QUARTZ_SI_3A, QUARTZ_O_6C],
        spacegroup=QUARTZ_SPACEGROUP,
        cellpar=[a_angstrom, a_angstrom, c_angstrom, 90.0, 90.0, 120.0],
    )
    # Canonical in-plane cell: a1 along x, a2 at 120°, a3 along z (what ASE already gives; enforce it).
    cell = np.array(
        [
            [a_angstrom, 0.0, 0.0],
            [-0.5 * a_angstrom, 0.5 * np.sqrt(3.0) * a_angstrom, 0.0],
            [0.0, 0.0, c_angstrom],
        ]
    )
    atoms.set_cell(cell, scale_atoms=True)
    atoms.wrap()
    return atoms
