"""User calculators that fail, named by target (``tests.hardening.failing_calculators:NanForces``)
as a user names theirs: the toy pair model (:class:`~flatcontact.structures.toy.ToyPairCalculator`)
with one defect each."""

from __future__ import annotations

from typing import ClassVar

import numpy as np
from ase.calculators.calculator import all_changes
from ase.calculators.emt import EMT

from flatcontact.structures.toy import ToyPairCalculator


class NanForces(ToyPairCalculator):
    """The toy model with a NaN in the z force of its first atom (a model far from its data)."""

    def calculate(self, atoms=None, properties=("energy",), system_changes=all_changes):
        super().calculate(atoms, properties, system_changes)
        self.results["forces"][0, 2] = np.nan


class FailsWhenPressed(ToyPairCalculator):
    """The toy model that raises once the gap between the slabs (lowest slab-2 atom minus
    highest slab-1 atom) is below ``fail_gap_angstrom``: it fails at a compressed point of a
    scan, not at the reference."""

    default_parameters: ClassVar[dict[str, float]] = {
        **ToyPairCalculator.default_parameters,
        "fail_gap_angstrom": 0.0,
    }

    def calculate(self, atoms=None, properties=("energy",), system_changes=all_changes):
        super().calculate(atoms, properties, system_changes)
        z = self.atoms.positions[:, 2]
        slab = np.asarray(self.atoms.arrays["slab"])
        gap = float(z[slab == 2].min() - z[slab == 1].max())
        if gap < float(self.parameters["fail_gap_angstrom"]):
            raise RuntimeError(f"gap {gap:.3f} Å outside the fitted range\nsee the model card")


class Broken:
    """Not an ASE Calculator subclass: ``get_potential_energy`` and ``get_forces`` only, the
    forces of the wrong shape for the structure (an index error inside the user's code)."""

    def get_potential_energy(self, atoms=None, force_consistent=False):
        return 0.0

    def get_forces(self, atoms=None):
        return np.zeros((len(atoms) + 1, 3))[[len(atoms) + 5]]


def broken(atoms=None, **kwargs):
    """Factory of :class:`Broken`."""
    return Broken()


class FailsAfter(EMT):
    """ASE's EMT that raises at its ``after``-th evaluation (a model that diverges in the
    middle of a relaxation); a fresh instance (the pre-run check's) evaluates once."""

    def __init__(self, after: int = 3, **kwargs):
        super().__init__(**kwargs)
        self.after = int(after)
        self.calls = 0

    def calculate(self, atoms=None, properties=("energy",), system_changes=all_changes):
        self.calls += 1
        if self.calls >= self.after:
            raise RuntimeError(f"evaluation {self.calls}: the model diverged")
        super().calculate(atoms, properties, system_changes)


class NanStress(ToyPairCalculator):
    """The toy model that also returns a stress, NaN, whether asked for or not (as a
    calculator may for a cell that is not periodic along z)."""

    implemented_properties = ("energy", "free_energy", "forces", "stress")

    def calculate(self, atoms=None, properties=("energy",), system_changes=all_changes):
        super().calculate(atoms, properties, system_changes)
        self.results["stress"] = np.full(6, np.nan)


def boom(**kwargs):
    """A factory that refuses to build its calculator."""
    raise ValueError("sigma must be positive\nsee the manual")
