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


def _scan(tmp_path, name, symmetry, mode="normal", optimizer="LBFGS", fmax=0.005, **kwargs):
    ref = toy_interface_3()
    z0 = thickness(ref)
    return run_scan(
        ref,
        _toy_factory(),
        GridSpec(6, 6, thickness_angstrom=(z0 - 0.2, z0 + 0.3)),
        tmp_path / name,
        RelaxSettings(fmax, mode=mode, optimizer=optimizer),
        executor=SerialExecutor(),
        symmetry=symmetry,
        **kwargs,
    )


def test_reduced_toy_scan_equals_the_full_scan(tmp_path):
    """Relaxation along z only keeps the symmetry: the reduced grid is the full one, to what
    the relaxation tolerance leaves (an energy error of order fmax²/k: at fmax 0.005 eV/Å the
    two scans differ by up to 1.5e-3 meV/Å², at 5e-4 by 1.0e-5 to 1.7e-5)."""
    full = _scan(tmp_path, "full", SymmetrySettings(enabled=False), fmax=5e-4)
    red = _scan(tmp_path, "reduced", SymmetrySettings(verify_points=3), fmax=5e-4)
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
    assert de < 1e-4  # meV/Å²: the relaxation tolerance's scale, not the symmetry's
    assert bool(ds["converged"].all())
    assert int(ds.attrs["symmetry_order"]) == 6


def test_a_relaxation_that_breaks_the_symmetry_is_computed_in_full(tmp_path):
    """Full 3-D relaxation of the toy: at its unstable high-energy registries the free layer
    slides sideways (the full scan itself is not symmetric there, by up to 0.05 eV), though
    the structure has order 6. The verification at the highest orbits must see it. Where the
    layer slides depends on the relaxation's path (from cold starts no registry breaks the
    group): the construction is ASE's BFGS along the ``planes`` warm-start tree, whose full
    scan breaks the group by 0.053 eV (measured; the scan's own L-BFGS and ``columns`` tree
    break it elsewhere or not beyond 2e-4 eV)."""
    full = _scan(
        tmp_path, "full", SymmetrySettings(enabled=False), mode="full", optimizer="BFGS",
        order="planes",
    )  # fmt: skip
    e = full.dataset["energy"].values
    group = shift_space_group(toy_interface_3()).for_grid(6, 6)
    spread = max(np.ptp([e[a, b] for a, b in orbit], axis=0).max() for orbit in group.orbits(6, 6))
    assert spread > 1e-3  # the constructed case: the relaxed landscape breaks the group
    red = _scan(
        tmp_path, "reduced", SymmetrySettings(verify_points=24), mode="full", optimizer="BFGS",
        order="planes",
    )  # fmt: skip
    sym = red.symmetry
    assert sym["computed_in_full"]
    assert sym["verification"]["max_energy_difference_mev_per_a2"] > 0.01
    assert any("breaks the interface's shift-space symmetry" in n for n in red.notes)
    assert red.points_stored == 72 and not red.dataset["mapped"].any()
    assert int(red.dataset.attrs["symmetry_order"]) == 1  # the analysis must not symmetrise


def _reduced_toy_scan(out, **kwargs):
    return _scan(out.parent, out.name, SymmetrySettings(verify_points=3), **kwargs)


@pytest.mark.parametrize("phase", ["representatives", "verified points"])
def test_an_interrupted_and_resumed_reduced_scan_equals_an_uninterrupted_one(tmp_path, phase):
    """Ctrl-C partway: the partial ispes.nc maps the orbits of the stored representatives (and
    stores the group); the resumed scan writes the same ispes.nc as one that ran through."""
    from flatcontact.ispes.contract import open_ispes
    from flatcontact.ispes.scan import ScanInterrupted

    whole = _reduced_toy_scan(tmp_path / "whole")
    n_reps = whole.points_stored - 3
    # progress calls: one at the start of each phase, one per stored point
    stop_after = 5 if phase == "representatives" else n_reps + 2

    def stop(done, total, count=[0]):  # noqa: B006 - counts the calls of this run
        count[0] += 1
        if count[0] > stop_after:
            raise KeyboardInterrupt

    out = tmp_path / "stopped"
    with pytest.raises(ScanInterrupted) as info:
        _reduced_toy_scan(out, progress=stop)
    part = info.value.result.dataset
    stored = info.value.result.points_stored
    assert 0 < stored < whole.points_stored
    assert int(part.attrs["symmetry_order"]) == 6
    mapped = part["mapped"].values
    # every point whose representative is stored is filled, and only those
    assert mapped.sum() > 0
    assert int(np.isfinite(part["energy"].values).sum()) == stored + int(mapped.sum())
    on_disk = open_ispes(out / "ispes.nc")
    assert bool((on_disk["mapped"].values == mapped).all())
    resumed = _reduced_toy_scan(out)
    assert resumed.symmetry["verify_points"] == whole.symmetry["verify_points"]
    a, b = whole.dataset, resumed.dataset
    for name in ("energy", "normal_stress", "converged", "mapped", "force_calls"):
        np.testing.assert_array_equal(a[name].values, b[name].values, err_msg=name)
    for key in ("symmetry_order", "computed_points", "points_done"):
        np.testing.assert_array_equal(a.attrs[key], b.attrs[key], err_msg=key)


def test_the_fallback_names_the_failing_points_and_why_the_whole_grid(tmp_path):
    """A tolerance no relaxation meets: every verified point fails, scan.json-level record and
    note name them, and the grid is computed in full (not only their orbits)."""
    ref = toy_interface_3()
    z0 = thickness(ref)
    settings = SymmetrySettings(verify_points=2, energy_tolerance_mev_per_a2=1e-15)
    red = run_scan(
        ref,
        _toy_factory(),
        GridSpec(6, 6, thickness_angstrom=(z0 - 0.2, z0 + 0.3)),
        tmp_path / "red",
        RelaxSettings(mode="normal"),
        executor=SerialExecutor(),
        symmetry=settings,
    )
    sym = red.symmetry
    checked = sym["verification"]["checked"]
    assert sym["computed_in_full"] and len(checked) == 2
    bad = [c for c in checked if c["energy_difference_mev_per_a2"] > 1e-15]
    assert bad  # round-off alone exceeds 1e-15 meV/Å² somewhere
    reason = sym["computed_in_full_reason"]
    assert reason in red.notes
    for c in bad:
        assert str(tuple(c["point"])) in reason
    assert "unverified orbits" in reason
    assert red.points_stored == 72 and not red.dataset["mapped"].any()


def test_quartz_two_fold_axis_is_kept_on_the_scan_grids():
    """The quick preset's quartz interface: a slab-swapping two-fold axis whose half-cell
    translation the atoms give 1.5e-7 off (7e-7 Å, far inside the 1e-3 Å structure
    tolerance); on a 12 × 12 grid that is 1.8e-6 grid steps, which a fixed 1e-6 dropped."""
    from flatcontact.config import load_config as preset_config
    from flatcontact.stages.build import BuildInputs, build_stage

    reference = build_stage(preset_config(preset_name="quick"), BuildInputs(), None).atoms
    group = shift_space_group(reference)
    assert group.order == 2 and group.operations[1].swaps_slabs
    # the quick preset cuts the slabs at the bundled SNAP's own lattice, a = 4.9422 Å
    a = float(np.linalg.norm(reference.cell[0]))
    assert a == pytest.approx(4.9422, abs=1e-3)
    assert group.cell_lengths_angstrom == pytest.approx((a, a), abs=1e-6)
    for n in (6, 12, 24):
        assert group.for_grid(n, n).order == 2


def test_grid_tolerance_is_the_structure_tolerance():
    """An operation whose image of the grid is off the nodes by less than the structure
    tolerance (in Å along a1) maps the grid; by more, it does not."""
    from flatcontact.ispes.shift_symmetry import ShiftGroup, ShiftOperation

    identity = ShiftOperation(((1, 0), (0, 1)), (0.0, 0.0), False)
    length, tol = 5.0, 1e-3
    for off_angstrom, kept in ((0.5 * tol, True), (2.0 * tol, False)):
        shifted = ShiftOperation(((1, 0), (0, 1)), (0.5 + off_angstrom / length, 0.0), False)
        group = ShiftGroup((identity, shifted), tol, (length, length))
        assert group.for_grid(12, 12).order == (2 if kept else 1)
    # a node just below 1 is node 0 (periodic)
    below = ShiftOperation(((1, 0), (0, 1)), (1.0 - 0.5 * tol / length, 0.0), False)
    group = ShiftGroup((identity, below), tol, (length, length))
    assert group.for_grid(12, 12).order == 2
    np.testing.assert_array_equal(group.grid_images(12, 12)[1], group.grid_images(12, 12)[0])


def test_progress_of_a_reduced_scan_counts_grid_points(tmp_path):
    """One bar over the grid: a stored representative counts the points of its orbit, a
    verified point one more; it never goes back and ends at grid points + verified points."""
    calls = []
    red = _reduced_toy_scan(tmp_path / "bar", progress=lambda d, t: calls.append((d, t)))
    done = [d for d, _ in calls]
    assert done == sorted(done)
    n_verified = red.symmetry["verification"]["points"]
    assert n_verified == 3
    assert calls[-1] == (72 + n_verified, 72 + n_verified)
    assert all(t == 72 + 3 for _, t in calls)  # verify_points 3, all of them chosen
    # the representatives' phase ends with every grid point filled
    assert (72, 75) in calls
