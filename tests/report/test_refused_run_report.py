"""A run refused after the scan still writes its report (issue 32): what was computed, the
refusal with its points and the remedies, the grid among them where the refusal can be the
grid's; a rerun redoes no finished stage. And after ``contact.accept_untrusted`` the report
names the untrusted numbers that flowed on.

The refused run is the toy Lennard-Jones interface on a 7 × 7 grid: its σ_MSS falls with the
load in the internal form (μ = −7.0, interval −8.7 .. −5.4 MPa/GPa over 0, 0.5, 1 GPa, measured
with this code) and the ``negative_slope`` gate stops it before the contact stage.
"""

from __future__ import annotations

import json
import re

import pytest

from flatcontact.foundation.layout import REFUSAL_JSON, REPORT_HTML
from flatcontact.report.html import render_html
from flatcontact.report.sections.gates import gates_section
from flatcontact.report.sections.refusal import (
    finer_grid,
    refusal_record,
    refusal_section,
    remedies,
)

REFUSED_YAML = """\
structure: {kind: toy-lj, layers: 3}
potential: {calculator: {target: "flatcontact.ispes.toy:toy_calculator"}}
scan:
  grid: [7, 7]
  p_range_gpa: {lo_gpa: -0.2, hi_gpa: 1.5, n: 4}
  executor: serial
analysis: {p_gpa: [0.0, 0.5, 1.0]}
contact: {p0_gpa: [0.5, 1.0]}
report: {svg: false}
"""


def _text(page: str) -> str:
    """The report's words (figures, style and tags removed)."""
    import html

    page = re.sub(r"<style>.*?</style>", " ", page, flags=re.S)
    page = re.sub(r"<img[^>]*>", " ", page)
    return " ".join(html.unescape(re.sub(r"<[^>]+>", " ", page)).split())


@pytest.fixture(scope="module")
def refused_run(tmp_path_factory):
    """(config, run directory, the refusal line, the stage records after the first run)."""
    from flatcontact.config.load import load_config
    from flatcontact.foundation.errors import InputError
    from flatcontact.pipeline import Pipeline

    base = tmp_path_factory.mktemp("refused")
    (base / "run.yaml").write_text(REFUSED_YAML)
    cfg = load_config(base / "run.yaml")
    with Pipeline(cfg, base / "run") as pipe, pytest.raises(InputError) as info:
        pipe.run()
    records = {
        d.name: (d / "stage.json").read_text() for d in (base / "run").glob("0*-*") if d.is_dir()
    }
    return cfg, base / "run", str(info.value), records


def test_the_refusal_names_the_gate_its_numbers_and_the_report(refused_run):
    _, run, line, _ = refused_run
    assert "\n" not in line
    assert line.startswith("negative_slope: ") and "μ = " in line
    assert str(run / REPORT_HTML) in line
    assert not (run / "06-contact").exists()  # the contact stage never started


def test_the_report_holds_what_was_computed_the_refusal_its_points_and_the_remedies(
    refused_run,
):
    _, run, _, _ = refused_run
    record = json.loads((run / "07-report" / REFUSAL_JSON).read_text())
    assert record["stage"] == "contact"
    assert record["finished"] == ["build", "scan", "analyze", "laws"]
    (finding,) = record["findings"]
    assert finding["gate"] == "negative_slope"
    # the numbers that failed the gate: μ and its whole interval below 0, as laws.json says
    laws = json.loads((run / "04-laws" / "laws.json").read_text())
    mu = laws["intervals"]["mu_mpa_per_gpa"]
    assert mu["high"] < 0
    for value in (mu["value"], mu["low"], mu["high"]):
        assert f"{value:.3g}" in finding["message"]
    # the grid is among the remedies, with the finer grid to try
    assert record["remedies"][0].startswith(
        "a finer lateral grid, scan.grid: [11, 11] (now [7, 7])"
    )
    assert any("accept_untrusted" in r for r in record["remedies"])
    text = _text((run / REPORT_HTML).read_text())
    assert (run / REPORT_HTML).read_bytes() == (run / "07-report" / REPORT_HTML).read_bytes()
    # the refusal first, then the sections of the finished stages, their figures embedded
    order = [
        text.index(t)
        for t in (
            "Run refused",
            "Summary",
            "1. Interface",
            "2. ISPES scan",
            "3. Constant-pressure",
            "4. Load laws",
        )
    ]
    assert order == sorted(order), text[:400]
    assert "Gate negative_slope fired" in text and f"{mu['value']:.3g}" in text
    assert "scan.grid: [11, 11]" in text
    assert "contact refused" in text  # the stage table
    page = (run / REPORT_HTML).read_text()
    assert page.count("data:image/png;base64") >= 3  # Fig. 1, the scan's columns, Fig. 2 ...
    assert "5. Modified Mindlin contact" not in text  # no contact numbers exist


def test_a_rerun_of_the_refused_run_redoes_no_finished_stage(refused_run):
    from flatcontact.foundation.errors import InputError
    from flatcontact.pipeline import Pipeline

    cfg, run, line, records = refused_run
    events = []
    with Pipeline(cfg, run, on_event=events.append) as pipe, pytest.raises(InputError) as info:
        pipe.run()
    assert str(info.value) == line
    ended = {e.name: e.action for e in events if e.kind == "end"}
    assert ended == {n: "skipped" for n in ("build", "scan", "analyze", "laws", "report")}
    for name in ("01-build", "02-scan", "03-analyze", "04-laws", "07-report"):
        assert (run / name / "stage.json").read_text() == records[name]


def test_a_report_of_a_run_refused_in_the_analysis_holds_the_fold_and_its_remedies(
    refused_run, tmp_path
):
    """The same finished build and scan, refused in the analysis (a fold the scan recorded):
    no analysis, laws or contact section; the fold's column, z, p and refused loads; the
    relaxation, the thicknesses (the grid) and lower loads among the remedies."""
    from flatcontact.foundation.layout import STAGES
    from flatcontact.stages.report import ReportInputs, report_stage

    cfg, run, _, _ = refused_run
    fold = {
        "column": "grid column at shift (0.429, 0.143) (-(1/A) dU/dz)",
        "z_angstrom": 11.3125,
        "p_gpa": 1.02,
        "loads_refused_gpa": [1.5],
    }
    message = (
        "P = 1.5 GPa is at or above a fold of grid column at shift (0.429, 0.143): ... the "
        "energies are not converged enough for their derivative: tighten "
        "scan.fmax_ev_per_angstrom or use analysis.load_source: stress"
    )
    record = refusal_record("analyze", message, [], ["build", "scan"], (7, 7), [fold])
    folders = {name: run / f"{index:02d}-{name}" for name, index in STAGES.items()}
    report_stage(cfg, ReportInputs(folders, {}, record), tmp_path)
    assert json.loads((tmp_path / REFUSAL_JSON).read_text()) == record
    text = _text((tmp_path / REPORT_HTML).read_text())
    assert "Refused (analyze)" in text and "not converged enough" in text
    assert "grid column at shift (0.429, 0.143)" in text and "11.3125" in text and "1.02" in text
    assert "2. ISPES scan" in text and "4. Load laws" not in text
    assert "3. Constant-pressure" not in text
    assert "analyze refused" in text and "laws done" not in text
    joined = " | ".join(record["remedies"])
    assert "tighten scan.fmax_ev_per_angstrom" in joined
    assert "more thicknesses around the fold" in joined and "analysis.p_gpa" in joined


def test_remedies_name_the_grid_where_the_refusal_can_be_the_grids():
    assert finer_grid([6, 6]) == "a finer lateral grid, scan.grid: [9, 9] (now [6, 6])"
    slope = {"stage": "contact", "message": "x", "findings": [{"gate": "negative_slope"}]}
    assert "scan.grid: [9, 9]" in remedies(slope, (6, 6))[0]
    slip = {"stage": "contact", "message": "x", "findings": [{"gate": "in_slab_slip"}]}
    assert not any("scan.grid" in r for r in remedies(slip, (6, 6)))
    other = {"stage": "analyze", "message": "analysis.energy_form: unknown", "findings": []}
    assert remedies(other, (6, 6)) == []
    section = refusal_section(refusal_record("laws", "too few loads", [], ["build"], (3, 3)))
    assert section.title == "Run refused" and section.notes == ["Refused (laws): too few loads"]


def test_after_accept_untrusted_the_box_names_the_numbers_that_flowed_on():
    contact = {
        "gates": {
            "fired": [{"gate": "negative_slope", "message": "μ < 0", "overridden": True}],
            "overridden": ["negative_slope"],
            "notes": [],
        },
        "parameters": {
            "k_mpa_per_gpa": 10.0,
            "tau0_mpa": 449.5,
            "mu_mpa_per_gpa": -7.02,
            "sigma0_mpa": 130.2,
            "contact_modulus_gpa": 52.5,
            "shear_modulus_gpa": 29.0,
            "work_of_adhesion_j_per_m2": 0.18,
        },
        "provenance": {
            "k_mpa_per_gpa": "config",
            "tau0_mpa": "fitted laws",
            "mu_mpa_per_gpa": "fitted laws",
            "sigma0_mpa": "fitted laws",
            "work_of_adhesion_j_per_m2": "scan work of separation",
            "moduli": "config",
        },
        "results": [{"p0_gpa": 0.5}, {"p0_gpa": 1.0}],
    }
    section = gates_section(contact)
    (line,) = [n for n in section.notes if n.startswith("Untrusted numbers that flowed on")]
    assert "τ0 = 449.5 MPa" in line and "μ = -7.02 MPa/GPa" in line and "σ0 = 130.2 MPa" in line
    assert "k = " not in line  # given in the configuration, not the gated fit
    assert "w = " not in line  # a negative slope does not reach the landscape's W
    assert "p0 = 0.5, 1 GPa" in line
    assert "E* = 52.5 GPa and G* = 29 GPa are the configuration's" in line
    assert "Untrusted numbers" in render_html("t", [section])
