"""The bundled sio2-snap: loads, reproduces its own validation report, meets the stated targets."""

import json

import pytest

from flatcontact.potentials.engines import bulk_calculator
from flatcontact.potentials.files import BUNDLED_DIR
from flatcontact.potentials.names import snapcoeff_path
from flatcontact.training.snapfiles import read_snapcoeff

HERE = BUNDLED_DIR / "sio2-snap"


@pytest.fixture(scope="module")
def report():
    return json.loads((HERE / "validation.json").read_text())


def test_files_and_provenance():
    for name in (
        "sio2-snap.snapcoeff",
        "sio2-snap.snapparam",
        "validation.json",
        "provenance.json",
    ):
        assert (HERE / name).is_file()
    prov = json.loads((HERE / "provenance.json").read_text())
    assert prov["teacher"] == "chgnet" and prov["model_name"] == "r2scan"
    assert prov["recipe"] == "sio2" and isinstance(prov["seed"], int)
    assert "train-snap --recipe sio2" in prov["command"]
    assert prov["wall_time_s"] < 3600  # trained within an hour on this machine class
    coeffs = read_snapcoeff(snapcoeff_path("sio2-snap"))
    assert coeffs.elements == ("Si", "O")
    assert coeffs.hyper.as_dict() == {
        **prov["hyper"],
        "radii": coeffs.hyper.radii,
        "weights": coeffs.hyper.weights,
    }


def test_heldout_errors_are_reproduced(report):
    from flatcontact.training.dataset import read_dataset
    from flatcontact.training.validate import dataset_errors

    frames = read_dataset(HERE / "test.extxyz", ["Si", "O"])
    err = dataset_errors(frames, bulk_calculator("sio2-snap"))
    stored = report["heldout_errors"]
    assert err["energy_rmse_mev_per_atom"] == pytest.approx(
        stored["energy_rmse_mev_per_atom"], rel=1e-6
    )
    assert err["force_rmse_mev_per_angstrom"] == pytest.approx(
        stored["force_rmse_mev_per_angstrom"], rel=1e-6
    )
    # targets vs the reference model, met on the groups the ISPES scan relies on
    for group in ("quartz_relaxed_strain", "quartz_pressure", "dense_slab", "active"):
        g = err["by_config_type"][group]
        assert g["energy_rmse_mev_per_atom"] <= 10.0, group
        assert g["force_rmse_mev_per_angstrom"] <= 200.0, group


def test_quartz_lattice_and_elastic_constants_reproduced(report):
    from flatcontact.training.validate import quartz_elastic, quartz_lattice

    calc = bulk_calculator("sio2-snap")
    relaxed, lat = quartz_lattice(calc)
    p, r = report["potential"], report["reference"]
    assert lat["a_angstrom"] == pytest.approx(p["lattice"]["a_angstrom"], abs=1e-4)
    assert lat["c_angstrom"] == pytest.approx(p["lattice"]["c_angstrom"], abs=1e-4)
    # within 1 % of the reference model (CHGNet r2SCAN)
    assert lat["a_angstrom"] == pytest.approx(r["lattice"]["a_angstrom"], rel=0.01)
    assert lat["c_angstrom"] == pytest.approx(r["lattice"]["c_angstrom"], rel=0.01)
    el = quartz_elastic(relaxed, calc)
    for k, v in el["cij_gpa"].items():
        assert v == pytest.approx(p["elastic"]["cij_gpa"][k], abs=0.3), k
    for k in ("C11", "C33", "C44", "C66"):  # the large constants within 15 % of the reference
        assert el["cij_gpa"][k] == pytest.approx(r["elastic"]["cij_gpa"][k], rel=0.15), k


def test_dense_surface_reported_stable(report):
    assert report["targets_met"]["dense_surface_stable"]
    assert report["potential"]["dense_surface_2x2"]["dense_after_md_300k"]


def test_works_in_the_interface_engine():
    """The bundled files run in flatcontact.potentials' two-slab LAMMPS engine."""
    from flatcontact.potentials import InteractionModel, make_calculator
    from flatcontact.structures.assemble import make_interface
    from flatcontact.training.validate import seeded_dense_slab

    slab = seeded_dense_slab()
    slab.pbc = (True, True, False)
    iface = make_interface(slab, 3.0, face_atoms=6)
    iface.calc = make_calculator(InteractionModel(intra="snap:sio2-snap"), iface)
    f = iface.get_forces()
    assert f.shape == (len(iface), 3)
    assert abs(f.sum(axis=0)).max() < 1e-6  # Newton's third law across the whole interface
