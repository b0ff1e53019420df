"""The compute-snap design matrix against LAMMPS pair_style snap, and coefficient recovery."""

import numpy as np
import pytest

from flatcontact.training.dataset import labelled
from flatcontact.training.descriptors import SnapDescriptors
from flatcontact.training.fit import FitSettings, assemble, compute_blocks, fit_snap
from flatcontact.training.lammps_bulk import snap_calculator
from flatcontact.training.polymorphs import build_polymorph
from flatcontact.training.recipe import strain_cell
from flatcontact.training.snapfiles import (
    SnapCoefficients,
    SnapHyper,
    n_bispectrum,
    read_snapcoeff,
    write_snap_files,
)

ELEMENTS = ["Si", "O"]


def distorted_quartz(seed: int, reps=(1, 1, 1)):
    rng = np.random.default_rng(seed)
    q = strain_cell(build_polymorph("alpha_quartz").repeat(reps), rng.uniform(-0.03, 0.03, 6))
    q.positions += rng.normal(0.0, 0.05, q.positions.shape)
    return q


def test_bispectrum_counts_match_lammps():
    # LAMMPS documentation: 2J = 6 -> 30, 2J = 8 -> 55 components (chemflag 0)
    assert n_bispectrum(6) == 30
    assert n_bispectrum(8) == 55
    d = SnapDescriptors(SnapHyper(twojmax=4, rcutfac=4.0), ELEMENTS)
    blk = d(distorted_quartz(0))
    assert blk.energy.shape == (2 * (1 + n_bispectrum(4)),)


@pytest.mark.parametrize("quadratic", [False, True])
def test_design_rows_reproduce_pair_snap(tmp_path, quadratic):
    """E = a_E.beta, F = A_F beta, stress = A_S beta exactly as LAMMPS computes with the files."""
    hyper = SnapHyper(twojmax=4, rcutfac=4.2, quadratic=quadratic)
    desc = SnapDescriptors(hyper, ELEMENTS)
    rng = np.random.default_rng(1)
    beta = rng.normal(0.0, 0.01, desc.n_columns)
    coeffs = SnapCoefficients(tuple(ELEMENTS), hyper, desc.coefficients_from_vector(beta))
    coeff_path, _ = write_snap_files(tmp_path / "rand", coeffs)
    calc = snap_calculator(coeff_path)
    for seed, reps in ((2, (1, 1, 1)), (3, (2, 1, 1))):  # triclinic cells, rotated frames
        atoms = distorted_quartz(seed, reps)
        blk = desc(atoms)
        atoms.calc = calc
        np.testing.assert_allclose(atoms.get_potential_energy(), blk.energy @ beta, rtol=1e-12)
        np.testing.assert_allclose(atoms.get_forces().ravel(), blk.forces @ beta, atol=1e-10)
        # LAMMPS reports pressure in bar: agreement limited by its bar<->eV/Å^3 constant
        np.testing.assert_allclose(atoms.get_stress(), blk.stress @ beta, rtol=1e-6, atol=1e-9)


def test_forces_are_minus_energy_gradient():
    desc = SnapDescriptors(SnapHyper(twojmax=4, rcutfac=4.2), ELEMENTS)
    beta = np.random.default_rng(4).normal(0.0, 0.01, desc.n_columns)
    atoms = distorted_quartz(5)
    f = (desc(atoms).forces @ beta).reshape(-1, 3)
    h = 1e-5
    for i, k in ((0, 0), (4, 2), (8, 1)):
        e = []
        for s in (1, -1):
            a = atoms.copy()
            a.positions[i, k] += s * h
            e.append(desc(a).energy @ beta)
        assert f[i, k] == pytest.approx(-(e[0] - e[1]) / (2 * h), abs=1e-7)


def test_coefficient_file_round_trip(tmp_path):
    hyper = SnapHyper(twojmax=6, rcutfac=4.7, weights={"Si": 1.0, "O": 0.6})
    k = 1 + hyper.n_descriptor
    beta = {"Si": np.arange(k) * 0.1, "O": -np.arange(k) * 0.2}
    path, _ = write_snap_files(tmp_path / "x", SnapCoefficients(("Si", "O"), hyper, beta))
    back = read_snapcoeff(path)
    assert back.elements == ("Si", "O")
    assert back.hyper == hyper
    for el in ("Si", "O"):
        np.testing.assert_array_equal(back.beta[el], beta[el])


def test_fit_recovers_a_known_snap(tmp_path):
    """Data made by a SNAP are fitted back to the same coefficients (and the same physics)."""
    hyper = SnapHyper(twojmax=4, rcutfac=4.2)
    desc = SnapDescriptors(hyper, ELEMENTS)
    rng = np.random.default_rng(7)
    true = rng.normal(0.0, 0.02, desc.n_columns)
    true[0], true[desc.n_columns // 2] = -7.0, -3.0  # reference energies of Si and O
    coeff_path, _ = write_snap_files(
        tmp_path / "true", SnapCoefficients(("Si", "O"), hyper, desc.coefficients_from_vector(true))
    )
    calc = snap_calculator(coeff_path)
    frames = []
    for seed in range(12):
        a = distorted_quartz(100 + seed, (1, 1, 1) if seed % 2 else (1, 1, 2))
        if seed % 3 == 0:  # non-stoichiometric frames make the two reference energies identifiable
            del a[int(seed % len(a))]
        a.calc = calc
        f = labelled(a, a.get_potential_energy(), a.get_forces(), a.get_stress())
        f.info["config_type"] = "snap_made"
        frames.append(f)
    result = fit_snap(
        frames, ELEMENTS, [hyper], [FitSettings(100.0, 100.0)], ridges=(1e-14,), seed=0
    )
    got = np.concatenate([result.coefficients.beta[e] for e in ELEMENTS])
    ds = assemble(frames, compute_blocks(frames, hyper, ELEMENTS), ELEMENTS)
    np.testing.assert_allclose(ds.a_force @ got, ds.y_force, atol=1e-6)
    np.testing.assert_allclose(got, true, rtol=1e-4, atol=1e-6)
    assert result.errors["validation"]["force_rmse_mev_per_angstrom"] < 1e-3
