"""The ideal work of separation: slabs relaxed alone against the zero-load interface.

Cu(111)/Cu(111) with Mishin's EAM is a crystal cut across one of its own planes, so
W = 2γ(111) of the potential; γ is computed here with ASE's own EAM code (not the
project's LAMMPS engine) from a relaxed slab with two free surfaces and the bulk energy per
atom. The toy LJ interface is checked against a lattice sum of its cross-slab pairs written
here (rigid slabs) and against an ASE relaxation with slab 2's held plane free along z.
"""

import numpy as np
import pytest
from ase.build import bulk, fcc111
from ase.calculators.eam import EAM
from ase.constraints import FixAtoms, FixCartesian
from ase.optimize import BFGS

from flatcontact.foundation.units import EV_PER_A2_TO_J_PER_M2
from flatcontact.ispes.executors import SerialExecutor
from flatcontact.ispes.geometry import fixed_mask, in_plane_vectors, place_slab2, thickness
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.relax import RelaxSettings
from flatcontact.ispes.scan import run_scan
from flatcontact.ispes.work_of_separation import ideal_work_of_separation
from flatcontact.potentials.engines import calculator_factory
from flatcontact.potentials.lammps_runtime import lammps_potential_file
from flatcontact.potentials.model import InteractionModel
from flatcontact.structures.construct import build_interface
from flatcontact.structures.toy import (
    CUTOFF_SIGMA,
    EPS_CROSS_EV,
    SIGMA_ANGSTROM,
    ToyPairCalculator,
    toy_interface,
)

A_CU = 3.615  # Mishin Cu1 lattice constant (Å)


def cu111_gamma_with_ase_eam(layers=12):
    """γ(111) (J/m²) of Mishin's Cu EAM: (E_slab − N e_bulk)/(2A), slab relaxed, two free faces."""
    potential = str(lammps_potential_file("Cu_mishin1.eam.alloy"))
    cu = bulk("Cu", "fcc", a=A_CU)
    cu.calc = EAM(potential=potential)
    e_bulk = cu.get_potential_energy() / len(cu)
    slab = fcc111("Cu", size=(1, 1, layers), a=A_CU, vacuum=10.0)
    slab.pbc = (True, True, False)
    slab.calc = EAM(potential=potential)
    BFGS(slab, logfile=None).run(fmax=1e-5, steps=500)
    area = abs(np.linalg.det(slab.cell.array[:2, :2]))
    return (slab.get_potential_energy() - len(slab) * e_bulk) / (2 * area) * EV_PER_A2_TO_J_PER_M2


@pytest.mark.parametrize("mode", ["normal", "full"])
def test_cu111_work_of_separation_is_twice_the_surface_energy(mode):
    gamma = cu111_gamma_with_ase_eam()
    assert gamma == pytest.approx(1.239, abs=0.005)  # Mishin et al. (2001): γ(111) = 1.239 J/m²
    interface, _ = build_interface(
        {"kind": "fcc111", "element": "Cu", "a_angstrom": A_CU, "layers": 6}
    )
    factory = calculator_factory(InteractionModel(preset="cu-eam"))
    w = ideal_work_of_separation(
        interface, factory, RelaxSettings(fmax_ev_per_angstrom=1e-4, mode=mode), (0.0, 0.0)
    )
    assert w.converged
    assert abs(w.zero_load_stress_gpa) < 0.01
    # one cut, two surfaces: 2γ (the probe's pull-off with free inner planes gave ≈ 4γ)
    assert w.work_of_separation_j_per_m2 == pytest.approx(2 * gamma, abs=0.005)


def _cross_energy_ev(atoms):
    """Shifted-force LJ energy of the slab-1/slab-2 pairs, summed over lateral images."""
    sigma, eps = SIGMA_ANGSTROM, EPS_CROSS_EV
    rc = CUTOFF_SIGMA * sigma

    def v(r):
        return 4 * eps * ((sigma / r) ** 12 - (sigma / r) ** 6)

    def dv(r):
        return 4 * eps * (-12 * (sigma / r) ** 12 + 6 * (sigma / r) ** 6) / r

    slab = atoms.arrays["slab"]
    cell = atoms.cell.array
    total = 0.0
    for ri in atoms.positions[slab == 1]:
        for rj in atoms.positions[slab == 2]:
            for m in range(-6, 7):
                for n in range(-6, 7):
                    r = np.linalg.norm(rj + m * cell[0] + n * cell[1] - ri)
                    if r < rc:
                        total += v(r) - v(rc) - (r - rc) * dv(rc)
    return total


def test_toy_rigid_work_of_separation_is_the_depth_of_the_cross_potential():
    """Rigid slabs: the slabs alone keep their energy, so W = −min_z E_cross(z)/A."""
    ref = toy_interface(layers=3)
    factory = calculator_factory(
        InteractionModel(calculator={"target": "flatcontact.ispes.toy:toy_calculator"})
    )
    w = ideal_work_of_separation(ref, factory, RelaxSettings(mode="rigid"), (0.0, 0.0))
    z0 = thickness(ref)
    zs = np.linspace(z0 - 0.3, z0 + 0.6, 181)
    e = np.array([_cross_energy_ev(place_slab2(ref, 0.0, 0.0, z)) for z in zs])
    k = int(np.argmin(e))
    c = np.polyfit(zs[k - 3 : k + 4], e[k - 3 : k + 4], 2)  # the minimum between samples
    e_min = np.polyval(c, -c[1] / (2 * c[0]))
    a1, a2 = in_plane_vectors(ref)
    area = abs(a1[0] * a2[1] - a1[1] * a2[0])
    assert w.zero_load_thickness_angstrom == pytest.approx(-c[1] / (2 * c[0]), abs=1e-3)
    assert w.work_of_separation_j_per_m2 == pytest.approx(
        -e_min / area * EV_PER_A2_TO_J_PER_M2, rel=1e-6
    )


def test_toy_relaxed_work_of_separation_matches_an_ase_relaxation():
    """Full relaxation: the zero-load interface is the minimum with slab 2's held plane
    (one atom in the toy) free along z; each slab alone is relaxed with its held plane fixed."""
    ref = toy_interface(layers=3)
    factory = calculator_factory(
        InteractionModel(calculator={"target": "flatcontact.ispes.toy:toy_calculator"})
    )
    w = ideal_work_of_separation(ref, factory, RelaxSettings(fmax_ev_per_angstrom=1e-5), (0.0, 0.0))

    def relaxed(atoms, constraints):
        atoms = atoms.copy()
        atoms.set_constraint(constraints)
        atoms.calc = ToyPairCalculator()
        BFGS(atoms, logfile=None).run(fmax=1e-7, steps=2000)
        return atoms.get_potential_energy()

    held = fixed_mask(ref)
    top_held = np.flatnonzero(held & (ref.arrays["slab"] == 2))
    e_int = relaxed(
        ref,
        [
            FixAtoms(mask=held & (ref.arrays["slab"] == 1)),
            FixCartesian(top_held, mask=(True, True, False)),
        ],
    )
    # each slab alone: its atoms in the same cell, the other slab removed
    alone = [ref[ref.arrays["slab"] == k] for k in (1, 2)]
    e_slabs = sum(relaxed(s, [FixAtoms(mask=fixed_mask(s))]) for s in alone)
    a1, a2 = in_plane_vectors(ref)
    area = abs(a1[0] * a2[1] - a1[1] * a2[0])
    expected = (e_slabs - e_int) / area * EV_PER_A2_TO_J_PER_M2
    assert expected > 0
    assert w.work_of_separation_j_per_m2 == pytest.approx(expected, rel=1e-5)


def test_hand_written_thicknesses_keep_the_work_of_separation(tmp_path):
    ref = toy_interface(layers=3)
    ref.arrays["held"] = np.isin(ref.arrays["surface"], (1, 4))
    factory = calculator_factory(
        InteractionModel(calculator={"target": "flatcontact.ispes.toy:toy_calculator"})
    )
    relax = RelaxSettings(fmax_ev_per_angstrom=1e-4)
    z0 = thickness(ref)
    auto = run_scan(
        ref,
        factory,
        GridSpec(3, 3, p_range_gpa=(0.0, 1.0, 3)),
        tmp_path / "a",
        relax,
        executor=SerialExecutor(),
    )
    given = run_scan(
        ref,
        factory,
        GridSpec(3, 3, thickness_angstrom=(z0 - 0.2, z0, z0 + 0.3)),
        tmp_path / "b",
        relax,
        executor=SerialExecutor(),
    )
    w_auto = auto.adhesion["work_of_separation_j_per_m2"]
    assert w_auto > 0
    assert given.adhesion["work_of_separation_j_per_m2"] == pytest.approx(w_auto, rel=1e-12)
    # the probe's pull-off is kept beside it as a diagnostic, only where a probe ran
    assert auto.adhesion["pull_off_work_j_per_m2"] > 0
    assert "pull_off_work_j_per_m2" not in given.adhesion
    assert given.dataset.attrs["work_of_separation_j_per_m2"] == pytest.approx(w_auto, rel=1e-12)


@pytest.mark.parametrize("name", ["graphene-bilayer-kc", "graphene-bilayer-ilp"])
def test_interlayer_work_of_separation_is_the_depth_of_the_plain_lammps_curve(name):
    """Two rigid graphene sheets (REBO inside, KC or ILP across):
    W = −[min_z E(z) − E(apart)]/A with E from plain LAMMPS (rigid layers, shift 0)."""
    from scipy.optimize import minimize_scalar
    from tests.examples.test_examples import EXAMPLES, plain_energy_per_area

    from flatcontact.config import load_config

    cfg = load_config(EXAMPLES / f"{name}.yaml")
    ref, _ = build_interface(cfg.structure)
    w = ideal_work_of_separation(
        ref, calculator_factory(cfg.potential), RelaxSettings(mode=cfg.scan.relax_mode), (0, 0)
    )
    well = minimize_scalar(
        lambda z: plain_energy_per_area(ref, (0, 0), z, name),
        bounds=(3.0, 4.0),
        method="bounded",
        options={"xatol": 1e-5},
    )
    apart = plain_energy_per_area(ref, (0, 0), 60.0, name)
    assert w.zero_load_thickness_angstrom == pytest.approx(well.x, abs=1e-3)
    assert w.work_of_separation_j_per_m2 == pytest.approx(
        (apart - well.fun) * EV_PER_A2_TO_J_PER_M2, rel=1e-6
    )
