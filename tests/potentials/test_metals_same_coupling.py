"""Metals with the same potential across the interface: the ISPES is the γ-surface.

Cu (Mishin et al., PRB 63, 224106 (2001), ``Cu_mishin1.eam.alloy``): the intrinsic stacking
fault energy the paper reports is γ_isf = 44.4 mJ/m². An fcc(111) interface of two 6-layer
slabs in perfect ABC stacking is shifted rigidly by the partial Burgers vector (a1 + a2)/3,
which turns ...ABC|ABC... into ...ABC|BCA..., one intrinsic stacking fault; γ = ΔE/A with
the atoms relaxed along z only (the GSF convention) and unrelaxed.
"""

import numpy as np
import pytest
from ase.build import bulk, fcc111
from ase.constraints import FixCartesian
from ase.optimize import BFGS

from flatcontact.potentials import InteractionModel, make_calculator
from flatcontact.potentials.engines import bulk_calculator

EV_PER_A2_TO_MJ_PER_M2 = 16021.766


def fcc111_interface(symbol, a, layers=12, shift=(0.0, 0.0)):
    atoms = fcc111(symbol, size=(1, 1, layers), a=a, vacuum=10.0)
    atoms.pbc = (True, True, False)
    order = np.argsort(atoms.positions[:, 2])
    layer = np.empty(len(atoms), dtype=int)
    layer[order] = np.arange(1, layers + 1)
    atoms.arrays["layer"] = layer
    atoms.arrays["slab"] = np.where(layer > layers // 2, 2, 1)
    top = atoms.arrays["slab"] == 2
    atoms.positions[top, :2] += np.asarray(shift) @ atoms.cell.array[:2, :2]
    return atoms


def energy(model, atoms, relax_z=False):
    atoms = atoms.copy()
    atoms.calc = make_calculator(model, atoms)
    if relax_z:
        atoms.set_constraint(FixCartesian(range(len(atoms)), mask=(True, True, False)))
        BFGS(atoms, logfile=None).run(fmax=1e-5, steps=500)
    return atoms.get_potential_energy()


@pytest.mark.parametrize("relax_z", [False, True])
def test_cu_intrinsic_stacking_fault_energy_is_mishins(relax_z):
    model = InteractionModel(preset="cu-eam")
    a = 3.615  # Mishin Cu1 lattice constant
    perfect = fcc111_interface("Cu", a)
    faulted = fcc111_interface("Cu", a, shift=(1 / 3, 1 / 3))
    area = abs(np.linalg.det(perfect.cell.array[:2, :2]))
    gamma = (energy(model, faulted, relax_z) - energy(model, perfect, relax_z)) / area
    gamma *= EV_PER_A2_TO_MJ_PER_M2
    assert gamma == pytest.approx(44.4, abs=1.0)
    # a whole lattice translation of slab 2 is the perfect crystal again, to round-off
    again = fcc111_interface("Cu", a, shift=(1.0, 0.0))
    assert energy(model, again) == pytest.approx(energy(model, perfect), abs=1e-9)


def test_same_coupling_is_the_bulk_potential_across_the_interface():
    """At zero shift the interface is a perfect crystal cut nowhere: its energy per atom deep
    inside equals the bulk cohesive energy, Mishin's E0 = −3.54 eV (Cu), and the interface
    energy equals the energy of one 12-layer slab without slab labels."""
    model = InteractionModel(preset="cu-eam")
    perfect = fcc111_interface("Cu", 3.615)
    single = perfect.copy()
    del single.arrays["slab"]
    del single.arrays["layer"]
    assert energy(model, perfect) == pytest.approx(energy(model, single), abs=1e-10)
    cu = bulk("Cu", "fcc", a=3.615, cubic=True)
    cu.calc = bulk_calculator(model, cu)
    assert cu.get_potential_energy() / len(cu) == pytest.approx(-3.54, abs=0.005)


@pytest.mark.parametrize(
    ("preset", "symbol", "a", "cohesive_ev"),
    [("ni-eam", "Ni", 3.52, 4.45), ("al-eam", "Al", 4.05, 3.58)],
)
def test_ni_and_al_presets_give_their_cohesive_energies(preset, symbol, a, cohesive_ev):
    """Foiles, Baskes & Daw 1986 (Ni: Ec = 4.45 eV at a = 3.52 Å); Zhou et al. 2001 (Al:
    Ec = 3.58 eV); the relaxed lattice within 1 % of experiment (3.52, 4.05 Å)."""
    from flatcontact.elastic import relax_cell

    crystal = bulk(symbol, "fcc", a=a, cubic=True)
    calc = bulk_calculator(InteractionModel(preset=preset), crystal)
    relaxed = relax_cell(crystal, calc)
    relaxed.calc = calc
    assert -relaxed.get_potential_energy() / len(relaxed) == pytest.approx(cohesive_ev, abs=0.01)
    assert relaxed.cell.cellpar()[0] == pytest.approx(a, rel=0.01)
    assert np.abs(relaxed.get_stress()).max() < 1e-5  # eV/Å³: the bulk stress is the model's
