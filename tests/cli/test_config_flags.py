"""A flag given with a configuration is laid over it or refused in one line, never ignored.

For every option of ``flatcontact scan CONFIG`` and ``flatcontact build --config CONFIG``
(the options derived from the settings, :mod:`flatcontact.cli.options`, and the commands'
own), the command is run up to its stage with the stage replaced by a recorder: the settings
it would run with hold the flag's value where the file says something else, or the command
refused the flag in one ``error:`` line naming it. A table below gives each flag a value;
a flag added to a command without one fails :func:`test_every_flag_has_a_case`.
"""

from pathlib import Path

import pytest
from tests.cli.cli_helpers import one_error_line, run_cli

from flatcontact.cli import build as build_cli
from flatcontact.cli import scan as scan_cli

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
CU = EXAMPLES / "cu111-eam.yaml"  # fcc111 recipe, EAM preset (no LJ), p_range_gpa, 6x6
QUARTZ = EXAMPLES / "quartz-paper.yaml"  # quartz-dense recipe, SNAP + LJ
TOY = "flatcontact.ispes.toy:toy_calculator"


class Ran(Exception):
    """Raised by the stand-in of the stage, holding the settings it was called with."""

    def __init__(self, settings):
        super().__init__("stage called")
        self.settings = settings


def _setting(cfg, path: str):
    value = cfg
    for part in path.split("."):
        value = getattr(value, part)
    return value


#: scan flag -> (arguments, settings path, the value the settings must then hold)
SCAN_CASES = {
    "--relax-mode": (["--relax-mode", "rigid"], "scan.relax_mode", "rigid"),
    "--grid": (["--grid", "3", "4"], "scan.grid", (3, 4)),
    "--thickness-angstrom": (
        ["--thickness-angstrom", "9.5,10"],
        "scan.thickness_angstrom",
        [9.5, 10.0],
    ),
    "--workers": (["--workers", "3"], "scan.workers", 3),
    "--executor": (["--executor", "serial"], "scan.executor", "serial"),
    "--dask-address": (
        ["--dask-address", "tcp://10.0.0.5:8786"],
        "scan.dask_address",
        "tcp://10.0.0.5:8786",
    ),
    "--fmax-ev-per-angstrom": (
        ["--fmax-ev-per-angstrom", "0.002"],
        "scan.fmax_ev_per_angstrom",
        0.002,
    ),
    "--optimizer": (["--optimizer", "FIRE"], "scan.optimizer", "FIRE"),
    "--max-steps": (["--max-steps", "17"], "scan.max_steps", 17),
    "--order": (["--order", "planes"], "scan.order", "planes"),
    "--p-range-gpa": (["--p-range-gpa", "0.5", "3", "5"], "scan.p_range_gpa.n", 5),
    "--potential": (["--potential", "vashishta"], "potential.intra", None),
    "--calculator": (["--calculator", TOY], "potential.calculator.target", TOY),
    "--calculator-kwarg": (
        ["--calculator", TOY, "--calculator-kwarg", "eps_cross_ev=0.02"],
        "potential.calculator.kwargs",
        {"eps_cross_ev": 0.02},
    ),
}
#: Options of scan that set no setting (where to read and write, how to print).
SCAN_NOT_SETTINGS = {"--preset", "--interface", "--out", "--json"}

#: build flag -> (arguments, settings path, the value the settings must then hold)
BUILD_CASES = {
    "--layers": (["--layers", "9"], "structure.layers", 9),
    "--source": (["--source", "seed"], "structure.source", "seed"),
    "--gap-angstrom": (["--gap-angstrom", "2.5"], "structure.gap_angstrom", 2.5),
    "--fmax-ev-per-angstrom": (
        ["--fmax-ev-per-angstrom", "0.02"],
        "structure.fmax_ev_per_angstrom",
        0.02,
    ),
    "--lj-cutoff-angstrom": (
        ["--lj-cutoff-angstrom", "12"],
        "potential.lj.cutoff_angstrom",
        12.0,
    ),
    "--potential": (["--potential", "vashishta"], "potential.intra", None),
    "--svg": (["--no-svg"], "report.svg", False),
}
#: Options of build that set no setting, or that a configuration cannot take.
BUILD_NOT_SETTINGS = {"--out", "--config", "--structure", "--regenerate-dense"}


def _flags(command) -> set[str]:
    import typer.main

    click = typer.main.get_command(scan_cli.app).commands[command]
    return {opt for p in click.params for opt in p.opts if opt.startswith("--")}


def test_every_flag_has_a_case():
    assert _flags("scan") == set(SCAN_CASES) | SCAN_NOT_SETTINGS
    assert _flags("build") == set(BUILD_CASES) | BUILD_NOT_SETTINGS
    # the derived ones are the settings' own names
    assert {o.flag for o in scan_cli.OPTIONS} <= set(SCAN_CASES)
    assert {o.flag for o in build_cli.OPTIONS} <= set(BUILD_CASES)


def _applied_or_refused(argv, flag, path, expected, monkeypatch, capsys, stage):
    def record(settings, *args, **kwargs):
        raise Ran(settings)

    monkeypatch.setattr(stage, record)
    try:
        code, _, err = run_cli(argv, capsys)
    except Ran as ran:
        value = _setting(ran.settings, path)
        if expected is None:  # --potential: the name, as the model spells it
            assert "vashishta" in str(value).lower(), (flag, value)
        else:
            assert value == expected, (flag, path, value)
        return "applied"
    line = one_error_line(code, err)
    assert flag in line, (flag, line)
    return "refused"


@pytest.mark.parametrize("config", [CU, QUARTZ], ids=["fcc111-eam", "quartz"])
@pytest.mark.parametrize("flag", sorted(SCAN_CASES))
def test_scan_flag_over_a_configuration(flag, config, tmp_path, monkeypatch, capsys):
    from flatcontact.config import load_config

    args, path, expected = SCAN_CASES[flag]
    if expected is not None:
        try:
            assert _setting(load_config(config), path) != expected  # the flag changes it
        except AttributeError:  # potential.calculator is None in the file
            pass
    argv = ["scan", str(config), *args, "--out", str(tmp_path / "s")]
    got = _applied_or_refused(
        argv, flag, path, expected, monkeypatch, capsys, "flatcontact.stages.scan.scan_stage"
    )
    if flag in {o.flag for o in scan_cli.OPTIONS}:
        assert got == "applied"  # every scan setting applies to any configuration


@pytest.mark.parametrize("config", [CU, QUARTZ], ids=["fcc111-eam", "quartz"])
@pytest.mark.parametrize("flag", sorted(BUILD_CASES))
def test_build_flag_over_a_configuration(flag, config, tmp_path, monkeypatch, capsys):
    args, path, expected = BUILD_CASES[flag]
    argv = ["build", "--config", str(config), *args, "--out", str(tmp_path / "b")]
    got = _applied_or_refused(
        argv, flag, path, expected, monkeypatch, capsys, "flatcontact.stages.build.build_stage"
    )
    # the fcc111 recipe has no source, the EAM preset no LJ: those two are refused there
    refused = config == CU and flag in ("--source", "--lj-cutoff-angstrom")
    assert got == ("refused" if refused else "applied"), (flag, config.name)
    assert not (tmp_path / "b").exists() or got == "applied"
