"""SNAP through the LAMMPS engine: the per-slab mechanism only.

The coefficients are generated here (2J = 2, small deterministic values): they are not a silica
model, they only exercise the file handling, the per-slab NULL mapping and the force path.
The bundled ``sio2-snap`` (another engineer's work) replaces them for physics.
"""

import numpy as np
import pytest
from ase import Atoms

from flatcontact.potentials import InteractionModel, make_calculator
from flatcontact.potentials.lj import lj_cross_energy_forces

N_COEFF = 6  # 2J = 2: five bispectrum components + the constant


@pytest.fixture(scope="module")
def snap_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("snap")
    rng = np.random.default_rng(11)
    lines = ["# generated for a mechanism test", "2 6"]
    for element, radius in (("O", 0.5), ("Si", 0.6)):
        lines.append(f"{element} {radius} 1.0")
        lines += [f"{c:.6f}" for c in rng.normal(scale=0.05, size=N_COEFF)]
    (folder / "T.snapcoeff").write_text("\n".join(lines) + "\n")
    (folder / "T.snapparam").write_text(
        "rcutfac 4.0\ntwojmax 2\nrfac0 0.99363\nrmin0 0.0\nbzeroflag 0\nquadraticflag 0\n"
    )
    return folder / "T.snapcoeff"


def test_snap_per_slab_decomposition_and_forces(snap_files, close_interface):
    spec = InteractionModel(intra=f"snap:{snap_files}")
    assert spec.resolved.elements == ("O", "Si")
    atoms = close_interface.copy()
    atoms.calc = make_calculator(spec, atoms)
    e_total, f_total = atoms.get_potential_energy(), atoms.get_forces()
    parts = []
    for which in (1, 2):
        idx = np.flatnonzero(atoms.arrays["slab"] == which)
        part = Atoms(
            atoms.numbers[idx], positions=atoms.positions[idx], cell=atoms.cell, pbc=atoms.pbc
        )
        part.calc = make_calculator(spec, part)
        parts.append((part.get_potential_energy(), part.get_forces()))
    table = spec.lj.table(["O", "Si"], ["O", "Si"])
    e_lj, f_lj = lj_cross_energy_forces(atoms, atoms.arrays["slab"], table, spec.lj.cutoff_angstrom)
    assert e_total == pytest.approx(parts[0][0] + parts[1][0] + e_lj, abs=1e-8)
    assert np.allclose(f_total, np.concatenate([parts[0][1], parts[1][1]]) + f_lj, atol=1e-8)
    h = 1e-4
    for index, axis in ((0, 2), (5, 0), (20, 1)):
        x0 = atoms.positions[index, axis]
        atoms.positions[index, axis] = x0 + h
        ep = atoms.get_potential_energy()
        atoms.positions[index, axis] = x0 - h
        em = atoms.get_potential_energy()
        atoms.positions[index, axis] = x0
        assert f_total[index, axis] == pytest.approx(-(ep - em) / (2 * h), abs=1e-5)
