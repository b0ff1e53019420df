"""One grid point: fixed atoms, normal load, periodicity and symmetry of U (toy interface)."""

import numpy as np
import pytest
from ase.calculators.fd import calculate_numerical_forces

from flatcontact.ispes.contract import cell_area
from flatcontact.ispes.geometry import fixed_mask, in_plane_vectors, place_slab2, thickness
from flatcontact.ispes.relax import PointTask, RelaxSettings, relax_point
from flatcontact.ispes.toy import ToyPairCalculator
from flatcontact.units import EV_PER_A3_TO_GPA

TIGHT = RelaxSettings(fmax_ev_per_a=1e-5, optimizer="BFGS", max_steps=5000)


def relaxed(ref, a, b, z, settings=TIGHT, calc=None):
    return relax_point(ref, calc or ToyPairCalculator(), PointTask((0, 0, 0), a, b, z), settings)


def test_toy_forces_are_minus_energy_gradient(toy_reference):
    atoms = place_slab2(toy_reference, 0.3, 0.1, thickness(toy_reference) - 0.2)
    atoms.positions += np.random.default_rng(0).normal(scale=0.05, size=atoms.positions.shape)
    atoms.calc = ToyPairCalculator()
    np.testing.assert_allclose(
        atoms.get_forces(), calculate_numerical_forces(atoms, eps=1e-5), atol=1e-6
    )


def test_fixed_atoms_stay_fixed_and_free_atoms_converge(toy_reference):
    z = thickness(toy_reference) - 0.3
    placed = place_slab2(toy_reference, 0.37, 0.11, z)
    r = relaxed(toy_reference, 0.37, 0.11, z)
    fixed = fixed_mask(toy_reference)
    np.testing.assert_array_equal(r.positions[fixed], placed.positions[fixed])
    assert np.abs(r.positions[~fixed] - placed.positions[~fixed]).max() > 1e-3  # something relaxed
    assert r.converged and r.max_force_ev_per_a < TIGHT.fmax_ev_per_a
    assert r.force_calls >= r.steps >= 1


def test_load_is_minus_energy_derivative_along_a_column(toy_reference):
    """p = -(1/A) dU/dz (envelope theorem) from relaxed energies, compressed to tensile."""
    a1, a2 = in_plane_vectors(toy_reference)
    area = cell_area(a1, a2)
    z0, h = thickness(toy_reference), 2e-3
    for dz in (-0.3, 0.0, 0.4):
        lo, mid, hi = (relaxed(toy_reference, 0.21, 0.43, z0 + dz + d) for d in (-h, 0.0, h))
        fd_gpa = -(hi.energy_ev - lo.energy_ev) / (2 * h) / area * EV_PER_A3_TO_GPA
        assert mid.normal_stress_gpa == pytest.approx(fd_gpa, abs=2e-3)
        assert mid.reaction_stress_gpa == pytest.approx(fd_gpa, abs=2e-3)
    # sign: compressed is positive, stretched (adhesive) is negative
    assert relaxed(toy_reference, 0.0, 0.0, z0 - 0.3).normal_stress_gpa > 0.5
    assert relaxed(toy_reference, 0.0, 0.0, z0 + 0.4).normal_stress_gpa < -0.5


def test_rigid_body_load_is_robust_to_loose_tolerance(toy_reference):
    """At separation the load is zero; the fixed-atom reaction keeps the free atoms' residual."""
    z = thickness(toy_reference) + 8.0  # beyond the 6.25 Å cross cutoff
    loose = RelaxSettings(fmax_ev_per_a=2e-2, optimizer="FIRE")
    r = relaxed(toy_reference, 0.2, 0.3, z, settings=loose)
    assert abs(r.normal_stress_gpa) < 1e-12
    assert r.converged
    assert abs(r.reaction_stress_gpa) > 1e3 * abs(r.normal_stress_gpa)


def test_energy_is_periodic_over_the_cell(toy_reference):
    z = thickness(toy_reference) - 0.2
    base = relaxed(toy_reference, 0.25, 0.4, z)
    for a, b in ((1.25, 0.4), (0.25, -0.6), (-0.75, 1.4)):
        other = relaxed(toy_reference, a, b, z)
        assert other.energy_ev == pytest.approx(base.energy_ev, abs=1e-8)
        assert other.normal_stress_gpa == pytest.approx(base.normal_stress_gpa, abs=1e-5)


def test_mirror_symmetric_shifts_give_the_same_point(toy_reference):
    """fcc(111)/fcc(111) with ABC stacking on the a1+a2 diagonal is symmetric under a <-> b."""
    z = thickness(toy_reference) - 0.1
    for a, b in ((0.1, 0.3), (0.45, 0.2)):
        r1, r2 = relaxed(toy_reference, a, b, z), relaxed(toy_reference, b, a, z)
        assert r1.energy_ev == pytest.approx(r2.energy_ev, abs=1e-8)
        assert r1.normal_stress_gpa == pytest.approx(r2.normal_stress_gpa, abs=1e-5)
    # and the corrugation is real: different stackings differ
    top = relaxed(toy_reference, 2 / 3, 2 / 3, z)  # on top of slab 1's C layer
    fcc = relaxed(toy_reference, 0.0, 0.0, z)
    assert top.energy_ev - fcc.energy_ev > 1e-3


def test_warm_start_lands_on_the_same_point_with_fewer_force_calls(toy_reference):
    z0 = thickness(toy_reference)
    settings = RelaxSettings(fmax_ev_per_a=1e-4, optimizer="FIRE")
    calc = ToyPairCalculator()
    neighbour = relax_point(
        toy_reference, calc, PointTask((0, 0, 0), 0.25, 0.25, z0 - 0.2), settings
    )
    cold = relax_point(toy_reference, calc, PointTask((1, 0, 0), 0.5, 0.25, z0 - 0.2), settings)
    warm = relax_point(
        toy_reference,
        calc,
        PointTask(
            (1, 0, 0), 0.5, 0.25, z0 - 0.2, neighbour.positions, (0.25, 0.25), z0 - 0.2, (0, 0, 0)
        ),
        settings,
    )
    assert warm.energy_ev == pytest.approx(cold.energy_ev, abs=1e-6)
    assert warm.normal_stress_gpa == pytest.approx(cold.normal_stress_gpa, abs=5e-3)
    np.testing.assert_array_equal(
        warm.positions[fixed_mask(toy_reference)], cold.positions[fixed_mask(toy_reference)]
    )
