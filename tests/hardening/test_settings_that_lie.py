"""Settings that do nothing, or too late: a top-level calculator: (an unknown key naming
potential.calculator), a Dask address with an empty host label (a UnicodeError
traceback), uncertainty widths that are not normal finite floats within a bound (1e200 went
into laws.json as Infinity, 5e-324 broke the file contract) are one line at config --check."""

from __future__ import annotations

import pytest
from tests.hardening.helpers import refused, run_cli

from flatcontact.config.scan import parse_dask_address

TOY = """\
structure: {kind: toy-lj, layers: 3}
potential: {calculator: {target: "flatcontact.ispes.toy:toy_calculator"}}
scan: {grid: [3, 3], executor: serial}
"""


def _check(tmp_path, capsys, text):
    conf = tmp_path / "c.yaml"
    conf.write_text(text)
    return run_cli(["config", "--check", conf], capsys)


def test_a_top_level_calculator_beside_potential_is_one_line(tmp_path, capsys):
    text = TOY.replace("potential:", "calculator: {target: x:y}\npotential:")
    code, _, err = _check(tmp_path, capsys, text)
    refused(code, err, "c.yaml", "calculator: unknown field", "potential.calculator")


def test_a_top_level_calculator_alone_is_refused_naming_its_home(tmp_path, capsys):
    text = TOY.replace(
        'potential: {calculator: {target: "flatcontact.ispes.toy:toy_calculator"}}',
        'calculator: {target: "flatcontact.ispes.toy:toy_calculator"}',
    )
    code, _, err = _check(tmp_path, capsys, text)
    refused(code, err, "c.yaml", "calculator: unknown field", "potential.calculator")


def test_scan_calculator_flag_over_a_configuration_still_works(tmp_path):
    """The flag lays potential.calculator over the file's whole settings (a potential
    section included): the file's model is replaced, not merged."""
    from flatcontact.cli.settings import resolve_config

    conf = tmp_path / "c.yaml"
    conf.write_text(TOY)
    target = "flatcontact.ispes.toy:toy_calculator"
    calc = {"target": target, "kwargs": {"eps_cross_ev": 0.02}}
    cfg = resolve_config(conf, None, {"potential": {"calculator": calc}}, {})
    assert cfg.potential.calculator.kwargs == {"eps_cross_ev": 0.02}


@pytest.mark.parametrize(
    "address",
    [
        "tcp://a..b:8786",
        "tcp://.a:8786",
        "a.:8786",
        "tcp://" + "x" * 64 + ".org:8786",
        "tcp://" + ".".join(["abc"] * 70) + ":8786",
    ],
)
def test_a_dask_address_with_an_empty_or_long_host_label_is_one_line(tmp_path, capsys, address):
    code, _, err = _check(
        tmp_path,
        capsys,
        TOY.replace("executor: serial", f'executor: dask, dask_address: "{address}"'),
    )
    refused(code, err, "scan.dask_address", "host:port")
    assert "UnicodeError" not in err


def test_a_well_formed_dask_address_still_parses():
    assert parse_dask_address("tcp://node-1.cluster.example.org:8786") == (
        "tcp",
        "node-1.cluster.example.org",
        8786,
    )
    assert parse_dask_address("[::1]:8786") == ("tcp", "::1", 8786)


@pytest.mark.parametrize(
    ("value", "names"),
    [
        ("1e200", ["uncertainty.convergence_internal", "k_mpa_per_gpa", "1e+200"]),
        ("5e-324", ["uncertainty.convergence_internal", "k_mpa_per_gpa", "subnormal"]),
        ("-0.5", ["uncertainty.convergence_internal", "k_mpa_per_gpa"]),
        (".inf", ["uncertainty.convergence_internal", "k_mpa_per_gpa"]),
    ],
)
def test_an_uncertainty_width_outside_normal_bounded_floats_is_one_line(
    tmp_path, capsys, value, names
):
    code, _, err = _check(
        tmp_path,
        capsys,
        TOY + f"uncertainty: {{convergence_internal: {{k_mpa_per_gpa: {value}}}}}\n",
    )
    refused(code, err, *names)


def test_a_zero_or_ordinary_width_is_accepted(tmp_path, capsys):
    code, _, err = _check(
        tmp_path,
        capsys,
        TOY + "uncertainty: {convergence_internal: {k_mpa_per_gpa: 0.0, tau0_mpa: 2.15}}\n",
    )
    assert code == 0, err
