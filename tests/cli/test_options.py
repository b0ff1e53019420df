"""The command-line options derived from the settings (:mod:`flatcontact.cli.options`).

One name per quantity: every derived flag is its settings path below the section; its help
is the field's description; a value given on the command line lands at exactly that path of
the settings the stage runs with (the stage replaced by a recorder), and a bad one is one
line naming the flag.
"""

import math
import typing

import pytest
from tests.cli.cli_helpers import one_error_line, run_cli

from flatcontact.cli import analyze, build, contact, scan
from flatcontact.cli.options import flag_name
from flatcontact.config.paths import field_at
from flatcontact.foundation.numbers import field_bounds

COMMANDS = {"contact": contact, "analyze": analyze, "scan": scan, "build": build}


@pytest.mark.parametrize(
    ("path", "flag"),
    [
        ("contact.fit.csv", "--fit-csv"),
        ("contact.cycle.enabled", "--cycle"),
        ("contact.cycle.amplitudes_un", "--cycle-amplitudes-un"),
        ("analysis.energy_form", "--energy-form"),
        ("analysis.with_mep", "--with-mep"),
        ("report.svg", "--svg"),
        ("scan.thickness_angstrom", "--thickness-angstrom"),
        ("potential.lj.cutoff_angstrom", "--lj-cutoff-angstrom"),
    ],
)
def test_a_flag_is_its_settings_path(path, flag):
    assert flag_name(path) == flag


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_each_derived_option_is_its_field(command):
    module = COMMANDS[command]
    flag_of = module.FLAG_OF
    flags = [o.flag for o in module.OPTIONS]
    assert len(set(flags)) == len(flags)
    for option in module.OPTIONS:
        _, info = field_at(option.path)
        assert option.flag == flag_name(option.path)
        assert flag_of[option.path] == option.flag
        described = info.description.replace("[", "(").replace("]", ")").rstrip(".")
        assert option.help.startswith(f"{option.path}: {described}. Default: ")


def _sample(option):
    """A valid value of the option's setting other than its default, as typed on the
    command line, and the value the settings then hold."""
    special = {
        "contact.fit.csv": (["a.csv,b c.csv"], ["a.csv", "b c.csv"]),
        "contact.fit.free": (["tau0_mpa,k_mpa_per_gpa"], ["tau0_mpa", "k_mpa_per_gpa"]),
        "contact.fit.fixed": (["mu_mpa_per_gpa"], ["mu_mpa_per_gpa"]),
        "contact.experiment.csv": ("m.csv", "m.csv"),
    }
    if option.path in special:
        return special[option.path]
    _, info = field_at(option.path)
    ann = info.annotation
    default = info.get_default(call_default_factory=True)
    if option.kind == "bool":
        return (not default), (not default)
    if option.kind == "text":
        words = [
            w
            for a in [ann, *typing.get_args(ann)]
            if typing.get_origin(a) is typing.Literal
            for w in typing.get_args(a)
        ]
        word = next(w for w in reversed(words) if w != default)
        return word, word
    bounds = field_bounds(info)
    lo, hi = (bounds.lo, bounds.hi) if bounds else (1.0, 100.0)
    x = math.sqrt(lo * hi) if lo > 0 else (lo + hi) / 2 or 0.5 * hi
    x = float(f"{x:.3g}")
    if option.path.endswith("fractions") or option.path.endswith("_fraction"):
        x = 0.3
    if option.kind == "floats":
        return [f"{x:g}"], [x]
    return x, x


def test_each_contact_option_lands_at_its_path(monkeypatch, capsys):
    """One command with every contact option given: the settings the stage runs with hold
    each value at its path (all at once: the options are independent settings)."""
    seen = {}

    def record(settings, inputs, out):
        seen["settings"] = settings
        raise SystemExit(0)

    monkeypatch.setattr("flatcontact.stages.contact.contact_stage", record)
    argv, expected = ["contact"], {}
    for option in contact.OPTIONS:
        if option.path == "contact.cycle.amplitudes_un":
            continue  # it replaces amplitude_fractions: not given beside it
        typed, value = _sample(option)
        if option.kind == "bool":
            argv.append(option.flag if typed else f"--no-{option.flag.removeprefix('--')}")
        else:
            for item in typed if isinstance(typed, list) else [typed]:
                argv += [option.flag, str(item)]
        expected[option.path] = value
    code, _, err = run_cli(argv, capsys)
    assert code == 0, err
    cfg = seen["settings"]
    for path, value in expected.items():
        got = cfg
        for part in path.split("."):
            got = getattr(got, part)
        got = list(got) if isinstance(got, tuple) else got
        assert got == pytest.approx(value) if isinstance(value, float) else got == value, path


#: A value each kind of option refuses (a switch, a file name and a parameter name have none
#: of their own: the stage checks those).
BAD = {"floats": "x", "float": "nan", "text": "no-such-word"}


@pytest.mark.parametrize(
    "option",
    [
        o
        for o in contact.OPTIONS
        if o.kind in BAD and not o.path.endswith(("csv", "fit.free", "fit.fixed"))
    ],
    ids=lambda o: o.flag,
)
def test_a_bad_contact_value_is_one_line_naming_the_flag(option, capsys):
    code, _, err = run_cli(["contact", option.flag, BAD[option.kind]], capsys)
    line = one_error_line(code, err)
    assert option.flag in line, line
