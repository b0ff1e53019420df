"""A refusal of the pre-run checks names the configuration file the user gave, in the same
line from ``flatcontact config --check FILE``, ``flatcontact run FILE`` and (for the scan's
settings) ``flatcontact scan FILE``, before anything is written."""

from pathlib import Path

from tests.cli.cli_helpers import one_error_line, run_cli

#: A lateral grid the analysis cannot interpolate: refused by every run before its first stage.
COARSE_GRID = "scan:\n  grid: [2, 2]\n"
#: LAMMPS's minimiser with rigid layers: a scan setting the pre-run checks refuse.
CG_RIGID = "scan:\n  optimizer: lammps-cg\n  relax_mode: rigid-layers\n"


def _config(tmp_path, monkeypatch, text: str) -> str:
    """``text`` written to ``configs/run.yaml`` below a fresh working directory; the relative
    path as a user types it."""
    monkeypatch.chdir(tmp_path)
    Path("configs").mkdir()
    Path("configs/run.yaml").write_text(text)
    return "configs/run.yaml"


def test_run_names_the_file_and_field_as_config_check_does(tmp_path, monkeypatch, capsys):
    config = _config(tmp_path, monkeypatch, COARSE_GRID)
    check = one_error_line(*run_cli(["config", "--check", config], capsys)[::2])
    run = one_error_line(*run_cli(["run", config, "--out", "out"], capsys)[::2])
    assert run == check
    assert run.startswith(f"error: {config}: scan.grid: 2×2 lateral points"), run
    assert not Path("out").exists()  # refused before the run directory is made


def test_a_scan_setting_is_refused_in_the_same_line_by_every_command(tmp_path, monkeypatch, capsys):
    config = _config(tmp_path, monkeypatch, CG_RIGID)
    lines = [
        one_error_line(*run_cli(argv, capsys)[::2])
        for argv in (
            ["config", "--check", config],
            ["run", config, "--out", "out"],
            ["scan", config, "--out", "out", "--interface", "missing.extxyz"],
        )
    ]
    assert lines[0].startswith(f"error: {config}: scan.optimizer: 'lammps-cg' relaxes atoms")
    assert lines[1] == lines[0] and lines[2] == lines[0], lines
    assert sorted(p.name for p in Path().iterdir()) == ["configs"]  # nothing written


def test_scan_names_the_flag_that_set_the_refused_setting(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    argv = ["scan", "--optimizer", "lammps-cg", "--relax-mode", "rigid-layers", "--out", "o"]
    line = one_error_line(*run_cli(argv, capsys)[::2])
    assert line.startswith("error: --optimizer: 'lammps-cg' relaxes atoms"), line
    assert not Path("o").exists()


def test_study_convergence_refuses_its_base_as_config_check_does(tmp_path, monkeypatch, capsys):
    """The study's base run is CONFIG: its refusal is config --check's line, before the study
    starts (it was "the base configuration failed: config: ...", after the study began)."""
    config = _config(tmp_path, monkeypatch, COARSE_GRID)
    check = one_error_line(*run_cli(["config", "--check", config], capsys)[::2])
    code, out, err = run_cli(["study", "convergence", config, "--out", "study"], capsys)
    assert one_error_line(code, err) == check
    assert out == ""  # nothing started
    assert sorted(p.name for p in Path().iterdir()) == ["configs"]
