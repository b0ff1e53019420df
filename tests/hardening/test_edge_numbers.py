"""Numbers at the edge of floating point and measured-data files that lie.

Every float a user gives (flag or config field) is finite, a normal double and inside the
bounds the schema states; a value outside is one ``error:`` line naming the flag or field,
exit 2, no traceback and no warning line. A measured stiffness CSV reads the same whatever
its row order or exact repeats; a cell that is not a plain decimal or a physically
impossible row is refused naming the file and the data line.
"""

from __future__ import annotations

import json
import random
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from tests.cli.cli_helpers import one_error_line, run_cli

from flatcontact.config.contact import ContactConfig
from flatcontact.config.elastic import ElasticConfig
from flatcontact.config.scan import ScanConfig
from flatcontact.contact import experiment as ex
from flatcontact.contact.parameters import ContactParameters
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.numbers import field_bounds

SUBNORMAL = "1e-320"  # nonzero, below the smallest normal double (2.2e-308)


def _clean_refusal(code: int, err: str, *names: str) -> str:
    """One ``error:`` line naming every one of ``names``; no warning line."""
    line = one_error_line(code, err)
    assert "Warning" not in err, err
    for name in names:
        assert name in line, line
    return line


# (contact flags, the flag the line must name): each crashed or overflowed before
CONTACT_CASES = {
    "radius-subnormal": (["--radius-um", SUBNORMAL], "--radius-um"),
    "p0-subnormal": (["--p0-gpa", SUBNORMAL], "--p0-gpa"),
    "p0-huge": (["--p0-gpa", "1e308"], "--p0-gpa"),
    "contact-modulus-subnormal": (["--contact-modulus-gpa", SUBNORMAL], "--contact-modulus-gpa"),
    "shear-modulus-subnormal": (["--shear-modulus-gpa", SUBNORMAL], "--shear-modulus-gpa"),
    "johnson-shear-subnormal": (
        ["--shear-modulus-gpa", SUBNORMAL, "--johnson-shear-modulus"],
        "--shear-modulus-gpa",
    ),
    "tau0-huge": (["--tau0-mpa", "1e300"], "--tau0-mpa"),
    "sigma0-huge": (["--sigma0-mpa", "1e300"], "--sigma0-mpa"),
    "k-subnormal": (["--k-mpa-per-gpa", SUBNORMAL], "--k-mpa-per-gpa"),
    "work-of-adhesion-huge": (
        ["--work-of-adhesion-j-per-m2", "1e300"],
        "--work-of-adhesion-j-per-m2",
    ),
    # tiny but normal: with λ its cohesive-zone width overflowed; 0 (no adhesion) stays valid
    "work-of-adhesion-tiny": (
        ["--work-of-adhesion-j-per-m2", "1e-300", "--maugis-lambda", "1"],
        "--work-of-adhesion-j-per-m2",
    ),
    "maugis-lambda-subnormal": (
        ["--work-of-adhesion-j-per-m2", "0.1", "--maugis-lambda", SUBNORMAL],
        "--maugis-lambda",
    ),
    "cycle-fraction-subnormal": (
        ["--cycle", "--cycle-amplitude-fractions", SUBNORMAL],
        "--cycle-amplitude-fractions",
    ),
    "cycle-amplitude-subnormal": (
        ["--cycle", "--cycle-amplitudes-un", SUBNORMAL],
        "--cycle-amplitudes-un",
    ),
    "experiment-p0-subnormal": (["--experiment-p0-gpa", SUBNORMAL], "--experiment-p0-gpa"),
}


@pytest.mark.parametrize("case", sorted(CONTACT_CASES))
def test_contact_flag_at_the_edge_is_one_line(case, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    argv, flag = CONTACT_CASES[case]
    code, out, err = run_cli(["contact", *argv, "--json"], capsys)
    _clean_refusal(code, err, flag)
    assert out == "" and list(tmp_path.iterdir()) == []


def test_p0_list_over_the_loads_bound_is_refused_at_once(capsys, monkeypatch):
    monkeypatch.setenv("FLATCONTACT_MAX_LOADS", "9")  # the preset's analysis.p_gpa has 8
    p0 = ",".join(f"{0.1 * (i + 1):.1f}" for i in range(10))
    code, _, err = run_cli(["contact", "--p0-gpa", p0], capsys)
    _clean_refusal(code, err, "--p0-gpa", "FLATCONTACT_MAX_LOADS")


def test_elastic_strain_subnormal(capsys):
    code, _, err = run_cli(["elastic", "--strain", SUBNORMAL], capsys)
    _clean_refusal(code, err, "--strain", "subnormal")


@pytest.mark.parametrize(
    "section,field",
    [
        ("scan: {fmax_ev_per_angstrom: 1.0e-320}", "scan.fmax_ev_per_angstrom"),
        ("elastic: {strain: 1.0e-320}", "elastic.strain"),
        ("contact: {shear_modulus_gpa: 1.0e-320}", "contact.shear_modulus_gpa"),
        ("analysis: {p_gpa: [0.0, 1.0e-320]}", "analysis.p_gpa"),
        ("contact: {maugis_lambda: 1.0e-320, work_of_adhesion_j_per_m2: 0.1}", "maugis_lambda"),
    ],
)
def test_config_field_at_the_edge_is_one_line(section, field, tmp_path, capsys):
    path = tmp_path / "c.yaml"
    path.write_text(section + "\n")
    code, _, err = run_cli(["config", "--check", str(path)], capsys)
    _clean_refusal(code, err, "c.yaml", field)


@pytest.mark.parametrize(
    "argv",
    [
        ["--radius-um", "1e-3", "--contact-modulus-gpa", "1e4", "--shear-modulus-gpa", "0.01"],
        ["--radius-um", "1e4", "--contact-modulus-gpa", "0.01", "--shear-modulus-gpa", "1e4"],
        ["--p0-gpa", "1e-6,1e3", "--tau0-mpa", "1e5", "--sigma0-mpa", "1e5"],
        ["--work-of-adhesion-j-per-m2", "100", "--maugis-lambda", "1e-3"],
        ["--work-of-adhesion-j-per-m2", "100", "--maugis-lambda", "1e3", "--radius-um", "1e4"],
        [
            *(
                "--work-of-adhesion-j-per-m2",
                "1e-6",
                "--maugis-lambda",
                "1e-3",
                "--radius-um",
                "1e4",
            ),
            *("--contact-modulus-gpa", "1e4", "--shear-modulus-gpa", "0.01", "--p0-gpa", "1e3"),
        ],
        ["--work-of-adhesion-j-per-m2", "0", "--tau0-mpa", "0", "--sigma0-mpa", "0"],
    ],
)
def test_contact_at_the_bounds_runs_clean(argv, capsys):
    """The ends of the stated bounds are physics, not overflow: exit 0, finite numbers only."""
    code, out, err = run_cli(["contact", *argv, "--json"], capsys)
    assert code in (0, None), err
    assert "Warning" not in err and "Traceback" not in err, err
    assert "Infinity" not in out and "NaN" not in out
    json.loads(out)


def test_every_bounded_field_states_its_bounds():
    for model in (ContactConfig, ScanConfig, ElasticConfig):
        for name, field in model.model_fields.items():
            bounds = field_bounds(field)
            if bounds is not None:
                assert bounds.text() in field.description, (model.__name__, name)
    r = field_bounds(ContactConfig.model_fields["radius_um"])
    assert (r.lo, r.hi) == (1e-3, 1e4)  # 1 nm .. 1 cm


# ------------------------------------------------------------------ property: out of bounds


def _outside(lo: float, hi: float):
    """Floats below ``lo``, above ``hi``, or subnormal (nonzero, |x| < 2.2e-308)."""
    tiny = sys.float_info.min
    return st.one_of(
        st.floats(max_value=lo, exclude_max=True, allow_nan=False, allow_infinity=False),
        st.floats(min_value=hi, exclude_min=True, allow_nan=False, allow_infinity=False),
        st.floats(min_value=-tiny, max_value=tiny, exclude_min=True, exclude_max=True).filter(
            lambda x: x != 0.0
        ),
        st.sampled_from([float("nan"), float("inf"), float("-inf")]),
    )


_RADIUS = field_bounds(ContactConfig.model_fields["radius_um"])
_STRAIN = field_bounds(ElasticConfig.model_fields["strain"])
_FMAX = field_bounds(ScanConfig.model_fields["fmax_ev_per_angstrom"])
_QUICK = settings(
    max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


@_QUICK
@given(x=_outside(_RADIUS.lo, _RADIUS.hi))
def test_radius_flag_outside_bounds_is_refused(x, capsys):
    code, _, err = run_cli(["contact", f"--radius-um={x!r}"], capsys)
    _clean_refusal(code, err, "--radius-um")


@_QUICK
@given(x=_outside(_STRAIN.lo, _STRAIN.hi))
def test_strain_flag_outside_bounds_is_refused(x, capsys):
    code, _, err = run_cli(["elastic", f"--strain={x!r}"], capsys)
    _clean_refusal(code, err, "--strain")


@_QUICK
@given(x=_outside(_FMAX.lo, _FMAX.hi).filter(lambda v: np.isfinite(v)))
def test_fmax_field_outside_bounds_is_refused(x, tmp_path_factory, capsys):
    path = tmp_path_factory.mktemp("fmax") / "c.yaml"
    path.write_text(f"scan: {{fmax_ev_per_angstrom: {x:.17e}}}\n")  # a YAML 1.1 float
    code, _, err = run_cli(["config", "--check", str(path)], capsys)
    _clean_refusal(code, err, "scan.fmax_ev_per_angstrom")


# ------------------------------------------------------------------ measured-data files

HEADER = "mean shear stress [MPa],lateral stiffness [N/m]\n"


def _synthetic_rows() -> list[str]:
    """A "measurement" made by the model at τ0 = 40 MPa, p0 = 1.77 GPa (no real data ships)."""
    truth = ContactParameters(tau0_mpa=40.0)
    p0 = 1.77e9
    stress = np.linspace(0.02, 1.4, 30) * ex.model_collapse_stress(p0, truth)
    k = ex.model_stiffness_at_stress(stress, p0, truth)
    return [f"{float(s) / 1e6!r},{float(v)!r}\n" for s, v in zip(stress, k, strict=True)]


def _tau0(path: Path, capsys) -> float:
    code, out, err = run_cli(
        ["contact", "--p0-gpa", "1.77", "--experiment-csv", str(path), "--json"], capsys
    )
    assert code in (0, None), err
    return json.loads(out)["experiment"]["fitted_tau0_mpa"]


def test_shuffled_and_repeated_csv_gives_the_sorted_result(tmp_path, capsys):
    rows = _synthetic_rows()
    sorted_csv = tmp_path / "sorted.csv"
    sorted_csv.write_text(HEADER + "".join(rows))
    messy = rows + rows[::3]  # every third row twice
    random.Random(7).shuffle(messy)
    messy_csv = tmp_path / "messy.csv"
    messy_csv.write_text(HEADER + "".join(messy))
    tau_sorted = _tau0(sorted_csv, capsys)
    assert tau_sorted == pytest.approx(40.0, rel=0.02)
    assert _tau0(messy_csv, capsys) == tau_sorted  # exactly


@pytest.mark.parametrize(
    "body,line,words",
    [
        ("1,1000\n2,1_0\n3,500\n4,10\n", "line 3", ["1_0", "plain decimal"]),
        ("1,1000\n2,0x10\n3,500\n4,10\n", "line 3", ["0x10"]),
        ("1,1000\n2,1e-320\n3,500\n4,10\n", "line 3", ["subnormal"]),
        ("1,1000\n2,900\n3,-500\n4,10\n", "line 4", ["stiffness", "0..1e+12 N/m"]),
        ("1,1000\n-2,900\n3,500\n4,10\n", "line 3", ["stress", "0..100000 MPa"]),
        ("1,1000\n2,900\n2,800\n4,10\n", "lines 3 and 4", ["same stress"]),
        ("1,0\n2,0\n3,0\n4,0\n", None, ["same stiffness"]),
        ("1,1000\n2,1000\n3,1000\n4,1000\n", None, ["same stiffness"]),
        ("2,1000\n2,900\n2,500\n2,10\n", None, ["same stress"]),
        ("1,1000\n2,900\n1e303,500\n4,10\n", "line 4", ["stress", "100000 MPa"]),
        ("1,1000\n2,900\n3,1e308\n4,10\n", "line 4", ["stiffness", "N/m"]),
    ],
)
def test_impossible_csv_is_one_line_naming_file_and_row(body, line, words, tmp_path, capsys):
    path = tmp_path / "measured.csv"
    path.write_text(HEADER + body)
    code, _, err = run_cli(["contact", "--p0-gpa", "1.77", "--experiment-csv", str(path)], capsys)
    text = _clean_refusal(code, err, "measured.csv", *words)
    if line is not None:
        assert line in text


@pytest.mark.parametrize(
    "load,cell,words",
    [("p0 [GPa]", "1e300", ["load", "1000] GPa"]), ("normal load [uN]", "1e300", ["10000] N"])],
)
def test_fit_table_load_beyond_bounds_names_the_line(load, cell, words, tmp_path):
    from flatcontact.contact.measured import read_table

    path = tmp_path / "table.csv"
    path.write_text(
        f"mean shear stress [MPa],lateral stiffness [N/m],{load}\n1,1000,1\n2,900,{cell}\n"
    )
    with pytest.raises(InputError) as info:
        read_table(path, ContactParameters())
    text = str(info.value)
    assert "table.csv: data line 3" in text and "\n" not in text
    for word in words:
        assert word in text, text


def test_fit_table_rows_in_any_order_read_the_same(tmp_path):
    from flatcontact.contact.measured import read_table

    rows = [
        f"{s},{k},{p}\n"
        for p in (1.0, 2.0)
        for s, k in ((1, 1000), (2, 900), (3, 500), (4, 10), (5, 0))
    ]
    shuffled = rows + rows[:3]
    random.Random(3).shuffle(shuffled)
    head = "mean shear stress [MPa],lateral stiffness [N/m],p0 [GPa]\n"
    (tmp_path / "a.csv").write_text(head + "".join(rows))
    (tmp_path / "b.csv").write_text(head + "".join(shuffled))
    params = ContactParameters()
    a, b = read_table(tmp_path / "a.csv", params), read_table(tmp_path / "b.csv", params)
    assert [c.p0_gpa for c in a] == [c.p0_gpa for c in b] == [1.0, 2.0]
    for ca, cb in zip(a, b, strict=True):
        np.testing.assert_array_equal(ca.stress_pa, cb.stress_pa)
        np.testing.assert_array_equal(ca.stiffness_n_per_m, cb.stiffness_n_per_m)
