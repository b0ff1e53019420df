"""The ``rigid-layers`` relaxation mode as an ASE constraint, for ASE's optimisers.

The scan's own L-BFGS applies the same projection without ASE
(:func:`flatcontact.ispes.relax.constraint_projector`); this class serves the other
optimisers (FIRE, BFGS, ...) and keeps ``ase.constraints`` (≈0.5 s of imports) out of
scan workers that do not need it.
"""

from __future__ import annotations

import numpy as np
from ase import Atoms
from ase.constraints import FixConstraint


class RigidLayersAlongZ(FixConstraint):
    """Each group of atoms (a layer) moves as a rigid body along z only.

    Positions: a proposed step keeps only each group's mean z displacement. Forces: each
    atom of a group gets the group's mean z-force (the generalised force on its height per
    atom), x and y zero, so an optimiser's step is the same for every atom of the group and
    ``fmax`` is |Σ_group F_z| / n_group.
    """

    def __init__(self, groups: list[np.ndarray]):
        self.groups = [np.asarray(g, dtype=int) for g in groups]

    def get_removed_dof(self, atoms: Atoms) -> int:
        return sum(3 * len(g) - 1 for g in self.groups)

    def adjust_positions(self, atoms: Atoms, new: np.ndarray) -> None:
        old = atoms.positions
        for g in self.groups:
            dz = float(np.mean(new[g, 2] - old[g, 2]))
            new[g] = old[g]
            new[g, 2] += dz

    def adjust_forces(self, atoms: Atoms, forces: np.ndarray) -> None:
        for g in self.groups:
            fz = float(np.mean(forces[g, 2]))
            forces[g] = 0.0
            forces[g, 2] = fz

    def todict(self) -> dict:
        return {
            "name": "RigidLayersAlongZ",
            "kwargs": {"groups": [g.tolist() for g in self.groups]},
        }
