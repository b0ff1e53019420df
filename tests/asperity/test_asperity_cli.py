"""``flatcontact asperity``: bad input is one error line before any work; the stage's verdict."""

import json

from tests.cli.cli_helpers import one_error_line, run_cli

from flatcontact.stages.asperity import verdict

CU_LJ = """\
structure: {kind: fcc111, element: Cu, a_angstrom: 3.615, layers: 3, gap_angstrom: 3.0}
potential:
  intra: [{pair_style: eam/alloy, pair_coeff: [Cu_mishin1.eam.alloy]}]
  coupling: lj
asperity: {radius_angstrom: 100.0, p0_gpa: [1.0], contact_modulus_gpa: 73.0, steps: 1}
"""


def test_a_misspelt_geometry_is_one_line_naming_the_field(tmp_path, capsys):
    config = tmp_path / "c.yaml"
    config.write_text(CU_LJ.replace("steps: 1}", "steps: 1, geometry: cone}"))
    code, _, err = run_cli(["asperity", str(config), "--out", str(tmp_path / "o")], capsys)
    line = one_error_line(code, err)
    assert "asperity.geometry" in line
    assert not (tmp_path / "o").exists()


def test_a_run_without_laws_is_refused_before_any_work(tmp_path, capsys):
    config = tmp_path / "c.yaml"
    config.write_text(CU_LJ)
    code, _, err = run_cli(
        ["asperity", str(config), "--out", str(tmp_path / "o"), "--run", str(tmp_path)], capsys
    )
    assert "04-laws" in one_error_line(code, err)
    code, _, err = run_cli(
        ["asperity", str(config), "--out", str(tmp_path / "o"), "--laws", str(tmp_path / "x")],
        capsys,
    )
    assert "--laws" in one_error_line(code, err)


def test_too_many_atoms_are_refused_in_one_line(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("FLATCONTACT_MAX_ASPERITY_ATOMS", "100")
    config = tmp_path / "c.yaml"
    config.write_text(CU_LJ)
    code, _, err = run_cli(["asperity", str(config), "--out", str(tmp_path / "o")], capsys)
    assert "FLATCONTACT_MAX_ASPERITY_ATOMS" in one_error_line(code, err)
    assert not (tmp_path / "o").exists()


def test_states_of_other_settings_are_refused(tmp_path, capsys):
    config = tmp_path / "c.yaml"
    config.write_text(CU_LJ)
    state = tmp_path / "o" / "state"
    state.mkdir(parents=True)
    (state / "spec.json").write_text(json.dumps({"geometry": "sphere"}))
    code, _, err = run_cli(["asperity", str(config), "--out", str(tmp_path / "o")], capsys)
    assert "other asperity settings" in one_error_line(code, err)


def _load(ratio):
    return {"ratios_atoms_over_model": {"peak_lateral_force_hertz": ratio}}


def test_the_verdict_says_whether_the_model_holds_and_by_how_much():
    holds = verdict("cylinder", 400.0, [_load(1.1), _load(0.9)])
    assert "holds" in holds and "0.90 to 1.10" in holds and "R = 40 nm" in holds
    fails = verdict("sphere", 50.0, [_load(3.0)])
    assert "does not hold" in fails and "3.00 times" in fails
    assert "no laws" in verdict("cylinder", 1.0, [])


def test_config_check_refuses_an_asperity_without_lammps_or_layers(tmp_path):
    import pytest

    from flatcontact.config import build_config
    from flatcontact.foundation.errors import InputError
    from flatcontact.stages.preflight import check_asperity

    ase = build_config(
        {
            "structure": {"kind": "fcc111", "element": "Cu"},
            "potential": {"calculator": {"target": "ase.calculators.emt:EMT"}},
            "asperity": {"enabled": True},
        }
    )
    with pytest.raises(InputError, match="needs a LAMMPS interaction model"):
        check_asperity(ase)
    cfg = build_config(
        {
            "structure": {"kind": "file", "file": str(tmp_path / "x.extxyz")},
            "potential": {"preset": "cu-eam"},
            "asperity": {"enabled": True},
        }
    )
    with pytest.raises(InputError, match=r"asperity\.enabled: structure\.kind=file has no layers"):
        check_asperity(cfg)


def test_bad_radii_are_one_line_before_any_work(tmp_path, capsys):
    config = tmp_path / "c.yaml"
    config.write_text(CU_LJ)
    for radii, expected in (
        ("100,abc", "--radii: '100,abc': expected comma-separated radii in Å"),
        ("100,100", "--radii: '100,100': expected distinct"),
        ("100,2", "--radii: 2.0: expected radii in Å, 5 <= R <= 100000"),
    ):
        out = tmp_path / "o"
        code, _, err = run_cli(
            ["asperity", str(config), "--out", str(out), "--radii", radii], capsys
        )
        assert expected in one_error_line(code, err)
        assert not out.exists()
