"""A flag given with a configuration is laid over it or refused in one line, never ignored.

For every option of ``flatcontact scan CONFIG`` and ``flatcontact build --config CONFIG``
(the options derived from the settings, :mod:`flatcontact.cli.options`, and the commands'
own), the command is run up to its stage with the stage replaced by a recorder: the settings
it would run with hold the flag's value where the file says something else, or the command
refused the flag in one ``error:`` line naming it. A table below gives each flag a value;
a flag added to a command without one fails :func:`test_every_flag_has_a_case`.
``flatcontact analyze`` (no configuration: its flags over the preset) likewise, with its
one hand-declared setting option, ``--p-gpa`` (why: :mod:`flatcontact.cli.options`), in
each form it takes.
"""

from pathlib import Path

import pytest
from tests.cli.cli_helpers import one_error_line, run_cli

from flatcontact.cli import analyze as analyze_cli
from flatcontact.cli import build as build_cli
from flatcontact.cli import scan as scan_cli
from flatcontact.config.paths import field_at

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
    "--precondition": (["--no-precondition"], "scan.precondition", False),
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


#: analyze flag -> (arguments after the ISPES file, settings path, the value it must then hold)
ANALYZE_CASES = {
    "--direction-deg": (["--direction-deg", "30"], "analysis.direction_deg", 30.0),
    "--energy-form": (["--energy-form", "enthalpy"], "analysis.energy_form", "enthalpy"),
    "--load-source": (["--load-source", "stress"], "analysis.load_source", "stress"),
    "--energy-zero": (["--energy-zero", "each"], "analysis.energy_zero", "each"),
    "--threshold-gpa": (["--threshold-gpa", "1.5"], "analysis.threshold_gpa", 1.5),
    "--allow-missing": (["--allow-missing"], "analysis.allow_missing", True),
    "--with-mep": (["--with-mep"], "analysis.with_mep", True),
    "--svg": (["--no-svg"], "report.svg", False),
    "--p-gpa": (["--p-gpa", "0.25", "1.75"], "analysis.p_gpa", [0.25, 1.75]),
}
#: Options of analyze that set no setting.
ANALYZE_NOT_SETTINGS = {"--out", "--json"}


def _click(command):
    import typer.main

    return typer.main.get_command(scan_cli.app).commands[command]


def _flags(command) -> set[str]:
    return {opt for p in _click(command).params for opt in p.opts if opt.startswith("--")}


def test_every_flag_has_a_case():
    assert _flags("scan") == set(SCAN_CASES) | SCAN_NOT_SETTINGS
    assert _flags("build") == set(BUILD_CASES) | BUILD_NOT_SETTINGS
    assert _flags("analyze") == set(ANALYZE_CASES) | ANALYZE_NOT_SETTINGS
    # the derived ones are the settings' own names
    assert {o.flag for o in scan_cli.OPTIONS} <= set(SCAN_CASES)
    assert {o.flag for o in build_cli.OPTIONS} <= set(BUILD_CASES)
    assert {o.flag for o in analyze_cli.OPTIONS} <= set(ANALYZE_CASES)
    # every setting option is derived, but analyze's --p-gpa (cli/options.py says why)
    assert {o.flag for o in analyze_cli.OPTIONS} == set(ANALYZE_CASES) - {"--p-gpa"}


def test_p_range_gpa_is_derived_from_its_field():
    """``--p-range-gpa LO HI N`` is the sub-section ``scan.p_range_gpa``: one value per field,
    in the field order, typed as the fields are, help from the description."""
    (option,) = [o for o in scan_cli.OPTIONS if o.path == "scan.p_range_gpa"]
    assert option.flag == "--p-range-gpa" and scan_cli.FLAG_OF["scan.p_range_gpa"] == option.flag
    assert option.metavar == "LO HI N"
    model = field_at("scan.p_range_gpa.n")[0]
    assert (
        [name for name, _ in option.parts] == list(model.model_fields) == ["lo_gpa", "hi_gpa", "n"]
    )
    (param,) = [p for p in _click("scan").params if "--p-range-gpa" in p.opts]
    assert param.nargs == 3 and param.metavar == "LO HI N"
    assert [kind for _, kind in option.parts] == [float, float, int]
    assert option.value((0.5, 3.0, 5)) == {"lo_gpa": 0.5, "hi_gpa": 3.0, "n": 5}
    described = field_at("scan.p_range_gpa")[1].description
    assert option.help.startswith(f"scan.p_range_gpa: {described}. Default: ")


@pytest.mark.parametrize(
    "argv",
    [
        ["--p-range-gpa", "3", "0.5", "5"],  # lo >= hi
        ["--p-range-gpa", "0.5", "3", "1"],  # n < 2
        ["--p-range-gpa", "abc", "3", "5"],  # not a number
        ["--p-range-gpa", "0.5", "3", "2.5"],  # n not an integer
        ["--p-range-gpa", "0.5", "3", "5", "--thickness-angstrom", "9"],  # both
    ],
)
def test_a_bad_p_range_gpa_is_one_line_naming_it(argv, tmp_path, capsys):
    line = one_error_line(*run_cli(["scan", *argv, "--out", str(tmp_path / "s")], capsys)[::2])
    assert "--p-range-gpa" in line, line
    assert not (tmp_path / "s").exists()


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
    # the fcc111 recipe has no source, the EAM preset no LJ: those two are refused there; nor
    # has Vashishta parameters for Cu: the pre-run evaluation refuses it naming --potential
    refused = config == CU and flag in ("--source", "--lj-cutoff-angstrom", "--potential")
    assert got == ("refused" if refused else "applied"), (flag, config.name)
    assert not (tmp_path / "b").exists() or got == "applied"


def _analyzed_with(argv, monkeypatch, capsys):
    """The settings ``flatcontact analyze`` would run its stage with (the stage a recorder)."""

    def record(settings, *args, **kwargs):
        raise Ran(settings)

    monkeypatch.setattr("flatcontact.stages.analyze.analyze_stage", record)
    with pytest.raises(Ran) as ran:
        run_cli(["analyze", *map(str, argv)], capsys)
    return ran.value.settings


@pytest.mark.parametrize("flag", sorted(ANALYZE_CASES))
def test_analyze_flag_lands_at_its_setting(flag, tmp_path, monkeypatch, capsys):
    from flatcontact.config import load_config

    args, path, expected = ANALYZE_CASES[flag]
    assert _setting(load_config(None), path) != expected  # the flag changes it
    loads = [] if flag == "--p-gpa" else ["--p-gpa", "1"]  # analyze needs a load
    settings = _analyzed_with([tmp_path / "ispes.nc", *loads, *args], monkeypatch, capsys)
    assert _setting(settings, path) == expected


@pytest.mark.parametrize(
    "argv",
    [
        ["{nc}", "--p-gpa", "0.5", "1", "2"],
        ["--p-gpa", "0.5", "1", "2", "{nc}"],
        ["--p-gpa", "0.5", "{nc}", "1", "2"],
        ["{nc}", "--p-gpa", "0.5,1", "--p-gpa", "2"],
        ["{nc}", "--p-gpa=0.5,1,2"],
        ["--p-gpa", "{nc}", "0.5", "1,2"],  # the file where a load was expected: still read
    ],
)
def test_every_form_of_p_gpa_gives_the_same_loads(argv, tmp_path, monkeypatch, capsys):
    nc = tmp_path / "ispes.nc"
    settings = _analyzed_with([a.format(nc=nc) for a in argv], monkeypatch, capsys)
    assert settings.analysis.p_gpa == [0.5, 1.0, 2.0]


def test_one_load_is_enough_for_analyze(tmp_path, monkeypatch, capsys):
    """The run's settings ask for two loads (to fit the laws); analyze takes one."""
    settings = _analyzed_with([tmp_path / "ispes.nc", "--p-gpa", "-0.5"], monkeypatch, capsys)
    assert settings.analysis.p_gpa == [-0.5]


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (["--p-gpa", "2e3"], "--p-gpa"),  # outside the setting's bounds
        (["--p-gpa", "nan"], "--p-gpa"),
        ([], "--p-gpa"),  # no load
        (["--p-gpa", "1,,2"], "--p-gpa"),
    ],
)
def test_a_bad_p_gpa_is_one_line_naming_it(argv, said, tmp_path, capsys):
    code, _, err = run_cli(["analyze", str(tmp_path / "ispes.nc"), *argv], capsys)
    assert said in one_error_line(code, err)


def test_p_gpa_help_is_the_field_description():
    (param,) = [p for p in _click("analyze").params if "--p-gpa" in p.opts]
    described = field_at("analysis.p_gpa")[1].description.replace("[", "(").replace("]", ")")
    assert param.help.startswith(f"analysis.p_gpa: {described}"), param.help
