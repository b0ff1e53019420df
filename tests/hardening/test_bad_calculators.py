"""A user calculator factory that returns None, a number or a class, raises, or is given a
NaN keyword argument: one ``error:`` line naming the factory (or the keyword argument), exit
2, no traceback, and for the keyword argument before anything is computed."""

from __future__ import annotations

import textwrap

import pytest
from tests.hardening.helpers import assert_refused_cleanly

from flatcontact.foundation.errors import InputError
from flatcontact.ispes.toy import toy_calculator
from flatcontact.potentials.loader import call_factory
from flatcontact.structures.interface_io import write_interface
from flatcontact.structures.toy import toy_interface

FACTORIES = textwrap.dedent(
    """
    from ase.calculators.emt import EMT

    from flatcontact.ispes.toy import toy_calculator


    def none(**kw):
        return None


    def number(**kw):
        return 1.0


    def a_class(**kw):
        return EMT


    def boom(**kw):
        raise ValueError("sigma must be positive\\nsee the manual")


    def toy(**kw):
        return toy_calculator(**kw)
    """
)


@pytest.fixture(scope="module")
def interface(tmp_path_factory):
    folder = tmp_path_factory.mktemp("iface")
    return write_interface(toy_interface(layers=3), folder / "interface.extxyz")


@pytest.fixture
def factories(tmp_path, monkeypatch):
    (tmp_path / "userfactories_h3.py").write_text(FACTORIES)
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.chdir(tmp_path)
    return "userfactories_h3"


@pytest.mark.parametrize(
    ("name", "said"),
    [
        ("none", "returned None"),
        ("number", "returned a float (1.0)"),
        ("a_class", "returned the class EMT"),
        ("boom", "failed: ValueError: sigma must be positive see the manual"),
    ],
)
@pytest.mark.parametrize("executor", ["serial", "processes"])
def test_a_factory_that_gives_no_calculator_is_one_line_naming_it(
    name, said, executor, factories, interface, tmp_path, capsys
):
    target = f"{factories}:{name}"
    argv = ["scan", "--interface", interface, "--calculator", target, "--thickness-angstrom", "11"]
    argv += ["--grid", "2", "2", "--executor", executor, "--out", tmp_path / "o"]
    if executor == "processes":
        argv += ["--workers", "1"]
    line = assert_refused_cleanly(argv, capsys, interface.parent, [target])
    assert said in line


@pytest.mark.parametrize("value", ["nan", ".nan", "inf", "-.inf"])
def test_a_non_finite_keyword_argument_is_refused_naming_it(
    value, factories, interface, tmp_path, capsys
):
    argv = ["scan", "--interface", interface, "--calculator", f"{factories}:toy"]
    argv += ["--calculator-kwarg", f"sigma_angstrom={value}", "--thickness-angstrom", "11"]
    argv += ["--out", tmp_path / "o"]
    assert_refused_cleanly(argv, capsys, tmp_path, ["sigma_angstrom", "finite"])
    assert not (tmp_path / "o").exists()


def test_a_non_finite_keyword_argument_in_a_config_names_the_field(factories, tmp_path, capsys):
    config = tmp_path / "run.yaml"
    config.write_text(
        "structure: {kind: toy-lj}\n"
        f"potential:\n  calculator: {{target: '{factories}:toy', "
        "kwargs: {params: {sigma: [1.0, .nan]}}}\n"
    )
    line = assert_refused_cleanly(["config", "--check", config], capsys, tmp_path, [str(config)])
    assert "potential.calculator.kwargs" in line and "params.sigma[1]" in line


def test_library_callers_get_the_same_checks(factories):
    with pytest.raises(InputError, match="returned None"):
        call_factory(f"{factories}:none")
    with pytest.raises(InputError, match=r"keyword argument cutoff: expected a finite"):
        call_factory(f"{factories}:toy", None, {"cutoff": float("inf")})
    # a real calculator passes unchanged
    calc = call_factory(f"{factories}:toy", None, {"eps_cross_ev": 0.05})
    assert type(calc) is type(toy_calculator()) and calc.parameters["eps_cross_ev"] == 0.05
