"""The toy calculator with a fold of its own: a term that depends on the thickness alone.

A module of its own so that the scan's calculator loader imports it by name
(``tests.ispes.fold_toy:folded_toy``). The term acts between the held outer planes (surfaces
1 and 4), which never move in a relaxation, so no relaxation at any force tolerance changes
it: it adds the load p_x(z) = B exp(-((z - z0)/w)²) (GPa, > 0 pressed) to every point at
thickness z, whose rise on the compressed side (dp_x/dz up to B √2 e^(-1/2)/w) exceeds the
toy's own fall of about 7 GPa/Å when B √2 e^(-1/2)/w > 7: a fold of the interaction itself.
"""

from __future__ import annotations

import math

import numpy as np
from ase.calculators.calculator import Calculator, all_changes

from flatcontact.foundation.units import EV_PER_A3_TO_GPA
from flatcontact.ispes.toy import toy_calculator
from flatcontact.structures.interface_contract import in_plane_vectors


class FoldedToy(Calculator):
    """The toy pair model plus the thickness-only term of the module docstring."""

    implemented_properties = ("energy", "forces")

    def __init__(self, z0_angstrom: float, width_angstrom: float, bump_gpa: float):
        super().__init__()
        self.inner = toy_calculator()
        self.z0, self.w, self.b = z0_angstrom, width_angstrom, bump_gpa / EV_PER_A3_TO_GPA

    def calculate(self, atoms=None, properties=("energy",), system_changes=all_changes):
        super().calculate(atoms, properties, system_changes)
        work = self.atoms.copy()
        work.calc = self.inner
        energy = float(work.get_potential_energy())
        forces = np.array(work.get_forces())
        surface = np.asarray(self.atoms.arrays["surface"])
        bottom, top = surface == 1, surface == 4
        z = float(self.atoms.positions[top, 2].mean() - self.atoms.positions[bottom, 2].mean())
        a1, a2 = in_plane_vectors(self.atoms)
        area = abs(float(a1[0] * a2[1] - a1[1] * a2[0]))
        x = (z - self.z0) / self.w
        # E_x(z) = -A ∫ p_x dz, dE_x/dz = -A p_x
        energy -= area * self.b * self.w * 0.5 * math.sqrt(math.pi) * math.erf(x)
        push = area * self.b * math.exp(-x * x)  # -dE_x/dz, on the mean z of surface 4
        forces[top, 2] += push / top.sum()
        forces[bottom, 2] -= push / bottom.sum()
        self.results = {"energy": energy, "forces": forces}


def folded_toy(atoms=None, z0_angstrom=11.1, width_angstrom=0.05, bump_gpa=1.5) -> FoldedToy:
    return FoldedToy(z0_angstrom, width_angstrom, bump_gpa)
