"""The LAMMPS engine's per-call fast path gives the energies, forces and stresses of a fresh setup.

After its first evaluation the engine writes positions into LAMMPS's own arrays and runs one
force evaluation without setup (``run 1 pre no post no``), relying on LAMMPS's neighbour check.
Here every evaluation along a path of random displacements (small ones that keep the
neighbour lists, and large ones that cross periodic boundaries and force a rebuild) is
compared with an independent engine that does a full ``run 0`` setup at that geometry.
"""

import numpy as np
import pytest
from ase.build import bulk

from flatcontact.potentials import InteractionModel, make_calculator
from flatcontact.potentials.calculator import LammpsInterfaceCalculator
from flatcontact.potentials.lammps_engine import LammpsEngine
from flatcontact.potentials.lammps_setup import compile_setup


def _path(atoms, seed):
    rng = np.random.default_rng(seed)
    pos = atoms.positions.copy()
    upper = np.asarray(atoms.arrays["slab"]) == 2
    for k in range(12):
        # small steps (the neighbour lists are kept), then slab 2 slid by 0.6 Å (more than
        # half the 1 Å skin: a rebuild), then a translation by more than the cell (every
        # atom re-wrapped)
        pos = pos + rng.normal(scale=0.01, size=pos.shape)
        if k >= 5:
            step = rng.normal(size=3) * [1.0, 1.0, 0.2]
            pos[upper] += 0.6 * step / np.linalg.norm(step)
        if k == 9:
            pos[:, :2] += 1.3 * atoms.cell.array[0, :2]
        yield pos.copy()


def _fresh(setup, cell, pbc, positions, stress):
    engine = LammpsEngine(setup, cell, pbc)
    try:
        return engine.compute(positions, stress=stress)
    finally:
        engine.close()


def _check_path(model, atoms, bulk_cell=False, seed=0):
    setup = compile_setup(model, atoms, bulk=bulk_cell)
    engine = LammpsEngine(setup, atoms.cell.array, atoms.pbc)
    try:
        engine.compute(atoms.positions, stress=bulk_cell)
        for pos in _path(atoms, seed):
            got = engine.compute(pos, stress=bulk_cell)
            want = _fresh(setup, atoms.cell.array, atoms.pbc, pos, bulk_cell)
            assert got[0] == pytest.approx(want[0], rel=1e-11, abs=1e-9)
            np.testing.assert_allclose(got[1], want[1], rtol=0, atol=1e-9)
            if bulk_cell:
                np.testing.assert_allclose(got[2], want[2], rtol=0, atol=1e-10)
            _check_views(engine)
    finally:
        engine.close()


def _check_views(engine):
    """The cached views are LAMMPS's current arrays (same data addresses as the wrapper's)."""
    rows, x, f = engine._views()
    assert engine._cached_views is not None  # cached, not rebuilt on every call
    lmp = engine.lmp
    assert x.ctypes.data == lmp.numpy.extract_atom("x", nelem=engine.n, dim=3).ctypes.data
    assert f.ctypes.data == lmp.numpy.extract_atom("f", nelem=engine.n, dim=3).ctypes.data
    ids = lmp.numpy.extract_atom("id", nelem=engine.n)
    assert np.array_equal(np.asarray(ids)[rows], np.arange(1, engine.n + 1))


@pytest.mark.parametrize("intra", ["vashishta", "tersoff"])
def test_quartz_interface_path_equals_fresh_setups(close_interface, intra):
    _check_path(InteractionModel(intra=intra), close_interface)


def test_interlayer_bilayer_path_equals_fresh_setups():
    """atom_style full, molecule ids per layer, REBO + Kolmogorov-Crespi (normals each call)."""
    from test_interlayer_presets import hexagonal_bilayer

    atoms = hexagonal_bilayer(2.46, 3.4, (1 / 3, 1 / 3)).repeat((3, 3, 1))
    _check_path(InteractionModel(preset="graphene-rebo-kc"), atoms, seed=1)


def test_bulk_stress_path_equals_fresh_setups():
    atoms = bulk("Cu", "fcc", a=3.61, cubic=True).repeat((2, 2, 2))
    atoms.arrays["slab"] = 1 + (atoms.positions[:, 2] > 3.6).astype(int)  # "slab 2" slides
    _check_path(InteractionModel(preset="cu-eam"), atoms, bulk_cell=True, seed=3)


def test_calculator_reports_position_only_changes(close_interface):
    atoms = close_interface.copy()
    calc = make_calculator(InteractionModel(intra="tersoff"), atoms)
    atoms.calc = calc
    atoms.get_forces()
    assert calc.check_state(atoms) == []
    atoms.positions[3, 0] += 1e-9
    assert calc.check_state(atoms) == ["positions"]
    atoms.get_forces()
    atoms.numbers[0] = 14 if atoms.numbers[0] == 8 else 8
    assert "numbers" in calc.check_state(atoms)


def test_vertical_cell_change_keeps_the_engine(close_interface):
    """A slab's vertical cell vector (the scan resizes it with z) is not part of the LAMMPS box:
    changing it keeps the engine and the numbers; an in-plane change rebuilds it."""
    atoms = close_interface.copy()
    calc = make_calculator(InteractionModel(intra="tersoff"), atoms)
    assert isinstance(calc, LammpsInterfaceCalculator)
    atoms.calc = calc
    e0, f0 = atoms.get_potential_energy(), atoms.get_forces()
    engine = calc.engine
    atoms.cell[2, 2] += 7.0
    assert atoms.get_potential_energy() == pytest.approx(e0, abs=1e-10)
    np.testing.assert_allclose(atoms.get_forces(), f0, atol=1e-10)
    assert calc.engine is engine
    atoms.set_cell(atoms.cell.array * [[1.01], [1.01], [1.0]], scale_atoms=True)
    atoms.get_forces()
    assert calc.engine is not engine


def test_positions_keep_lammps_images_so_no_spurious_rebuild():
    """Atoms on the cell boundary (Cu(111) lattice sites at fractional 0) are handed to LAMMPS
    at the image LAMMPS holds: re-evaluating the same structure, or one moved by less than
    the skin, moves no atom by a lattice vector (which forced a neighbour rebuild per call)."""
    from flatcontact.structures.construct import build_interface

    atoms, _ = build_interface({"kind": "fcc111", "element": "Cu", "layers": 4})
    atoms = atoms.repeat((14, 14, 1))  # 1,568 atoms: here the wrap and LAMMPS disagree
    setup = compile_setup(InteractionModel(preset="cu-eam"), atoms)
    engine = LammpsEngine(setup, atoms.cell.array, atoms.pbc)
    try:
        engine.compute(atoms.positions)
        rows, x, _ = engine._views()
        before = x[rows].copy()
        wrapped = engine.box.to_lammps(atoms.positions)
        # the case the images matter for: LAMMPS and the plain wrap disagree on some atoms
        assert np.abs(wrapped - before).max() > 1.0
        engine.compute(atoms.positions)
        rows, x, _ = engine._views()
        assert np.abs(x[rows] - before).max() < 1e-12  # the same images, to round-off
        rng = np.random.default_rng(1)
        step = rng.normal(scale=0.05, size=atoms.positions.shape)
        moved = engine.compute(atoms.positions + step)
        rows, x, _ = engine._views()
        assert np.abs(x[rows] - before).max() < 0.5  # every atom at its own image
        want = _fresh(setup, atoms.cell.array, atoms.pbc, atoms.positions + step, False)
        assert moved[0] == pytest.approx(want[0], rel=1e-11, abs=1e-9)
        np.testing.assert_allclose(moved[1], want[1], rtol=0, atol=1e-9)
    finally:
        engine.close()


def test_uncopied_forces_are_lammps_array_and_fresh_values(close_interface):
    """``compute(copy=False)`` (the scan's L-BFGS): on a slab cell with a1 along x the forces
    are LAMMPS's own array, read-only, and equal to a fresh setup's along the path (rebuilds
    and re-wraps included); with the default copy they are the same numbers in a new array."""
    model = InteractionModel(intra="vashishta")
    atoms = close_interface
    setup = compile_setup(model, atoms)
    engine = LammpsEngine(setup, atoms.cell.array, atoms.pbc)
    try:
        assert engine.box.same_frame
        engine.compute(atoms.positions)
        for k, pos in enumerate(_path(atoms, 3)):
            energy, forces = engine.compute(pos, copy=k % 2 == 1)
            own = np.shares_memory(forces, engine._views()[2])
            assert own == (k % 2 == 0) and forces.flags.writeable == (k % 2 == 1)
            want = _fresh(setup, atoms.cell.array, atoms.pbc, pos, False)
            assert energy == pytest.approx(want[0], rel=1e-11, abs=1e-9)
            np.testing.assert_allclose(forces, want[1], rtol=0, atol=1e-9)
    finally:
        engine.close()


def test_reallocated_lammps_arrays_are_followed(close_interface):
    """LAMMPS reallocates ``x`` and ``f`` when the local + ghost atoms outgrow them (here a
    ghost cutoff of 60 Å between two calls multiplies the ghosts: ``atom->nmax`` grows): the
    engine's next call writes into and reads from the new arrays (one int, ``nmax``, tells it),
    and its energy and forces are a fresh setup's."""
    model = InteractionModel(intra="vashishta")
    atoms = close_interface
    setup = compile_setup(model, atoms)
    engine = LammpsEngine(setup, atoms.cell.array, atoms.pbc)
    try:
        engine.compute(atoms.positions)
        nmax = engine._nmax.value
        x_before = engine._views()[1].ctypes.data
        engine.lmp.commands_list(["comm_modify cutoff 60.0", "run 0 post no"])
        assert engine._nmax.value > nmax  # the reallocation this test is about
        assert engine.lmp.numpy.extract_atom("x").ctypes.data != x_before
        for pos in _path(atoms, 5):
            energy, forces = engine.compute(pos, copy=False)
            want = _fresh(setup, atoms.cell.array, atoms.pbc, pos, False)
            assert energy == pytest.approx(want[0], rel=1e-11, abs=1e-9)
            np.testing.assert_allclose(forces, want[1], rtol=0, atol=1e-9)
            _check_views(engine)
    finally:
        engine.close()
