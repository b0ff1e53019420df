"""Bulk α-quartz checks, ring/coordination analysis, the dense (0001) reconstruction and its verification."""

import numpy as np
import pytest

from flatcontact.potentials import InteractionModel
from flatcontact.structures.build import _single_slab_calculator, reconstruct_dense_slab
from flatcontact.structures.bulk import alpha_quartz
from flatcontact.structures.dense import verify_dense_slab
from flatcontact.structures.slab import cleavage_heights, quartz_0001_slab
from flatcontact.structures.topology import bonds, coordination, ring_sizes


def test_alpha_quartz_bulk():
    atoms = alpha_quartz()
    assert len(atoms) == 9 and atoms.get_chemical_formula() == "O6Si3"
    i, j, _ = bonds(atoms)
    d = atoms.get_distances(i, j, mic=True)
    assert np.allclose(np.unique(d.round(3)), [1.605, 1.613], atol=2e-3)
    cn = coordination(atoms)
    symbols = np.array(atoms.get_chemical_symbols())
    assert np.all(cn[symbols == "Si"] == 4) and np.all(cn[symbols == "O"] == 2)
    # the smallest rings of α-quartz are six-membered (12 bonds)
    assert set(ring_sizes(atoms, range(9))) == {12}


def test_cleavage_planes_and_slab_stoichiometry():
    bulk = alpha_quartz()
    heights = cleavage_heights(bulk, 5.405 / 3)
    assert len(heights) == 3
    for cut in range(3):
        slab = quartz_0001_slab(layers=5, cut=cut)
        assert slab.get_chemical_formula() == "O10Si5"
        verdict = verify_dense_slab(slab)
        assert not verdict["dense"] and verdict["coordination_defects"]  # a raw cut is not dense


@pytest.fixture(scope="module")
def vashishta_dense():
    spec = InteractionModel(intra="vashishta")
    return reconstruct_dense_slab(4, _single_slab_calculator(spec), model_label="vashishta")


def test_vashishta_reaches_and_keeps_the_dense_surface(vashishta_dense):
    spec = InteractionModel(intra="vashishta")
    slab, record = vashishta_dense
    assert slab is not None
    verdict = verify_dense_slab(slab)
    assert verdict["dense"], verdict["failures"]
    for face in verdict["faces"].values():
        assert face["smallest_ring_in_face_layer_si"] == [6, 6]  # six-rings in the surface layer
        # small (3- or 4-membered) rings beneath the surface layer, unlike bulk quartz (6)
        assert all(r < 6 for r in face["smallest_ring_overall_si"])
        assert face["si_height_spread_angstrom"] < 0.1
    # the reconstruction lowers the energy relative to the relaxed raw cut
    dense_energy = min(t["energy_ev"] for t in record["trials"] if t["dense"])
    raw = quartz_0001_slab(layers=4, cut=2)
    from flatcontact.structures.dense import relax

    raw_energy = relax(raw, _single_slab_calculator(spec)(raw))["energy_ev"]
    assert dense_energy < raw_energy - 1.0


def test_tersoff_cannot_hold_the_dense_surface():
    spec = InteractionModel(intra="tersoff")
    slab, record = reconstruct_dense_slab(4, _single_slab_calculator(spec), model_label="tersoff")
    assert slab is None and not any(t["dense"] for t in record["trials"])


def test_verification_flags_a_broken_bond(vashishta_dense):
    slab, _ = vashishta_dense
    broken = slab.copy()
    top_o = np.argmax(
        np.where(np.array(broken.get_chemical_symbols()) == "O", broken.positions[:, 2], -np.inf)
    )
    broken.positions[top_o, 2] += 1.5
    verdict = verify_dense_slab(broken)
    assert not verdict["dense"]
    assert any("coordination" in f for f in verdict["failures"])


@pytest.mark.slow
def test_build_quartz_interface_vashishta_seed():
    from flatcontact.structures.build import build_quartz_interface
    from flatcontact.structures.interface_contract import fixed_mask

    interface, report = build_quartz_interface(
        InteractionModel(intra="vashishta"), 6, source="seed"
    )
    assert all(v["dense"] for v in report["interface_verification"].values())
    assert fixed_mask(interface).sum() == 12


@pytest.mark.parametrize("intra", ["vashishta", "tersoff"])
def test_shipped_chgnet_slab_is_dense_and_survives_relaxation(intra):
    from flatcontact.structures.build import load_shipped_dense_slab
    from flatcontact.structures.dense import relax

    slab, provenance = load_shipped_dense_slab()
    assert provenance["verification"]["dense"] and "CHGNet" in provenance["model"]
    assert verify_dense_slab(slab)["dense"]
    spec = InteractionModel(intra=intra)
    relax(slab, _single_slab_calculator(spec)(slab))
    verdict = verify_dense_slab(slab)
    assert verdict["dense"], verdict["failures"]
