"""LAMMPS engine: energy decomposition, finite-difference forces, frame invariance, reuse."""

import numpy as np
import pytest
from ase import Atoms

from flatcontact.foundation.errors import InputError
from flatcontact.potentials import InteractionModel, make_calculator
from flatcontact.potentials.lj import lj_cross_energy_forces
from flatcontact.structures.placement import interslab_min_distance

CLASSICAL = ["vashishta", "tersoff"]


def _energy_forces(spec, atoms):
    a = atoms.copy()
    a.calc = make_calculator(spec, a)
    return a.get_potential_energy(), a.get_forces(), a.calc


def _slab_alone(atoms, which):
    idx = np.flatnonzero(atoms.arrays["slab"] == which)
    return Atoms(atoms.numbers[idx], positions=atoms.positions[idx], cell=atoms.cell, pbc=atoms.pbc)


@pytest.mark.parametrize("intra", CLASSICAL)
def test_energy_is_slab1_plus_slab2_plus_cross_lj(close_interface, intra):
    spec = InteractionModel(intra=intra)
    # slabs close enough that the intra-slab cutoffs would reach across if not NULL-mapped
    assert interslab_min_distance(close_interface) < 3.0
    e_total, f_total, _ = _energy_forces(spec, close_interface)
    e1, f1, _ = _energy_forces(spec, _slab_alone(close_interface, 1))
    e2, f2, _ = _energy_forces(spec, _slab_alone(close_interface, 2))
    groups = close_interface.arrays["slab"]
    table = spec.lj.table(["O", "Si"], ["O", "Si"])
    e_lj, f_lj = lj_cross_energy_forces(close_interface, groups, table, spec.lj.cutoff_angstrom)
    assert e_lj < 0 or e_lj > 0  # the cross LJ is not empty
    assert e_total == pytest.approx(e1 + e2 + e_lj, abs=1e-8)
    f_sum = np.concatenate([f1, f2]) + f_lj
    assert np.allclose(f_total, f_sum, atol=1e-8)
    if intra != "vashishta":  # Tersoff Si–O cutoffs (< 3 Å) do not reach across anyway
        return
    # Vashishta's 7.35 Å two-body range does: treating both slabs as one body differs
    whole = close_interface.copy()
    del whole.arrays["slab"]
    e_whole, _, _ = _energy_forces(spec, whole)
    assert abs(e_whole - (e1 + e2)) > 1e-3


@pytest.mark.parametrize("intra", [*CLASSICAL, "none"])
def test_forces_match_finite_differences(close_interface, intra):
    spec = InteractionModel(intra=intra)
    atoms = close_interface.copy()
    atoms.calc = make_calculator(spec, atoms)
    forces = atoms.get_forces()
    h = 1e-4
    rng = np.random.default_rng(3)
    for index in rng.choice(len(atoms), size=6, replace=False):
        for axis in range(3):
            x0 = atoms.positions[index, axis]
            atoms.positions[index, axis] = x0 + h
            ep = atoms.get_potential_energy()
            atoms.positions[index, axis] = x0 - h
            em = atoms.get_potential_energy()
            atoms.positions[index, axis] = x0
            fd = -(ep - em) / (2 * h)
            assert forces[index, axis] == pytest.approx(fd, abs=2e-4 * max(1.0, abs(fd)))


def test_lj_only_engine_matches_numpy_lj(close_interface):
    spec = InteractionModel(intra="none")
    e, f, _ = _energy_forces(spec, close_interface)
    table = spec.lj.table(["O", "Si"], ["O", "Si"])
    e_np, f_np = lj_cross_energy_forces(
        close_interface, close_interface.arrays["slab"], table, spec.lj.cutoff_angstrom
    )
    assert e == pytest.approx(e_np, rel=1e-10, abs=1e-12)
    assert np.allclose(f, f_np, atol=1e-10)


@pytest.mark.parametrize("cutoff_angstrom", [26.0, 30.0])
def test_a_long_lj_cutoff_fits_lammps_neighbour_lists(close_interface, cutoff_angstrom):
    """The quartz study's cutoff step to 26 Å overflowed LAMMPS's default per-atom neighbour
    capacity ("Neighbor list overflow, boost neigh_modify one"): the setup sizes it from the
    cutoff. Checked against the numpy LJ written independently of LAMMPS."""
    spec = InteractionModel(intra="none", lj={"cutoff_angstrom": cutoff_angstrom})
    e, f, _ = _energy_forces(spec, close_interface)
    table = spec.lj.table(["O", "Si"], ["O", "Si"])
    e_np, f_np = lj_cross_energy_forces(
        close_interface, close_interface.arrays["slab"], table, cutoff_angstrom
    )
    assert e == pytest.approx(e_np, rel=1e-10, abs=1e-12)
    assert np.allclose(f, f_np, atol=1e-10)


@pytest.mark.parametrize("reflect", [False, True])
def test_frame_invariance_rotation_reflection_and_cell_choice(close_interface, reflect):
    spec = InteractionModel(intra="vashishta")
    e0, f0, _ = _energy_forces(spec, close_interface)
    theta = 0.7
    r = np.array([[np.cos(theta), -np.sin(theta), 0], [np.sin(theta), np.cos(theta), 0], [0, 0, 1]])
    if reflect:
        r = r @ np.diag([1.0, -1.0, 1.0])
    moved = close_interface.copy()
    moved.set_cell(close_interface.cell.array @ r.T, scale_atoms=False)
    moved.positions = close_interface.positions @ r.T
    e1, f1, _ = _energy_forces(spec, moved)
    assert e1 == pytest.approx(e0, abs=1e-8)
    assert np.allclose(f1, f0 @ r.T, atol=1e-7)
    # an equivalent choice of the second lattice vector (a2 + a1) is the same crystal
    other = close_interface.copy()
    cell = other.cell.array.copy()
    cell[1] += cell[0]
    other.set_cell(cell, scale_atoms=False)
    e2, f2, _ = _energy_forces(spec, other)
    assert e2 == pytest.approx(e0, abs=1e-8)
    assert np.allclose(f2, f0, atol=1e-7)


def test_calculator_reuse_counts_calls_and_rebuilds_on_new_structure(close_interface):
    spec = InteractionModel(intra="tersoff")
    atoms = close_interface.copy()
    calc = make_calculator(spec, atoms)
    atoms.calc = calc
    engine = calc.engine
    e0 = atoms.get_potential_energy()
    atoms.get_forces()  # cached: no new call
    assert calc.force_calls == 1
    atoms.positions[0, 2] += 0.01
    atoms.get_forces()
    assert calc.force_calls == 2 and calc.engine is engine  # positions only: same LAMMPS instance
    atoms.positions[0, 2] -= 0.01
    assert atoms.get_potential_energy() == pytest.approx(e0, abs=1e-10)
    smaller = atoms[:-3]
    smaller.calc = calc
    smaller.get_potential_energy()
    assert calc.engine is not engine and calc.force_calls == 4


def test_element_mismatch_is_one_line_input_error(close_interface):
    atoms = close_interface.copy()
    atoms.symbols[0] = "Ge"
    with pytest.raises(InputError, match="Ge") as info:
        make_calculator(InteractionModel(intra="vashishta"), atoms)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("angle", [2.7e-34, 1e-17, -1e-16])
def test_a1_along_x_to_round_off_is_the_unrotated_frame(close_interface, angle):
    """A cell whose a1 leaves x by round-off only (2.7e-34 rad in the built Cu(111) cells) is
    LAMMPS's own frame exactly (no rotation per call: ``same_frame``); its energy and forces
    are the unrotated cell's, and rotating by 1e-6 rad is still a rotation."""
    from flatcontact.potentials.lammps_box import LammpsBox

    spec = InteractionModel(intra="vashishta")
    e0, f0, _ = _energy_forces(spec, close_interface)
    cell = close_interface.cell.array.copy()
    cell[0, 1] = angle * cell[0, 0]
    tilted = close_interface.copy()
    tilted.set_cell(cell, scale_atoms=False)
    box = LammpsBox(cell, tilted.pbc)
    assert box.same_frame and np.array_equal(box.q, np.eye(2))
    e1, f1, _ = _energy_forces(spec, tilted)
    assert e1 == pytest.approx(e0, rel=1e-14)
    np.testing.assert_allclose(f1, f0, rtol=0, atol=1e-12)
    cell[0, 1] = 1e-6 * cell[0, 0]
    assert not LammpsBox(cell, tilted.pbc).same_frame


def test_the_paper_slab_builds_with_the_studys_26_angstrom_cutoff(tmp_path):
    """The quartz convergence study's cutoff step 22 -> 26 Å died in the build stage (the
    dense slab's relaxation: "Neighbor list overflow, boost neigh_modify one", LAMMPS's default
    capacity of 2000 neighbours per atom); the capacity now follows the cutoff
    (lammps_setup.neighbour_capacity)."""
    from flatcontact.config import build_config
    from flatcontact.pipeline import Pipeline
    from flatcontact.potentials.lammps_setup import LAMMPS_DEFAULT_NEIGHBOURS, neighbour_capacity

    assert neighbour_capacity(18.0) > LAMMPS_DEFAULT_NEIGHBOURS  # a bound, set from 18 Å on
    cfg = build_config({"potential": {"lj": {"cutoff_angstrom": 26.0}}}, "paper")
    with Pipeline(cfg, tmp_path / "run") as pipe:
        pipe.build()
    assert (tmp_path / "run" / "01-build" / "interface.extxyz").is_file()
