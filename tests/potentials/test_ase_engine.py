"""ASE-calculator engine: per-slab ASE calculators + numpy LJ agree with the LAMMPS engine."""

import numpy as np
import pytest

from flatcontact.foundation.errors import InputError
from flatcontact.potentials import InteractionModel, LJSpec, make_calculator


@pytest.mark.parametrize("model", ["vashishta", "tersoff"])
def test_ase_engine_agrees_with_lammps_engine(close_interface, model):
    lj = LJSpec(cutoff_angstrom=9.0)
    lammps_spec = InteractionModel(intra=model, lj=lj)
    ase_spec = InteractionModel(intra=f"ase:flatcontact.potentials.factories:{model}", lj=lj)
    assert ase_spec.kind == "ase"
    results = []
    for spec in (lammps_spec, ase_spec):
        atoms = close_interface.copy()
        atoms.calc = make_calculator(spec, atoms)
        results.append((atoms.get_potential_energy(), atoms.get_forces(), atoms.calc))
    (e_l, f_l, _), (e_a, f_a, calc) = results
    assert e_a == pytest.approx(e_l, abs=1e-8)
    assert np.allclose(f_a, f_l, atol=1e-8)
    assert calc.force_calls == 1


def test_ase_factory_errors_are_one_line():
    spec = InteractionModel(intra="ase:flatcontact.potentials.factories:no_such_factory")
    with pytest.raises(InputError, match="no_such_factory"):
        from ase.build import bulk

        atoms = bulk("Si")
        atoms.calc = make_calculator(spec, atoms)
