"""A pair potential whose fcc intrinsic stacking fault lies below the perfect crystal.

Shifted-force Lennard-Jones plus a narrow attractive Gaussian well at √(8/3) r_nn, the
distance of the two third neighbours across a close-packed plane in hcp stacking, which the
fcc crystal does not have (its third shell is at √3 r_nn). An intrinsic stacking fault puts
each atom of the two planes beside it in local hcp stacking, so the well lowers its energy
below the perfect crystal's: γ_isf < 0. The bulk fcc lattice does not feel the well.
Energy, forces and stress (ASE's sign) are analytic: the build relaxes its lattice.
"""

from __future__ import annotations

import numpy as np
from ase.calculators.calculator import Calculator, all_changes
from ase.neighborlist import neighbor_list

SIGMA = 2.3  # Å
EPSILON = 0.2  # eV
CUTOFF = 2.5 * SIGMA
R_NN = 2.534  # Å: the fcc nearest neighbour of this LJ (a = 3.583 Å, relaxed)
WELL_CENTRE = np.sqrt(8 / 3) * R_NN  # hcp's third neighbours across the plane
WELL_DEPTH = 0.002  # eV
WELL_WIDTH = 0.08  # Å


def _phi(r):
    sr6 = (SIGMA / r) ** 6
    lj = 4 * EPSILON * (sr6 * sr6 - sr6)
    dlj = 4 * EPSILON * (-12 * sr6 * sr6 + 6 * sr6) / r
    g = -WELL_DEPTH * np.exp(-((r - WELL_CENTRE) ** 2) / (2 * WELL_WIDTH**2))
    dg = -g * (r - WELL_CENTRE) / WELL_WIDTH**2
    return lj + g, dlj + dg


def _shifted(r):
    e, de = _phi(r)
    ec, dec = _phi(np.array([CUTOFF]))
    return e - ec - (r - CUTOFF) * dec, de - dec


class FaultFavoured(Calculator):
    """The pair potential of the module docstring (every element alike)."""

    implemented_properties = ("energy", "free_energy", "forces", "stress")

    def calculate(self, atoms=None, properties=("energy",), system_changes=all_changes):
        super().calculate(atoms, properties, system_changes)
        i, d, vec = neighbor_list("idD", self.atoms, CUTOFF)
        e, de = _shifted(d)
        energy = 0.5 * float(e.sum())
        pair_force = (de / d)[:, None] * vec  # on i from j: dφ/dr · (r_j − r_i)/r
        forces = np.zeros((len(self.atoms), 3))
        np.add.at(forces, i, pair_force)
        self.results = {"energy": energy, "free_energy": energy, "forces": forces}
        if all(self.atoms.pbc):
            virial = 0.5 * np.einsum("k,ka,kb->ab", de / d, vec, vec)
            s = virial / self.atoms.get_volume()
            self.results["stress"] = np.array(
                [s[0, 0], s[1, 1], s[2, 2], s[1, 2], s[0, 2], s[0, 1]]
            )


def fault_favoured(atoms=None):
    """``potential: {calculator: {target: tests.analysis.fault_favoured:fault_favoured}}``."""
    return FaultFavoured()
