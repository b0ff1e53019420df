"""The closest inter-slab distance (the scan's overlap check) against an all-pairs neighbour list."""

import numpy as np
import pytest
from ase.neighborlist import neighbor_list
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp
from scipy.spatial import cKDTree

from flatcontact.structures import placement
from flatcontact.structures.assemble import make_interface
from flatcontact.structures.interface_contract import thickness
from flatcontact.structures.placement import (
    _closest_pair_distance,
    interslab_min_distance,
    place_slab2,
)
from flatcontact.structures.slab import quartz_0001_slab


def all_pairs_min_distance(atoms, cutoff):
    """Independent: ASE's neighbour list of every pair, cross pairs kept."""
    slab = np.asarray(atoms.arrays["slab"])
    i, j, d = neighbor_list("ijd", atoms, cutoff)
    cross = slab[i] != slab[j]
    return float(d[cross].min()) if cross.any() else float("inf")


@pytest.fixture(scope="module")
def reference():
    return make_interface(quartz_0001_slab(layers=4, cut=2), gap_angstrom=3.0, face_atoms=3)


@pytest.mark.parametrize("cutoff", [2.0, 4.0, 7.0])
def test_matches_all_pairs_over_shifts_and_thicknesses(reference, cutoff):
    rng = np.random.default_rng(11)
    z0 = thickness(reference)
    seen_finite = seen_inf = False
    for _ in range(25):
        a, b = rng.random(2)
        z = z0 + rng.uniform(-2.5, 4.0)
        atoms = place_slab2(reference, a, b, z, min_distance_angstrom=0.0)
        expected = all_pairs_min_distance(atoms, cutoff)
        got = interslab_min_distance(atoms, cutoff)
        if np.isinf(expected):
            assert np.isinf(got)
            seen_inf = True
        else:
            assert got == pytest.approx(expected, abs=1e-9)
            seen_finite = True
    assert seen_finite and seen_inf  # both branches exercised


def test_tilted_small_cell_needs_several_images(reference):
    # a cutoff longer than the cell: the nearest image is beyond the first neighbour cell
    atoms = place_slab2(reference, 0.3, 0.6, thickness(reference) + 6.0, min_distance_angstrom=0.0)
    cutoff = 3.0 * float(np.linalg.norm(atoms.cell[0]))
    assert interslab_min_distance(atoms, cutoff) == pytest.approx(
        all_pairs_min_distance(atoms, cutoff), abs=1e-9
    )


#: clouds of 1-40 points, coordinates in ±30 Å (ties and repeated points included)
clouds = hnp.arrays(
    np.float64,
    st.tuples(st.integers(1, 40), st.just(3)),
    elements=st.floats(-30.0, 30.0, allow_nan=False, allow_infinity=False),
)


@settings(max_examples=300, deadline=None)
@given(points=clouds, queries=clouds)
def test_brute_force_distance_is_the_k_d_trees_bit_for_bit(points, queries):
    """The all-pairs minimum (numpy, small cells) is scipy's k-d tree's number exactly, so the
    overlap guard decides as before the brute force replaced the tree there."""
    d, _ = cKDTree(points).query(queries, k=1)
    assert _closest_pair_distance(points, queries) == float(d.min())


@pytest.mark.parametrize("cutoff", [2.0, 4.0, 7.0])
def test_brute_force_and_tree_agree_over_shifts_thicknesses_and_tilted_images(
    reference, cutoff, monkeypatch
):
    """interslab_min_distance with every pair compared (the default on these cells) and with
    the k-d tree forced (BRUTE_FORCE_MAX_PAIRS below every count) on periodic placements:
    the same float, inf included."""
    rng = np.random.default_rng(5)
    z0 = thickness(reference)
    cases = [
        place_slab2(
            reference, *rng.random(2), z0 + rng.uniform(-2.5, 4.0), min_distance_angstrom=0.0
        )
        for _ in range(40)
    ]
    brute = [interslab_min_distance(atoms, cutoff) for atoms in cases]
    monkeypatch.setattr(placement, "BRUTE_FORCE_MAX_PAIRS", -1)
    tree = [interslab_min_distance(atoms, cutoff) for atoms in cases]
    assert brute == tree
    assert any(np.isfinite(brute))


def test_overlap_check_validates_the_reference_once_and_places_as_place_slab2(
    reference, monkeypatch
):
    """The grid's overlap check validates the reference once, not at each of its points, and
    place_slab2 without validating gives the validated atoms exactly (and its overlap error)."""
    from flatcontact.foundation.errors import InputError
    from flatcontact.ispes import grid as grid_module
    from flatcontact.ispes.grid import GridSpec, check_thicknesses

    rng = np.random.default_rng(3)
    z0 = thickness(reference)
    for _ in range(10):
        a, b, z = *rng.random(2), z0 + rng.uniform(-0.5, 2.0)
        want = place_slab2(reference, a, b, z)
        got = place_slab2(reference, a, b, z, validate_reference=False)
        np.testing.assert_array_equal(got.positions, want.positions)
        np.testing.assert_array_equal(got.cell.array, want.cell.array)
    with pytest.raises(InputError, match="overlap"):
        place_slab2(reference, 0.0, 0.0, z0 - 4.0, validate_reference=False)
    calls = []
    real = grid_module.validate_interface
    monkeypatch.setattr(grid_module, "validate_interface", lambda *a: calls.append(1) or real(*a))
    check_thicknesses(reference, GridSpec(4, 4, thickness_angstrom=(z0,)), [z0, z0 + 1.0])
    assert len(calls) == 1
