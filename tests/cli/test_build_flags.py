"""``flatcontact build --config``: every flag given is laid over the file or refused in one line
naming it, never ignored; ``--layers`` is judged by the file's recipe, not by the quartz rule."""

from pathlib import Path

import pytest
from tests.cli.cli_helpers import one_error_line, run_cli

from flatcontact.cli.build import _config_settings

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
CU = EXAMPLES / "cu111-eam.yaml"
KC = EXAMPLES / "graphene-bilayer-kc.yaml"
QUARTZ = EXAMPLES / "quartz-paper.yaml"


def _settings(config, **given):
    recipe = {k: None for k in ("layers", "source", "gap_angstrom", "fmax_ev_per_angstrom")}
    recipe.update({k: v for k, v in given.items() if k in recipe})
    return _config_settings(config, None, None, given.get("lj_cutoff_angstrom"), recipe, False)


def test_given_flags_are_laid_over_the_file():
    base = _settings(CU)
    cfg = _settings(CU, layers=3, gap_angstrom=2.5)
    assert (cfg.structure.layers, cfg.structure.gap_angstrom) == (3, 2.5)
    assert base.structure.layers != 3
    assert _settings(KC, fmax_ev_per_angstrom=0.02).structure.fmax_ev_per_angstrom == 0.02
    assert _settings(QUARTZ, lj_cutoff_angstrom=12.0).potential.lj.cutoff_angstrom == 12.0
    # a flag not given keeps the file's value
    assert _settings(QUARTZ).potential.lj.cutoff_angstrom == 10.0  # the quick preset's


@pytest.mark.parametrize(
    ("config", "argv", "named"),
    [
        (CU, ["--source", "seed"], "--source: the structure recipe 'fcc111' has no source"),
        (CU, ["--lj-cutoff-angstrom", "12"], "--lj-cutoff-angstrom: the configuration's coupling"),
        (QUARTZ, ["--layers", "4"], "--layers=4: expected an integer >= 5"),
        (CU, ["--face-depth-angstrom", "2"], "No such option: --face-depth-angstrom"),
        (None, ["--normal-axis", "1"], "No such option: --normal-axis"),
    ],
)
def test_a_flag_that_cannot_apply_is_one_line_naming_it(config, argv, named, tmp_path, capsys):
    out = tmp_path / "b"
    head = ["build", "--config", str(config)] if config else ["build"]
    code, _, err = run_cli([*head, *argv, "--out", str(out)], capsys)
    assert named in one_error_line(code, err)
    assert not out.exists()


def test_layers_of_a_metal_are_not_judged_by_the_quartz_rule(tmp_path, capsys):
    """Three close-packed planes per slab is a valid fcc(111) recipe (the quartz rule asks
    for >= 5 O–Si–O layers): the build runs and writes 2 x 3 planes."""
    from ase.io import read

    out = tmp_path / "b"
    code, _, err = run_cli(
        ["build", "--config", str(CU), "--layers", "3", "--out", str(out)], capsys
    )
    assert code in (0, None), err
    atoms = read(out / "interface.extxyz")
    planes = {round(z, 1) for z in atoms.positions[:, 2]}
    assert len(planes) == 6
