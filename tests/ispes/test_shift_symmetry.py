"""Shift-space group of interfaces and the irreducible-registry scan.

Hand-derived group orders (operations s ↦ M s + t of the lateral shift, modulo the lattice):

- fcc(111) bicrystal continuing the stacking (Cu, 4 + 4 planes): each slab has the point
  group 3m about the same atom columns (C3 about A/B/C columns; the three mirrors through
  them that keep the ABC order), the γ-surface is not centrosymmetric: order 6.
- AB bilayer graphene (rigid sheets): each sheet is 6mm about its hexagon centre; every one
  of the 12 operations acts on the shift about the AA registry: order 12.
- h-BN AA′ (slab 2 = slab 1 turned by 180°): each sheet is 3m (C2 swaps B and N); the
  common 3m plus sheet-swapping two-fold axes that act like its mirrors: order 6.
"""

import numpy as np
import pytest
from tests.examples.test_examples import EXAMPLES

from flatcontact.config.load import load_config
from flatcontact.ispes.executors import SerialExecutor
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.reduction import SymmetrySettings
from flatcontact.ispes.relax import RelaxSettings
from flatcontact.ispes.scan import run_scan
from flatcontact.ispes.shift_symmetry import shift_space_group
from flatcontact.potentials.engines import calculator_factory
from flatcontact.potentials.model import InteractionModel
from flatcontact.structures.construct import build_interface
from flatcontact.structures.interface_contract import thickness
from flatcontact.structures.placement import place_slab2
from flatcontact.structures.toy import ToyPairCalculator


def _example(name):
    atoms, _ = build_interface(load_config(EXAMPLES / f"{name}.yaml").structure)
    return atoms


@pytest.mark.parametrize(
    ("name", "order"),
    [("cu111-eam", 6), ("graphene-bilayer-kc", 12), ("hbn-bilayer-ilp", 6)],
)
def test_group_order_of_known_interfaces(name, order):
    group = shift_space_group(_example(name))
    assert group.order == order
    assert group.operations[0].is_identity
    assert group.for_grid(6, 6).order == order  # 1/6 steps contain every special registry
    # a group: closed under composition (M2 M1, M2 t1 + t2 mod 1)
    keys = {(op.matrix, tuple(np.round(op.translation, 6) % 1)) for op in group.operations}
    for g1 in group.operations:
        for g2 in group.operations:
            m = np.array(g2.matrix) @ np.array(g1.matrix)
            t = (np.array(g2.matrix) @ np.array(g1.translation) + g2.translation) % 1
            key = (tuple(tuple(int(v) for v in r) for r in m), tuple(np.round(t, 6) % 1))
            assert key in keys


def test_rigid_energies_of_the_toy_obey_its_group():
    """Independent of the matching: the pair energy of the placed stack is equal at s and g·s."""
    ref = toy_interface_3()
    group = shift_space_group(ref)
    assert group.order == 6
    z = thickness(ref)
    calc = ToyPairCalculator()
    rng = np.random.default_rng(3)
    for s in rng.random((4, 2)):
        e0 = _energy(ref, s, z, calc)
        for op in group.operations[1:]:
            assert _energy(ref, op.apply(s), z, calc) == pytest.approx(e0, rel=1e-10, abs=1e-12)
    # and a non-member (the shift's inversion) changes it
    s = np.array([0.21, 0.07])
    assert abs(_energy(ref, (-s) % 1, z, calc) - _energy(ref, s, z, calc)) > 1e-6


def toy_interface_3():
    from flatcontact.structures.toy import toy_interface

    return toy_interface(layers=3)


def _energy(ref, s, z, calc):
    atoms = place_slab2(ref, float(s[0]), float(s[1]), z)
    atoms.calc = calc
    return atoms.get_potential_energy()


def test_a_displaced_atom_lowers_the_group_unless_the_tolerance_covers_it():
    ref = _example("cu111-eam")
    free = np.flatnonzero(~ref.arrays["held"] & (ref.arrays["slab"] == 1))[0]
    ref.positions[free, 0] += 0.01
    assert shift_space_group(ref, 1e-3).order < 6
    assert shift_space_group(ref, 0.05).order == 6


def _toy_factory():
    return calculator_factory(
        InteractionModel(calculator={"target": "flatcontact.ispes.toy:toy_calculator"})
    )


def _scan(tmp_path, name, symmetry, mode="normal"):
    ref = toy_interface_3()
    z0 = thickness(ref)
    return run_scan(
        ref,
        _toy_factory(),
        GridSpec(6, 6, thickness_angstrom=(z0 - 0.2, z0 + 0.3)),
        tmp_path / name,
        RelaxSettings(mode=mode),
        executor=SerialExecutor(),
        symmetry=symmetry,
    )


def test_reduced_toy_scan_equals_the_full_scan(tmp_path):
    """Relaxation along z only keeps the symmetry: the reduced grid is the full one."""
    full = _scan(tmp_path, "full", SymmetrySettings(enabled=False))
    red = _scan(tmp_path, "reduced", SymmetrySettings(verify_points=3))
    assert full.symmetry is None and full.points_stored == 72
    sym = red.symmetry
    assert sym["order"] == 6 and not sym["computed_in_full"]
    assert sym["verification"]["points"] == 3
    n_orbits = len(shift_space_group(toy_interface_3()).for_grid(6, 6).orbits(6, 6))
    assert red.points_stored == 2 * n_orbits + 3 < 72
    ds, df = red.dataset, full.dataset
    assert int(ds["mapped"].sum()) == 72 - red.points_stored
    assert ds.attrs["computed_points"] == red.points_stored and ds.attrs["grid_points"] == 72
    area = float(ds.attrs["area"])
    de = np.abs(ds["energy"].values - df["energy"].values).max() / area * 1e3
    assert de < 1e-3  # meV/Å²: the relaxation tolerance's scale, not the symmetry's
    assert bool(ds["converged"].all())
    assert int(ds.attrs["symmetry_order"]) == 6


def test_a_relaxation_that_breaks_the_symmetry_is_computed_in_full(tmp_path):
    """Full 3-D relaxation of the toy: at its unstable high-energy registries the free layer
    slides sideways (the full scan itself is not symmetric there, by up to 0.03 eV), though
    the structure has order 6. The verification at the highest orbits must see it."""
    full = _scan(tmp_path, "full", SymmetrySettings(enabled=False), mode="full")
    e = full.dataset["energy"].values
    group = shift_space_group(toy_interface_3()).for_grid(6, 6)
    spread = max(np.ptp([e[a, b] for a, b in orbit], axis=0).max() for orbit in group.orbits(6, 6))
    assert spread > 1e-3  # the constructed case: the relaxed landscape breaks the group
    red = _scan(tmp_path, "reduced", SymmetrySettings(verify_points=24), mode="full")
    sym = red.symmetry
    assert sym["computed_in_full"]
    assert sym["verification"]["max_energy_difference_mev_per_a2"] > 0.01
    assert any("breaks the interface's shift-space symmetry" in n for n in red.notes)
    assert red.points_stored == 72 and not red.dataset["mapped"].any()
    assert int(red.dataset.attrs["symmetry_order"]) == 1  # the analysis must not symmetrise
