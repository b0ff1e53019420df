"""Training's bulk calculators come from the interaction model and agree with raw LAMMPS."""

import numpy as np
import pytest
from ase.build import bulk

from flatcontact.potentials.engines import bulk_calculator
from flatcontact.structures.bulk import alpha_quartz
from flatcontact.training.lammps_bulk import (
    LammpsBulkCalculator,
    vashishta_calculator,
    vashishta_pair_commands,
)


def _efs(atoms, calc):
    a = atoms.copy()
    a.calc = calc
    return a.get_potential_energy(), a.get_forces(), a.get_stress()


def test_vashishta_bulk_model_equals_hand_written_pair_commands():
    """A sheared, rattled α-quartz cell (general triclinic: the Prism frame) gives the same
    energy, forces and stress through the model as through hand-written pair commands."""
    quartz = alpha_quartz()
    quartz.set_cell(
        quartz.cell.array @ np.array([[1, 0.02, 0.01], [0, 1, 0.03], [0, 0, 1]]), scale_atoms=True
    )
    quartz.rattle(0.03, seed=4)
    e1, f1, s1 = _efs(quartz, vashishta_calculator())
    e2, f2, s2 = _efs(quartz, LammpsBulkCalculator(vashishta_pair_commands(), ["Si", "O"]))
    assert e1 == pytest.approx(e2, abs=1e-9)
    assert np.allclose(f1, f2, atol=1e-9) and np.allclose(s1, s2, atol=1e-10)


def test_bulk_calculator_takes_presets():
    cu = bulk("Cu", "fcc", a=3.615, cubic=True)
    e, f, s = _efs(cu, bulk_calculator("cu-eam"))
    assert e / len(cu) == pytest.approx(-3.54, abs=0.005)  # Mishin et al. 2001, E0
    assert np.abs(f).max() < 1e-10 and np.abs(s).max() < 1e-4
