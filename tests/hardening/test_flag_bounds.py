"""Every number flag of every command is bounded: an audit over the typer app.

The test walks the command tree and finds every option whose type holds ``float`` or
``int``. Each must be listed in :data:`CASES` with a value outside its bounds (a subnormal,
1e300, NaN or an integer far beyond any study); run with it, the command is refused in one
``error:`` line naming the flag, exit 2, no traceback, nothing written in the working
directory. A new number flag without a case fails :func:`test_every_number_flag_has_a_case`,
so a flag cannot bypass the bounds unnoticed. Whether a flag is checked by the setting it
sets (``contact``, ``scan``, ``analyze``, ``elastic``) or by the bounded float of
:mod:`flatcontact.cli.app` (``build``, ``train-snap``, ``validate-potential``) does not
matter here: the user sees the same line.
"""

from __future__ import annotations

import typing

import pytest
import typer
from tests.hardening.helpers import assert_refused_cleanly

from flatcontact.cli import app

SUBNORMAL = "1e-320"
HUGE = "1e300"
HUGE_INT = "1000000000000"

#: (command, flag) -> (extra arguments, the bad value(s) of the flag); ``{tmp}`` is replaced
#: by the test's folder (the command's --out lies in it).
CASES: dict[tuple[str, str], tuple[list[str], list[str]]] = {
    ("analyze", "--threshold-gpa"): (["{tmp}/ispes.nc", "0.5"], [SUBNORMAL]),
    ("build", "--layers"): (["--out", "{tmp}/b"], [HUGE_INT]),
    ("build", "--gap-angstrom"): (["--out", "{tmp}/b"], [HUGE]),
    ("build", "--lj-cutoff-angstrom"): (["--out", "{tmp}/b"], ["1e6"]),
    ("build", "--fmax-ev-per-angstrom"): (["--out", "{tmp}/b"], [SUBNORMAL]),
    ("contact", "--radius-um"): (["--out", "{tmp}/c"], [SUBNORMAL]),
    ("contact", "--contact-modulus-gpa"): (["--out", "{tmp}/c"], [HUGE]),
    ("contact", "--shear-modulus-gpa"): (["--out", "{tmp}/c"], [SUBNORMAL]),
    ("contact", "--burgers-angstrom"): (["--out", "{tmp}/c"], [SUBNORMAL]),
    ("contact", "--equilibrium-separation-angstrom"): (["--out", "{tmp}/c"], [HUGE]),
    ("contact", "--unstable-stacking-mj-per-m2"): (["--out", "{tmp}/c"], [SUBNORMAL]),
    ("contact", "--k-mpa-per-gpa"): (["--out", "{tmp}/c"], [HUGE]),
    ("contact", "--tau0-mpa"): (["--out", "{tmp}/c"], [HUGE]),
    ("contact", "--mu-mpa-per-gpa"): (["--out", "{tmp}/c"], [HUGE]),
    ("contact", "--sigma0-mpa"): (["--out", "{tmp}/c"], [HUGE]),
    ("contact", "--work-of-adhesion-j-per-m2"): (["--out", "{tmp}/c"], [HUGE]),
    ("contact", "--maugis-lambda"): (["--out", "{tmp}/c"], [SUBNORMAL]),
    ("contact", "--knee-fraction"): (["--out", "{tmp}/c"], ["1.5"]),
    ("contact", "--experiment-p0-gpa"): (["--out", "{tmp}/c"], [HUGE]),
    ("contact", "--collapse-fraction"): (["--out", "{tmp}/c"], [SUBNORMAL]),
    ("scan", "--grid"): (["--out", "{tmp}/s"], [HUGE_INT, "4"]),
    ("scan", "--p-range-gpa"): (["--out", "{tmp}/s"], ["-0.2", HUGE, "4"]),
    ("scan", "--workers"): (["--out", "{tmp}/s"], [HUGE_INT]),
    ("scan", "--fmax-ev-per-angstrom"): (["--out", "{tmp}/s"], [SUBNORMAL]),
    ("scan", "--max-steps"): (["--out", "{tmp}/s"], [HUGE_INT]),
    ("train-snap", "--seed"): (["--out", "{tmp}/t", "--recipe", "sio2"], ["-1"]),
    ("train-snap", "--scale"): (["--out", "{tmp}/t", "--recipe", "sio2"], [SUBNORMAL]),
    ("train-snap", "--active-rounds"): (["--out", "{tmp}/t", "--recipe", "sio2"], ["-3"]),
    ("validate-potential", "--layers"): (
        ["vashishta", "--ispes", "--reference", "tersoff"],
        [HUGE_INT],
    ),
    ("validate-potential", "--grid"): (
        ["vashishta", "--ispes", "--reference", "tersoff"],
        [HUGE_INT, "4"],
    ),
    ("validate-potential", "--p-range-gpa"): (
        ["vashishta", "--ispes", "--reference", "tersoff"],
        ["-0.3", HUGE, "8"],
    ),
    ("validate-potential", "--fmax-ev-per-angstrom"): (
        ["vashishta", "--ispes", "--reference", "tersoff"],
        [SUBNORMAL],
    ),
    ("validate-potential", "--lj-cutoff-angstrom"): (
        ["vashishta", "--ispes", "--reference", "tersoff"],
        ["1e6"],
    ),
    ("elastic", "--strain"): ([], [SUBNORMAL]),
}


def number_flags() -> list[tuple[str, str]]:
    """(command path, flag) of every option whose annotation holds float or int."""
    found = []

    def walk(command, path):
        subs = getattr(command, "commands", None)
        if subs:
            for name, sub in subs.items():
                walk(sub, [*path, name])
            return
        for param in command.params:
            annotation = param.type_descriptor.annotation
            kinds = {annotation, *typing.get_args(annotation)}
            if kinds & {float, int}:
                found.append((" ".join(path), param.opts[0]))

    walk(typer.main.get_command(app), [])
    return found


def test_every_number_flag_has_a_case():
    flags = number_flags()
    assert len(flags) >= 30  # the walk reaches the commands (33 number flags today)
    missing = sorted(set(flags) - set(CASES))
    assert not missing, f"number flags without a bound case: {missing}"
    stale = sorted(set(CASES) - set(flags))
    assert not stale, f"cases of flags that no longer exist: {stale}"


@pytest.mark.parametrize("case", sorted(CASES), ids=lambda c: f"{c[0]} {c[1]}")
def test_a_number_flag_out_of_bounds_is_one_line_naming_it(case, tmp_path, capsys, monkeypatch):
    command, flag = case
    extra, values = CASES[case]
    (tmp_path / "ispes.nc").write_bytes(b"")
    monkeypatch.chdir(tmp_path)
    argv = [command, *(a.format(tmp=tmp_path) for a in extra), flag, *values]
    assert_refused_cleanly(argv, capsys, tmp_path, [flag])


#: list-valued number flags (typed as text, parsed by the command): (argv, the flag)
LIST_CASES = {
    "analyze-p-nan": (["analyze", "{tmp}/ispes.nc", "--p-gpa", "nan"], "--p-gpa"),
    "analyze-p-subnormal": (["analyze", "{tmp}/ispes.nc", "1e-320"], "--p-gpa"),
    "analyze-p-huge": (["analyze", "{tmp}/ispes.nc", "--p-gpa", "0.5,1e300"], "--p-gpa"),
    "validate-p-huge": (
        [
            "validate-potential",
            "vashishta",
            "--ispes",
            "--reference",
            "tersoff",
            "--p-gpa",
            "0,1e300",
        ],
        "--p-gpa",
    ),
    "contact-p0-nan": (["contact", "--out", "{tmp}/c", "--p0-gpa", "nan"], "--p0-gpa"),
    "contact-fit-p0-subnormal": (
        ["contact", "--out", "{tmp}/c", "--fit-p0-gpa", "1e-320"],
        "--fit-p0-gpa",
    ),
    "scan-thickness-huge": (
        ["scan", "--out", "{tmp}/s", "--thickness-angstrom", "1e300"],
        "--thickness-angstrom",
    ),
}


@pytest.mark.parametrize("case", sorted(LIST_CASES))
def test_a_list_number_flag_out_of_bounds_is_one_line_naming_it(
    case, tmp_path, capsys, monkeypatch
):
    """Number lists given as text (``--p-gpa 0.5,1``, positional loads) are held to the
    bounds of the setting they fill, before any file is read."""
    argv, flag = LIST_CASES[case]
    (tmp_path / "ispes.nc").write_bytes(b"")
    monkeypatch.chdir(tmp_path)
    assert_refused_cleanly([a.format(tmp=tmp_path) for a in argv], capsys, tmp_path, [flag])


#: structure: sections with one float out of its bound, and the field the line must name
RECIPE_CASES = {
    "quartz-gap-huge": ("{kind: quartz-dense, gap_angstrom: 1e300}", "structure.gap_angstrom"),
    "quartz-fmax-subnormal": (
        "{kind: quartz-dense, fmax_ev_per_angstrom: 1e-320}",
        "structure.fmax_ev_per_angstrom",
    ),
    "slab-gap-tiny": ("{kind: slab, file: s.extxyz, gap_angstrom: 1e-9}", "structure.gap_angstrom"),
    "fcc-lattice-huge": ("{kind: fcc111, element: Cu, a_angstrom: 1e6}", "structure.a_angstrom"),
    "fcc-slab2-lattice-subnormal": (
        "{kind: fcc111, element: Cu, slab2: {element: Ni, a_angstrom: 1e-320}}",
        "structure.slab2.a_angstrom",
    ),
    "sheets-interlayer-huge": (
        "{kind: sheets, sheet: graphene, interlayer_angstrom: 1e300}",
        "structure.interlayer_angstrom",
    ),
    "sheets-spacing-nan": (
        "{kind: sheets, sheet: graphene, interface_spacing_angstrom: .nan}",
        "structure.interface_spacing_angstrom",
    ),
    "sheets-rotation-huge": (
        "{kind: sheets, sheet: h-BN, rotate_deg: 1e300}",
        "structure.rotate_deg",
    ),
    "crystal-strain-huge": (
        "{kind: crystal, bulk: b.cif, miller: [0, 0, 1], match: {max_strain_percent: 1e300}}",
        "structure.match.max_strain_percent",
    ),
    "toy-sigma-subnormal": (
        "{kind: toy-lj, params: {sigma_angstrom: 1e-320}}",
        "structure.params",
    ),
    "toy-unknown-parameter": ("{kind: toy-lj, params: {epsilon: 1.0}}", "structure.params"),
}


@pytest.mark.parametrize("case", sorted(RECIPE_CASES))
def test_a_recipe_float_out_of_bounds_is_one_line_naming_its_field(case, tmp_path, capsys):
    """structure.* floats take the bounded float type: NaN, subnormal, huge and tiny are
    refused by ``config --check`` before anything is read or built."""
    section, field = RECIPE_CASES[case]
    config = tmp_path / "run.yaml"
    config.write_text(f"structure: {section}\n")
    line = assert_refused_cleanly(
        ["config", "--check", config], capsys, tmp_path, [field, str(config)]
    )
    assert "expected" in line or "finite" in line


def test_the_recipe_bounds_are_printed_by_show_default(capsys):
    from tests.hardening.helpers import run_cli

    from flatcontact.structures.recipe import SheetsRecipe

    code, out, _ = run_cli(["config", "--show-default"], capsys)
    assert code == 0
    assert "gap_angstrom: 3.0" in out
    assert "[0.5..20 Å]" in out  # the quartz gap's comment
    # every bounded recipe field states its bounds in its description (the schema)
    for name in ("interlayer_angstrom", "interface_spacing_angstrom", "rotate_deg"):
        assert "[" in SheetsRecipe.model_fields[name].description, name
