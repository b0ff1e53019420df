"""One grid point: fixed atoms, normal load, periodicity and symmetry of U (toy interface)."""

import numpy as np
import pytest
from ase.calculators.calculator import Calculator, all_changes
from ase.calculators.fd import calculate_numerical_forces
from ase.neighborlist import neighbor_list

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.units import EV_PER_A3_TO_GPA
from flatcontact.ispes.contract import cell_area
from flatcontact.ispes.geometry import fixed_mask, in_plane_vectors, place_slab2, thickness
from flatcontact.ispes.relax import PointTask, RelaxSettings, relax_point
from flatcontact.structures.construct import build_interface
from flatcontact.structures.toy import ToyPairCalculator

TIGHT = RelaxSettings(fmax_ev_per_angstrom=1e-5, optimizer="BFGS", max_steps=5000)


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
    assert r.converged and r.max_force_ev_per_a < TIGHT.fmax_ev_per_angstrom
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
    loose = RelaxSettings(fmax_ev_per_angstrom=2e-2, optimizer="FIRE")
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
    settings = RelaxSettings(fmax_ev_per_angstrom=1e-4, optimizer="FIRE")
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


# --------------------------------------------------------------------------- relaxation modes
class SheetPairCalculator(Calculator):
    """Symmetric toy model of stacked sheets, written here (independent of flatcontact).

    Harmonic bonds k (r - r0)² / 2 between atoms of the same layer closer than 1.8 Å,
    shifted Lennard-Jones 4ε[(σ/r)¹² - (σ/r)⁶] - V(rc) between atoms of different layers.
    """

    implemented_properties = ("energy", "free_energy", "forces")

    def __init__(self, r0=2.46 / np.sqrt(3), k=20.0, eps=0.005, sigma=3.0, rc=8.0):
        super().__init__()
        self.r0, self.k, self.eps, self.sigma, self.rc = r0, k, eps, sigma, rc

    def calculate(self, atoms=None, properties=("energy",), system_changes=all_changes):
        super().calculate(atoms, properties, system_changes)
        i, j, d, vec = neighbor_list("ijdD", self.atoms, self.rc)
        layer = np.asarray(self.atoms.arrays["layer"])
        same = layer[i] == layer[j]
        bond = same & (d < 1.8)
        cross = ~same
        s6 = (self.sigma / d) ** 6
        sc6 = (self.sigma / self.rc) ** 6
        e = np.where(bond, 0.5 * self.k * (d - self.r0) ** 2, 0.0)
        e += np.where(cross, 4 * self.eps * (s6 * s6 - s6 - (sc6 * sc6 - sc6)), 0.0)
        de = np.where(bond, self.k * (d - self.r0), 0.0)
        de += np.where(cross, 4 * self.eps * (-12 * s6 * s6 + 6 * s6) / d, 0.0)
        f = (de / d)[:, None] * vec
        n = len(self.atoms)
        forces = np.stack([np.bincount(i, weights=f[:, c], minlength=n) for c in range(3)], 1)
        energy = 0.5 * float(e.sum())
        self.results = {"energy": energy, "free_energy": energy, "forces": forces}


def _sheets(layers):
    atoms, _ = build_interface(
        {"kind": "sheets", "sheet": "graphene", "layers": layers, "stacking": "A"}
    )
    return atoms


def test_sheet_toy_forces_are_minus_energy_gradient():
    atoms = _sheets(2)
    atoms.positions += np.random.default_rng(1).normal(scale=0.03, size=atoms.positions.shape)
    atoms.calc = SheetPairCalculator()
    np.testing.assert_allclose(
        atoms.get_forces(), calculate_numerical_forces(atoms, eps=1e-5), atol=1e-6
    )


@pytest.mark.parametrize("mode", ["full", "normal", "rigid-layers", "rigid"])
def test_AB_and_BA_bilayer_are_equal_in_every_mode(mode):
    """Bilayer of monolayers, each held whole: AB (2/3, 1/3) and BA (1/3, 2/3) from AA."""
    ref = _sheets(1)
    z = thickness(ref)
    settings = RelaxSettings(fmax_ev_per_angstrom=1e-6, optimizer="BFGS", max_steps=5000, mode=mode)
    ab = relaxed(ref, 2 / 3, 1 / 3, z, settings, SheetPairCalculator())
    ba = relaxed(ref, 1 / 3, 2 / 3, z, settings, SheetPairCalculator())
    aa = relaxed(ref, 0.0, 0.0, z, settings, SheetPairCalculator())
    assert ab.energy_ev == pytest.approx(ba.energy_ev, abs=1e-12)
    assert ab.normal_stress_gpa == pytest.approx(ba.normal_stress_gpa, abs=1e-10)
    assert aa.energy_ev - ab.energy_ev > 1e-4  # AA is the repulsive stacking
    assert ab.steps == 0 and ab.converged  # every atom held: nothing relaxes


@pytest.mark.parametrize("mode", ["full", "normal", "rigid-layers", "rigid"])
def test_mirror_related_shifts_stay_equal_with_free_layers(mode):
    """AA-stacked two-sheet slabs: the mirror z -> -z maps shift s onto -s, so U(s) = U(-s)
    (AB = BA included) in every mode, with the inner sheets free and the outer ones held."""
    ref = _sheets(2)
    assert ref.arrays["held"].tolist() == [True, True, False, False, False, False, True, True]
    z = thickness(ref) - 0.3
    settings = RelaxSettings(fmax_ev_per_angstrom=1e-6, optimizer="BFGS", max_steps=5000, mode=mode)
    for a, b in ((0.23, 0.11), (2 / 3, 1 / 3)):
        plus = relaxed(ref, a, b, z, settings, SheetPairCalculator())
        minus = relaxed(ref, -a, -b, z, settings, SheetPairCalculator())
        assert plus.converged and minus.converged
        assert plus.energy_ev == pytest.approx(minus.energy_ev, abs=1e-9)
        assert plus.normal_stress_gpa == pytest.approx(minus.normal_stress_gpa, abs=1e-5)


def test_modes_are_nested_minimisations():
    """More freedom, lower energy: U_full <= U_normal <= U_rigid-layers < U_rigid at the same
    point; normal moves atoms along z only, rigid-layers moves whole layers along z, rigid
    moves nothing."""
    ref = _sheets(2)
    z = thickness(ref) - 0.4
    energies = {}
    placed = place_slab2(ref, 0.23, 0.11, z)
    free = ~fixed_mask(ref)
    layer = ref.arrays["layer"]
    for mode in ("rigid", "rigid-layers", "normal", "full"):
        settings = RelaxSettings(
            fmax_ev_per_angstrom=1e-6, optimizer="BFGS", max_steps=5000, mode=mode
        )
        r = relaxed(ref, 0.23, 0.11, z, settings, SheetPairCalculator())
        assert r.converged
        energies[mode] = r.energy_ev
        moved = r.positions - placed.positions
        if mode == "rigid":
            np.testing.assert_array_equal(r.positions, placed.positions)
            assert r.steps == 0 and r.force_calls == 1
            single = placed.copy()
            single.calc = SheetPairCalculator()
            assert r.energy_ev == single.get_potential_energy()
        if mode == "rigid-layers":
            np.testing.assert_array_equal(moved[:, :2], 0.0)
            for k in (2, 3):  # each free sheet shifted as a whole along z
                dz = moved[layer == k, 2]
                assert np.ptp(dz) < 1e-12 and abs(dz[0]) > 1e-4
        if mode == "normal":
            np.testing.assert_array_equal(moved[:, :2], 0.0)
            assert np.abs(moved[free, 2]).max() > 1e-3
        if mode == "full":
            assert np.abs(moved[free, :2]).max() > 1e-5
    assert energies["full"] <= energies["normal"] + 1e-10
    assert energies["normal"] <= energies["rigid-layers"] + 1e-10
    assert energies["rigid-layers"] < energies["rigid"] - 1e-5


@pytest.mark.parametrize("mode", ["normal", "rigid-layers"])
def test_constrained_modes_load_is_minus_energy_derivative(toy_reference, mode):
    """The envelope theorem holds for the constrained (z-only, rigid-layer) minima too."""
    a1, a2 = in_plane_vectors(toy_reference)
    area = cell_area(a1, a2)
    z0, h = thickness(toy_reference) - 0.2, 2e-3
    settings = RelaxSettings(fmax_ev_per_angstrom=1e-6, optimizer="BFGS", max_steps=5000, mode=mode)
    lo, mid, hi = (relaxed(toy_reference, 0.21, 0.43, z0 + d, settings) for d in (-h, 0.0, h))
    fd_gpa = -(hi.energy_ev - lo.energy_ev) / (2 * h) / area * EV_PER_A3_TO_GPA
    assert mid.normal_stress_gpa == pytest.approx(fd_gpa, abs=2e-3)
    assert mid.steps >= 1


def test_unknown_mode_is_refused():
    with pytest.raises(InputError, match="mode: 'relaxed'"):
        RelaxSettings(mode="relaxed")


def test_mode_enters_the_store_fingerprint_only_when_not_full():
    from flatcontact.ispes.store import interface_hash

    assert "mode" not in RelaxSettings().as_dict()  # stores written before the modes stay valid
    assert RelaxSettings(mode="normal").as_dict()["mode"] == "normal"
    ref = _sheets(1)  # held monolayers tagged 2 / 3: the held atoms are not the default
    other = ref.copy()
    other.arrays["held"] = np.isin(other.arrays["surface"], (1, 4))
    assert interface_hash(ref) != interface_hash(other)
    plain = ref.copy()
    del plain.arrays["held"]
    assert interface_hash(plain) == interface_hash(other)


def test_a_bilayer_of_held_monolayers_is_a_valid_scan_interface():
    from flatcontact.ispes.scan import check_interface

    ref = _sheets(1)
    assert fixed_mask(ref).all()
    check_interface(ref)  # nothing to relax is a rigid scan, not an error


@pytest.mark.parametrize("mode", ["normal", "rigid-layers"])
def test_warm_start_keeps_the_mode_constraints(mode):
    """A warm start from a fully relaxed neighbour lands on the same constrained minimum."""
    ref = _sheets(2)
    z = thickness(ref) - 0.3
    tight = RelaxSettings(fmax_ev_per_angstrom=1e-6, optimizer="BFGS", max_steps=5000, mode=mode)
    full = RelaxSettings(fmax_ev_per_angstrom=1e-6, optimizer="BFGS", max_steps=5000)
    calc = SheetPairCalculator()
    neighbour = relax_point(ref, calc, PointTask((0, 0, 0), 0.2, 0.1, z), full)
    cold = relax_point(ref, calc, PointTask((1, 0, 0), 0.3, 0.1, z), tight)
    warm = relax_point(
        ref,
        calc,
        PointTask((1, 0, 0), 0.3, 0.1, z, neighbour.positions, (0.2, 0.1), z, (0, 0, 0)),
        tight,
    )
    assert warm.energy_ev == pytest.approx(cold.energy_ev, abs=1e-9)
    placed = place_slab2(ref, 0.3, 0.1, z)
    np.testing.assert_array_equal(warm.positions[:, :2], placed.positions[:, :2])
    if mode == "rigid-layers":
        layer = ref.arrays["layer"]
        for k in (2, 3):
            assert np.ptp(warm.positions[layer == k, 2] - placed.positions[layer == k, 2]) < 1e-12
