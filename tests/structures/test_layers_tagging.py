"""Layers found by the structure and the contract's tags: graphene, MoS2, Cu(111), quartz."""

import json

import numpy as np
import pytest
from ase.build import bulk
from ase.io import write

from flatcontact.foundation.errors import InputError
from flatcontact.structures.assemble import face_tags, make_interface
from flatcontact.structures.build import load_shipped_dense_slab
from flatcontact.structures.construct import build_interface
from flatcontact.structures.dense import QUARTZ_ATOMS_PER_LAYER
from flatcontact.structures.interface_contract import fixed_mask, thickness, validate_interface
from flatcontact.structures.interface_io import read_interface, write_interface
from flatcontact.structures.layers import atomic_planes, chunk_layers, sheet_layers
from flatcontact.structures.quartz_layers import DENSE_FACE_LAYERS


def test_graphene_bilayer_of_monolayers_is_one_held_layer_per_slab():
    atoms, report = build_interface({"kind": "sheets", "sheet": "graphene", "stacking": "AB"})
    assert len(atoms) == 4
    assert atoms.arrays["slab"].tolist() == [1, 1, 2, 2]
    assert atoms.arrays["layer"].tolist() == [1, 1, 2, 2]
    # one-layer slab: the layer is its own inner face (2 / 3) and is held whole
    assert atoms.arrays["surface"].tolist() == [2, 2, 3, 3]
    assert atoms.arrays["held"].all() and fixed_mask(atoms).all()
    # thickness of a bilayer of monolayers = the interlayer distance (graphite, 3.35 Å)
    assert thickness(atoms) == pytest.approx(3.35, abs=1e-9)
    # AB (Bernal): one sublattice of layer 2 over an atom of layer 1, the other over a hollow
    lower, upper = atoms.positions[:2, :2], atoms.positions[2:, :2]
    cell = atoms.cell.array[:2, :2]

    def lateral(p, q):
        d = np.linalg.solve(cell.T, q - p)
        d -= np.round(d)
        return np.linalg.norm(d @ cell)

    over = [min(lateral(p, q) for p in lower) for q in upper]
    assert sorted(np.round(over, 6)) == [0.0, pytest.approx(1.42028, abs=1e-4)]
    validate_interface(atoms)
    assert json.loads(atoms.info["recipe"])["kind"] == "sheets"
    assert report["material"] == "graphene"


def test_mos2_three_layers_per_slab_found_by_bonds():
    atoms, _ = build_interface({"kind": "sheets", "sheet": "MoS2", "layers": 3, "stacking": "AA'"})
    layer = atoms.arrays["layer"]
    assert layer.max() == 6
    for k in range(1, 7):  # each layer is one S-Mo-S sheet
        assert sorted(np.array(atoms.get_chemical_symbols())[layer == k]) == ["Mo", "S", "S"]
    # the bonded-component rule finds the same layers from the positions alone
    np.testing.assert_array_equal(sheet_layers(atoms), layer)
    # whereas atomic planes would split each sheet into three planes
    assert atomic_planes(atoms.positions[:, 2]).max() + 1 == 18
    surface = atoms.arrays["surface"]
    assert surface[layer == 1].tolist() == [1, 1, 1]
    assert set(surface[np.isin(layer, (2, 5))]) == {0}
    assert surface[layer == 3].tolist() == [2, 2, 2] and surface[layer == 4].tolist() == [3, 3, 3]
    assert surface[layer == 6].tolist() == [4, 4, 4]
    assert atoms.arrays["held"].tolist() == np.isin(layer, (1, 6)).tolist()
    # 2H stacking: Mo of each layer above the S of the one below; Mo-Mo distance 6.15 Å
    mo = atoms.positions[np.array(atoms.get_chemical_symbols()) == "Mo"]
    np.testing.assert_allclose(np.diff(mo[:, 2]), 6.15, atol=1e-9)
    assert thickness(atoms) == pytest.approx(5 * 6.15, abs=1e-9)


def test_cu111_six_layers_from_fcc111_and_from_a_cif(tmp_path):
    a = 3.615
    built, _ = build_interface({"kind": "fcc111", "element": "Cu", "a_angstrom": a, "layers": 6})
    cif = tmp_path / "Cu.cif"
    write(cif, bulk("Cu", "fcc", a=a, cubic=True))
    cut, report = build_interface(
        {"kind": "crystal", "bulk": str(cif), "miller": [1, 1, 1], "layers": 6}
    )
    d111 = a / np.sqrt(3.0)
    for atoms in (built, cut):
        assert len(atoms) == 12
        assert atoms.arrays["layer"].tolist() == list(range(1, 13))
        assert atoms.arrays["surface"].tolist() == [1, 0, 0, 0, 0, 2, 3, 0, 0, 0, 0, 4]
        assert atoms.arrays["held"].tolist() == [True] + [False] * 10 + [True]
        # slab 2 continues the crystal: 12 planes d111 apart, ABC stacking (shift a/√3 per plane)
        np.testing.assert_allclose(np.diff(np.sort(atoms.positions[:, 2])), d111, atol=1e-9)
        assert thickness(atoms) == pytest.approx(11 * d111, abs=1e-9)
        assert np.linalg.norm(atoms.cell[0]) == pytest.approx(a / np.sqrt(2.0), abs=1e-9)
        xy = atoms.positions[:, :2]
        cell = atoms.cell.array[:2, :2]
        frac = np.linalg.solve(cell.T, (xy[3] - xy[0]).T)
        assert np.allclose(frac - np.round(frac), 0.0, atol=1e-9)  # A..A every third plane
        frac = np.linalg.solve(cell.T, (xy[1] - xy[0]).T)
        assert not np.allclose(frac - np.round(frac), 0.0, atol=1e-3)
    rec = json.loads(cut.info["recipe"])
    assert rec["slab1"]["miller"] == [1, 1, 1] and rec["slab1"]["file"] == "Cu.cif"
    assert len(rec["slab1"]["sha256"]) == 64
    assert report["material"] == "Cu(111)"


def test_quartz_interface_tags_unchanged():
    """The shipped dense slab made into an interface: surface tags as before, held = surfaces
    1 and 4, the thickness the paper's, layers = the dense face (2 units) + O-Si-O units."""
    slab, _ = load_shipped_dense_slab()
    face = DENSE_FACE_LAYERS * QUARTZ_ATOMS_PER_LAYER
    ref = make_interface(
        slab, 3.0, face_atoms=face, slab_layers=chunk_layers(slab, face, QUARTZ_ATOMS_PER_LAYER)
    )
    tags = face_tags(slab, face_atoms=face)
    expected = np.concatenate(
        [np.select([tags == 1, tags == 2], [1, 2], 0), np.select([tags == 1, tags == 2], [3, 4], 0)]
    )
    np.testing.assert_array_equal(ref.arrays["surface"], expected)
    np.testing.assert_array_equal(ref.arrays["held"], np.isin(expected, (1, 4)))
    z, s = ref.positions[:, 2], ref.arrays["surface"]
    assert thickness(ref) == pytest.approx(z[s == 4].mean() - z[s == 1].mean(), abs=1e-12)
    layer = ref.arrays["layer"]
    counts = [int(np.sum(layer == k)) for k in range(1, layer.max() + 1)]
    assert counts == [6, 3, 3, 6, 6, 3, 3, 6]  # 6 O-Si-O units per slab, dense face = 2 units
    for k in range(1, 9):  # every unit and face layer is stoichiometric SiO2
        sym = np.array(ref.get_chemical_symbols())[layer == k]
        assert 2 * np.sum(sym == "Si") == np.sum(sym == "O")
    validate_interface(ref)


def test_quartz_recipe_is_the_dense_builder():
    """build_interface(quartz-dense) = build_quartz_interface (same positions, tags, thickness)."""
    from flatcontact.potentials import InteractionModel
    from flatcontact.structures.build import QUARTZ_MATERIAL, build_quartz_interface

    spec = InteractionModel(intra="vashishta")
    atoms, report = build_interface({"kind": "quartz-dense", "source": "shipped"}, potential=spec)
    direct, _ = build_quartz_interface(spec, layers=6, source="shipped")
    np.testing.assert_array_equal(atoms.positions, direct.positions)
    np.testing.assert_array_equal(atoms.arrays["surface"], direct.arrays["surface"])
    np.testing.assert_array_equal(atoms.arrays["held"], np.isin(atoms.arrays["surface"], (1, 4)))
    assert atoms.info["material"] == QUARTZ_MATERIAL
    assert report["thickness_angstrom"] == thickness(atoms)
    with pytest.raises(InputError, match="needs a potential"):
        build_interface({"kind": "quartz-dense"})


def test_old_interface_file_gets_default_held_and_found_layers(tmp_path):
    atoms, _ = build_interface(
        {"kind": "sheets", "sheet": "graphene", "layers": 2, "stacking": "AB"}
    )
    path = write_interface(atoms, tmp_path / "new.extxyz")
    back = read_interface(path)
    np.testing.assert_array_equal(back.arrays["layer"], atoms.arrays["layer"])
    np.testing.assert_array_equal(back.arrays["held"], atoms.arrays["held"])
    assert back.info["material"] == "graphene"
    old = atoms.copy()
    del old.arrays["layer"], old.arrays["held"]
    write(tmp_path / "old.extxyz", old, format="extxyz")
    back = read_interface(tmp_path / "old.extxyz")
    np.testing.assert_array_equal(back.arrays["held"], np.isin(atoms.arrays["surface"], (1, 4)))
    np.testing.assert_array_equal(back.arrays["layer"], atoms.arrays["layer"])


def test_partly_held_layer_is_refused():
    """Pinning some atoms of a layer (what broke AB/BA symmetry) is not a valid interface."""
    atoms, _ = build_interface({"kind": "sheets", "sheet": "graphene", "stacking": "AB"})
    held = atoms.arrays["held"].copy()
    held[1] = False
    atoms.arrays["held"] = held
    with pytest.raises(InputError, match="layer 1 is partly held"):
        validate_interface(atoms)
