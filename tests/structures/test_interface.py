"""The interface contract: tags, fixed atoms, thickness, placement of slab 2, extxyz round trip."""

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from flatcontact.foundation.errors import InputError
from flatcontact.structures.assemble import make_interface
from flatcontact.structures.interface_contract import fixed_mask, thickness
from flatcontact.structures.interface_io import read_interface, write_interface
from flatcontact.structures.placement import (
    MAX_SPREAD_STRAIN,
    MIN_INTERSLAB_DISTANCE_ANGSTROM,
    interslab_min_distance,
    place_slab2,
)
from flatcontact.structures.slab import quartz_0001_slab


@pytest.fixture(scope="module")
def reference():
    slab = quartz_0001_slab(layers=4, cut=2)
    return make_interface(slab, gap_angstrom=2.5, face_atoms=3, recipe={"test": "raw cut"})


def test_tags_and_fixed_atoms(reference):
    slab = reference.arrays["slab"]
    surface = reference.arrays["surface"]
    z = reference.positions[:, 2]
    n = len(reference) // 2
    assert np.all(slab[:n] == 1) and np.all(slab[n:] == 2)
    for tag in (1, 2, 3, 4):
        assert np.count_nonzero(surface == tag) == 3
    # surface 1 is the bottom of slab 1, surface 4 the top of slab 2
    assert z[surface == 1].max() < z[(slab == 1) & (surface != 1)].min()
    assert z[surface == 4].min() > z[(slab == 2) & (surface != 4)].max()
    assert z[surface == 2].max() < z[surface == 3].min()
    assert np.array_equal(fixed_mask(reference), np.isin(surface, (1, 4)))
    assert reference.pbc.tolist() == [True, True, False]


def test_thickness_definition(reference):
    z = reference.positions[:, 2]
    s = reference.arrays["surface"]
    assert thickness(reference) == pytest.approx(z[s == 4].mean() - z[s == 1].mean())


@settings(max_examples=25, deadline=None)
@given(
    sa=st.floats(-2.0, 2.0, allow_nan=False),
    sb=st.floats(-2.0, 2.0, allow_nan=False),
    dz=st.floats(0.0, 3.0, allow_nan=False),
)
def test_place_slab2_is_rigid_translation(reference, sa, sb, dz):
    target = thickness(reference) + dz
    moved = place_slab2(reference, sa, sb, target)
    assert thickness(moved) == pytest.approx(target, abs=1e-9)
    lower = reference.arrays["slab"] == 1
    assert np.allclose(moved.positions[lower], reference.positions[lower])
    # slab 2's internal geometry is unchanged (rigid), modulo lattice translations
    upper = ~lower
    a1, a2 = reference.info["a1"], reference.info["a2"]
    expected = reference.positions[upper] + np.array([*(sa * a1 + sb * a2), dz])
    delta = moved.positions[upper] - expected
    frac = np.linalg.solve(np.array([a1, a2]).T, delta[:, :2].T).T
    assert np.allclose(frac, np.round(frac), atol=1e-8)
    assert np.allclose(delta[:, 2], 0.0, atol=1e-9)
    # positions wrapped into the cell (ASE's wrap keeps fractions in [-1e-7, 1 - 1e-7))
    scaled = moved.get_scaled_positions(wrap=False)[:, :2]
    assert np.all((scaled >= -1e-6) & (scaled < 1 + 1e-6))


def test_place_slab2_periodic_in_lattice_vectors(reference):
    z = thickness(reference)
    a = place_slab2(reference, 0.3, 0.1, z)
    b = place_slab2(reference, 1.3, -0.9, z)
    assert np.allclose(a.positions, b.positions, atol=1e-9)


def test_place_slab2_refuses_overlap(reference):
    with pytest.raises(InputError, match="overlap"):
        place_slab2(reference, 0.0, 0.0, thickness(reference) - 4.0)
    ok = place_slab2(reference, 0.0, 0.0, thickness(reference))
    assert interslab_min_distance(ok) > MIN_INTERSLAB_DISTANCE_ANGSTROM


@pytest.fixture(scope="module")
def thick_reference():
    """12 O-Si-O layers per slab: a compliant stack that a rigid placement cannot load far."""
    slab = quartz_0001_slab(layers=12, cut=2)
    return make_interface(slab, gap_angstrom=2.5, face_atoms=3, recipe={"test": "raw cut"})


def test_place_slab2_spreads_a_compression_the_gap_cannot_take(thick_reference):
    ref = thick_reference
    z_ref = thickness(ref)
    target = z_ref - 3.0  # 6.9 % of the stack; rigidly, an Si faces an O 0.3 Å away at (0.5, 0)
    with pytest.raises(InputError, match="overlap"):
        place_slab2(ref, 0.5, 0.0, target, spread_compression=False)
    rigid = place_slab2(ref, 0.5, 0.0, z_ref)  # the same lateral placement, uncompressed
    spread = place_slab2(ref, 0.5, 0.0, target)
    assert thickness(spread) == pytest.approx(target, abs=1e-9)
    assert interslab_min_distance(spread) >= MIN_INTERSLAB_DISTANCE_ANGSTROM
    held = fixed_mask(ref)
    lower = ref.arrays["slab"] == 1
    # held layers: slab 1's untouched, slab 2's moved rigidly by dz
    assert np.allclose(spread.positions[held & lower], ref.positions[held & lower])
    dz = rigid.positions[held & ~lower] - spread.positions[held & ~lower]
    assert np.allclose(dz, [0.0, 0.0, 3.0], atol=1e-9)
    # free atoms: lateral as the rigid placement, heights an affine map fixing slab 1's held
    # layer and scaling every distance above it by z/z_ref (a homogeneous strain)
    free = ~held
    assert np.allclose(spread.positions[free, :2], rigid.positions[free, :2], atol=1e-9)
    h1 = ref.positions[held & lower, 2].mean()
    h = ref.positions[free, 2]
    assert np.allclose(spread.positions[free, 2] - h1, (h - h1) * target / z_ref, atol=1e-9)
    # the stacking order of the atomic planes is kept
    assert np.array_equal(
        np.argsort(h, kind="stable"), np.argsort(spread.positions[free, 2], kind="stable")
    )


def test_place_slab2_rigid_whenever_the_rigid_placement_fits(thick_reference):
    ref = thick_reference
    for dz in (0.5, 2.0):  # no overlap rigidly at (0, 0): the spread is not used
        placed = place_slab2(ref, 0.0, 0.0, thickness(ref) - dz)
        upper = ref.arrays["slab"] == 2
        assert np.allclose(placed.positions[upper, 2], ref.positions[upper, 2] - dz, atol=1e-9)
        assert np.allclose(placed.positions[~upper], ref.positions[~upper])


def test_place_slab2_refuses_a_spread_beyond_its_strain_bound(thick_reference):
    ref = thick_reference
    too_far = thickness(ref) * (1.0 - MAX_SPREAD_STRAIN) - 0.1
    with pytest.raises(InputError, match="overlap"):
        place_slab2(ref, 0.5, 0.0, too_far)


def test_extxyz_round_trip(reference, tmp_path):
    path = write_interface(reference, tmp_path / "interface.extxyz")
    back = read_interface(path)
    assert np.allclose(back.positions, reference.positions)
    assert np.array_equal(back.arrays["slab"], reference.arrays["slab"])
    assert np.array_equal(back.arrays["surface"], reference.arrays["surface"])
    assert np.allclose(back.info["a1"], reference.info["a1"])
    assert np.allclose(back.info["a2"], reference.info["a2"])
    assert json.loads(back.info["recipe"]) == {"test": "raw cut"}
    assert back.get_chemical_symbols() == reference.get_chemical_symbols()
    assert not list(tmp_path.glob("*.part"))


def test_read_interface_rejects_bad_arrays(reference, tmp_path):
    bad = reference.copy()
    bad.arrays["surface"] = bad.arrays["surface"].copy()
    bad.arrays["surface"][0] = 7
    from ase.io import write

    write(tmp_path / "bad.extxyz", bad, format="extxyz")
    with pytest.raises(InputError, match=r"bad\.extxyz.*surface"):
        read_interface(tmp_path / "bad.extxyz")
    with pytest.raises(InputError, match="not found"):
        read_interface(tmp_path / "missing.extxyz")
