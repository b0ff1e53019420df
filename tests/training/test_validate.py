"""validate-potential: every check runs, and a potential compared with itself is exact."""

import itertools
import json

import numpy as np
import pytest

from flatcontact.training.dataset import labelled, write_dataset
from flatcontact.training.lammps_bulk import vashishta_calculator
from flatcontact.training.polymorphs import build_polymorph
from flatcontact.training.validate import dataset_errors, validate_potential


def _frames(calc, n=4):
    rng = np.random.default_rng(5)
    out = []
    for _ in range(n):
        a = build_polymorph("alpha_quartz")
        a.positions += rng.normal(0, 0.03, a.positions.shape)
        a.calc = calc
        f = labelled(a, a.get_potential_energy(), a.get_forces(), a.get_stress())
        f.info["config_type"] = "quartz"
        out.append(f)
    return out


def test_errors_against_own_labels_vanish():
    calc = vashishta_calculator()
    err = dataset_errors(_frames(calc), calc)
    assert err["energy_rmse_mev_per_atom"] < 1e-9
    assert err["force_rmse_mev_per_angstrom"] < 1e-9
    assert err["stress_rmse_gpa"] < 1e-6
    assert set(err["by_config_type"]) == {"quartz"}


def test_validate_vashishta_against_itself():
    calc = vashishta_calculator()
    rep = validate_potential(
        calc, "vashishta", vashishta_calculator(), "vashishta", frames=_frames(calc), surface=True
    )
    p = rep["potential"]
    # NOTES.md: Vashishta relaxes alpha-quartz to a = 4.829, c = 5.309 Å
    assert p["lattice"]["a_angstrom"] == pytest.approx(4.829, abs=2e-3)
    assert rep["vs_reference"]["a_rel"] == pytest.approx(0.0, abs=1e-9)
    assert all(abs(v) < 1e-9 for v in rep["vs_reference"]["cij_rel"].values())
    eos = p["eos"]["points"]
    assert eos[0]["v_over_v0"] == pytest.approx(1.0, abs=1e-3)
    assert all(b["v_over_v0"] < a["v_over_v0"] for a, b in itertools.pairwise(eos))
    # bulk modulus from the EOS agrees with the Hill average from the Cij
    k_eos = p["eos"]["birch_murnaghan"]["k0_gpa"]
    k_hill = p["elastic"]["moduli_gpa"]["bulk_modulus"]
    assert k_eos == pytest.approx(k_hill, rel=0.1)
    ds = p["dense_surface"]
    assert ds["surface_energy_j_per_m2"] > 0
    assert {"dense_after_relaxation", "dense_after_md_300k"} <= set(ds)
    assert rep["targets_met"]["lattice_within_1pct"]
    json.dumps(rep)  # JSON-ready


def test_cli_validate_with_reference_file(tmp_path, capsys):
    from flatcontact.cli import main

    calc = vashishta_calculator()
    path = write_dataset(_frames(calc, 2), tmp_path / "held.extxyz")
    try:
        main(
            ["validate-potential", "vashishta", "--reference", str(path), "--no-surface", "--json"]
        )
    except SystemExit as exc:
        assert exc.code == 0
    rep = json.loads(capsys.readouterr().out)
    assert rep["heldout_errors"]["force_rmse_mev_per_angstrom"] < 1e-3  # extxyz precision
    assert rep["reference_label"] == str(path)


@pytest.mark.parametrize(
    ("name", "a_ref", "c_ref"), [("vashishta", 4.829, 5.309), ("tersoff", 5.082, 5.528)]
)
def test_classical_potentials_relax_to_known_lattices(name, a_ref, c_ref):
    """NOTES.md (LAMMPS box/relax): Vashishta 4.829/5.309 Å, Tersoff SiO 5.082/5.528 Å."""
    from flatcontact.potentials.engines import bulk_calculator
    from flatcontact.training.validate import quartz_lattice

    _, lat = quartz_lattice(bulk_calculator(name))
    assert lat["a_angstrom"] == pytest.approx(a_ref, abs=2e-3)
    assert lat["c_angstrom"] == pytest.approx(c_ref, abs=2e-3)
