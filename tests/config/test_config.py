"""The run configuration: presets, YAML round trip, one-line errors naming the field path."""

from __future__ import annotations

import pytest
import yaml
from typer.testing import CliRunner

from flatcontact.cli import app
from flatcontact.config import build_config, load_config, preset, to_yaml
from flatcontact.foundation.errors import InputError


@pytest.mark.parametrize("name", ["quick", "paper"])
def test_yaml_round_trip(tmp_path, name):
    cfg = load_config(preset_name=name)
    path = tmp_path / "c.yaml"
    path.write_text(to_yaml(cfg))
    assert load_config(path) == cfg
    assert yaml.safe_load(to_yaml(cfg, comments=False)) == cfg.to_dict()


def test_paper_preset_is_finer_than_quick():
    quick, paper = load_config(preset_name="quick"), load_config(preset_name="paper")
    assert paper.scan.grid[0] * paper.scan.grid[1] >= quick.scan.grid[0] * quick.scan.grid[1]
    assert paper.scan.p_range_gpa.n > quick.scan.p_range_gpa.n
    assert paper.scan.p_range_gpa.hi_gpa > quick.scan.p_range_gpa.hi_gpa
    assert paper.scan.fmax_ev_per_angstrom <= quick.scan.fmax_ev_per_angstrom
    assert len(paper.analysis.p_gpa) > len(quick.analysis.p_gpa)
    # 9 O-Si-O layers: the paper's 6 are not converged (docs/convergence.md, slab layers)
    assert paper.structure.layers == 9 and quick.structure.layers == 6


def test_file_overlays_preset_and_resolves_paths(tmp_path):
    (tmp_path / "iface.extxyz").write_text("")
    path = tmp_path / "run.yaml"
    path.write_text(
        "preset: paper\nstructure: {kind: file, file: iface.extxyz}\n"
        "scan: {thickness_angstrom: [14.1, 14.3]}\n"
    )
    cfg = load_config(path)
    assert cfg.preset == "paper"
    assert cfg.scan.grid == (12, 12)  # from the preset
    assert cfg.scan.p_range_gpa is None  # an explicit thickness list replaces the range
    assert cfg.structure.file == str((tmp_path / "iface.extxyz").resolve())
    assert load_config(path, preset_name="quick").preset == "quick"  # the flag wins


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "scan:\n  grid: [0, 4]\n",
            "c.yaml: scan.grid: expected two positive integers, got [0, 4]",
        ),
        ("scan:\n  grid: [4]\n", "c.yaml: scan.grid: expected two positive integers, got [4]"),
        ("scan:\n  gird: [4, 4]\n", "c.yaml: scan.gird: unknown field"),
        (
            "contact:\n  radius_um: -5\n",
            "c.yaml: contact.radius_um: expected 0.001 <= value <= 10000 µm, got -5",
        ),
        ("contact:\n  radius_nm: 5\n", "c.yaml: contact.radius_nm: unknown field"),
        (
            "contact:\n  p0_gpa: [1, -2]\n",
            "c.yaml: contact.p0_gpa.1: expected 1e-06 <= value <= 1000 GPa, got -2",
        ),
        ("analysis:\n  p_gpa: [1.0]\n", "c.yaml: analysis.p_gpa: expected at least two"),
        ("scan:\n  fmax_ev_per_angstrom: fast\n", "scan.fmax_ev_per_angstrom: expected a number"),
        ("scan:\n  optimizer: SD\n", "c.yaml: scan.optimizer: expected one of"),
        ("potential:\n  intra: reaxff\n", "c.yaml: potential.intra: unknown potential 'reaxff'"),
        (
            "scan:\n  p_range_gpa: {lo_gpa: 2, hi_gpa: 1, n: 4}\n",
            "c.yaml: scan.p_range_gpa: expected lo_gpa < hi_gpa",
        ),
        (
            "structure: {kind: toy-lj}\n",
            "c.yaml: structure.kind 'toy-lj' needs potential.calculator.target",
        ),
        ("preset: fast\n", "c.yaml: preset: expected quick or paper"),
        ("- 1\n- 2\n", "c.yaml: expected a mapping of sections"),
        ("scan: [1\n", "c.yaml: not valid YAML (line"),
        ("contact: 3\n", "c.yaml: contact: expected a mapping, got 3"),
        # every float finite: NaN/inf refused naming the path, before any work
        ("analysis: {p_gpa: [.nan, 1]}\n", "c.yaml: analysis.p_gpa.0: expected a finite number"),
        ("analysis: {direction_deg: .nan}\n", "c.yaml: analysis.direction_deg: expected a finite"),
        ("contact: {radius_um: .inf}\n", "c.yaml: contact.radius_um: expected a finite number"),
        (
            "scan: {thickness_angstrom: [17, .nan]}\n",
            "scan.thickness_angstrom.1: expected a finite",
        ),
        (
            "potential: {lj: {cutoff_angstrom: .inf}}\n",
            "c.yaml: potential.lj.cutoff_angstrom: expected a finite number, got inf",
        ),
        (
            "potential: {lj: {c6_scale: .nan}}\n",
            "c.yaml: potential.lj.c6_scale: expected a finite number",
        ),
        # element symbols of the LJ dicts are real elements
        (
            "potential: {lj: {volume_ratio: {Xx: 0.5}}}\n",
            "c.yaml: potential.lj.volume_ratio: key 'Xx': 'Xx' is not a chemical element symbol",
        ),
        (
            "potential: {lj: {c6_ev_a6: {O-Qq: 30}}}\n",
            "potential.lj.c6_ev_a6: c6_ev_a6 key 'O-Qq': 'Qq' is not a chemical element",
        ),
        (
            "potential: {lj: {r0_angstrom: {si: 2.0}}}\n",
            "'si' is not a chemical element symbol",
        ),
        # input files named by the config exist
        ("contact: {experiment: {csv: nothere.csv}}\n", "c.yaml: contact.experiment.csv: file "),
        ("structure: {kind: file, file: no.extxyz}\n", "c.yaml: structure.file: file "),
        # a union's member type is not part of the path (it printed
        # "refine.settings.list[literal['grid','thicknesses',...]].0")
        (
            "refine: {settings: [bogus]}\n",
            "c.yaml: refine.settings.0: expected 'grid', 'thicknesses', 'layers', 'fmax' or "
            "'cutoff', got \"bogus\"",
        ),
    ],
)
def test_bad_config_is_one_line_naming_the_path(tmp_path, text, message):
    path = tmp_path / "c.yaml"
    path.write_text(text)
    with pytest.raises(InputError) as info:
        load_config(path)
    text = str(info.value)
    assert message in text
    assert "\n" not in text
    assert "pydantic" not in text and "Traceback" not in text


def test_missing_config_file(tmp_path):
    with pytest.raises(InputError, match="no such config file"):
        load_config(tmp_path / "nope.yaml")


def test_every_field_is_documented():
    from flatcontact.config import RunConfig

    def walk(model):
        for name, field in model.model_fields.items():
            if model.__name__ not in ("InteractionModel", "LJSpec"):
                assert field.description, f"{model.__name__}.{name} has no description"
            ann = field.annotation
            for sub in getattr(ann, "__args__", (ann,)):
                if isinstance(sub, type) and hasattr(sub, "model_fields"):
                    walk(sub)

    walk(RunConfig)


def test_cli_show_default_prints_loadable_yaml(tmp_path):
    runner = CliRunner()
    result = runner.invoke(app, ["config", "--show-default", "--preset", "paper"])
    assert result.exit_code == 0, result.output
    assert "# lateral points along a1 and a2" in result.output
    path = tmp_path / "default.yaml"
    path.write_text(result.output)
    assert load_config(path) == load_config(preset_name="paper")


def test_cli_check_reports_one_line(tmp_path):
    from flatcontact.cli import main

    path = tmp_path / "c.yaml"
    path.write_text("scan:\n  grid: [0, 4]\n")
    with pytest.raises(SystemExit) as info:
        main(["config", "--check", str(path)])
    assert info.value.code == 2


def test_cli_check_refuses_nan_and_missing_files(tmp_path, capsys):
    from flatcontact.cli import main

    for text, where in (
        ("analysis: {p_gpa: [.nan, 1]}\n", "analysis.p_gpa.0"),
        ("contact: {experiment: {csv: missing.csv}}\n", "contact.experiment.csv"),
    ):
        path = tmp_path / "c.yaml"
        path.write_text(text)
        with pytest.raises(SystemExit) as info:
            main(["config", "--check", str(path)])
        err = capsys.readouterr().err.strip()
        assert info.value.code == 2 and err.count("\n") == 0
        assert err.startswith(f"error: {path}: {where}: ")


def test_lj_element_symbols_accepted():
    cfg = build_config({"potential": {"lj": {"volume_ratio": {"Si": 0.8, "O": 1.1}}}})
    assert cfg.potential.lj.volume_ratio == {"O": 1.1, "Si": 0.8}


def test_preset_data_is_a_copy():
    a = preset("quick")
    a["scan"]["grid"] = [1, 1]
    assert build_config({}).scan.grid == tuple(preset("quick")["scan"]["grid"])
