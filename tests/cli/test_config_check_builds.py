"""``config --check`` refuses what ``build`` would refuse: it builds the recipe (unrelaxed) and
sets the model up for it, so a LAMMPS setup error is one line before any work."""

import pytest
from ase.build import bulk
from ase.io import write
from tests.cli.cli_helpers import one_error_line, run_cli

MODULI = "contact: {contact_modulus_gpa: 50, shear_modulus_gpa: 30}\n"


def _au_crystal(tmp_path, potential: str) -> str:
    """A Au(111)/Au(111) config from a CIF (fcc Au, a = 4.08 Å) with ``potential``."""
    write(tmp_path / "Au.cif", bulk("Au", "fcc", a=4.08, cubic=True))
    config = tmp_path / "au.yaml"
    config.write_text(
        f"structure: {{kind: crystal, bulk: {tmp_path / 'Au.cif'}, miller: [1, 1, 1], layers: 3}}\n"
        f"potential: {potential}\n" + MODULI
    )
    return str(config)


def test_funcfl_eam_without_map_elements_false_is_one_line(tmp_path, capsys):
    """``pair_coeff * * Au_u3.eam Au`` is what LAMMPS refuses (three lines, after the build
    started); the check names the field and the fix before any work."""
    config = _au_crystal(
        tmp_path, "{intra: {pair_style: eam, pair_coeff: [Au_u3.eam]}, coupling: same}"
    )
    out = str(tmp_path / "b")
    for argv in (["config", "--check", config], ["build", "--config", config, "--out", out]):
        code, _, err = run_cli(argv, capsys)
        line = one_error_line(code, err)
        assert "potential.intra.0" in line and "map_elements: false" in line
    assert not (tmp_path / "b").exists()


def test_the_same_config_with_map_elements_false_passes_and_builds(tmp_path, capsys):
    config = _au_crystal(
        tmp_path,
        "{intra: {pair_style: eam, pair_coeff: [Au_u3.eam], map_elements: false}, coupling: same}",
    )
    code, out, err = run_cli(["config", "--check", config], capsys)
    assert code in (0, None), err
    assert "map_elements: false" in out
    code, out, err = run_cli(["build", "--config", config, "--out", str(tmp_path / "b")], capsys)
    assert code in (0, None), err
    assert (tmp_path / "b" / "interface.extxyz").is_file()


def test_an_element_the_model_lacks_is_refused_by_the_check(tmp_path, capsys):
    """fcc111 Au with the Cu EAM: the elements come from the built recipe, not from a file."""
    config = tmp_path / "au.yaml"
    config.write_text(
        "structure: {kind: fcc111, element: Au, layers: 4}\npotential: {preset: cu-eam}\n" + MODULI
    )
    code, _, err = run_cli(["config", "--check", str(config)], capsys)
    line = one_error_line(code, err)
    assert "potential 'cu-eam'" in line and "['Au']" in line


def test_a_lammps_setup_error_is_one_line(tmp_path, capsys):
    """``pair_style lj/cut`` without its global cutoff: LAMMPS's own refusal, in one line."""
    config = _au_crystal(
        tmp_path,
        "{intra: {pair_style: lj/cut, pair_coeff: ['0.2', '2.6'], elements: [Au], "
        "map_elements: false}, coupling: same}",
    )
    code, _, err = run_cli(["config", "--check", config], capsys)
    line = one_error_line(code, err)
    assert "potential" in line and "Illegal pair_style command" in line
    assert "Last input line: pair_style lj/cut" in line


@pytest.mark.parametrize(
    ("recipe", "field"),
    [
        (
            "{kind: fcc111, element: Cu, layers: 6, match: {max_atoms: 10}}",
            "structure.match.max_atoms",
        ),
        ("{kind: fcc111, element: Cu, layers: 2, held_layers: 2}", "structure.held_layers"),
    ],
)
def test_a_recipe_the_builder_refuses_is_refused_by_the_check(tmp_path, capsys, recipe, field):
    config = tmp_path / "cu.yaml"
    config.write_text(f"structure: {recipe}\npotential: {{preset: cu-eam}}\n" + MODULI)
    code, _, err = run_cli(["config", "--check", str(config)], capsys)
    line = one_error_line(code, err)
    assert field in line
