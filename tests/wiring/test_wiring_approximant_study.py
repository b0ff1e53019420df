"""``report.approximant_study`` followed from the YAML to the report, on the cheap toy run.

An approximant study's record (written by the study's own writers: ``write_approximants``,
and ``approximant_collapse`` for ``experiment_collapse.json``) named in an ordinary run's
``report:`` section: the report tables its cells with the numbers of those files, marks the
run's own cell when the build's lock has its atoms and twist, reruns when the study's files
change (their content is in the report's inputs, the scan is not rerun) and a file that is not
an approximant study is refused in one line before any stage.
"""

from __future__ import annotations

import json
import shutil

import pytest
from tests.studies.test_approximants_study import _fake_doc
from tests.wiring.test_wiring_experiment import TOY

from flatcontact.config import build_config
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import write_json_atomic
from flatcontact.foundation.layout import EXPERIMENT_COLLAPSE_JSON
from flatcontact.pipeline import Pipeline
from flatcontact.report.format import fmt
from flatcontact.report.sections.approximant_study import this_run_label
from flatcontact.studies.approximant_collapse import approximant_collapse
from flatcontact.studies.output import write_approximants

#: The experiment's moduli (examples/passivated-tip-*.yaml), given as the study requires.
MODULI = {"contact_modulus_gpa": 69.64, "shear_modulus_gpa": 63.40}


def _study(folder, scale=1.0):
    doc = _fake_doc()
    for cell in doc["cells"]:
        for key in ("tau0_mpa", "sigma0_mpa"):
            cell[key] *= scale
    write_approximants(doc, folder, "flatcontact study approximants (test)")
    cfg = build_config({**TOY, "contact": {**TOY["contact"], **MODULI}})
    rows = approximant_collapse(doc, cfg)
    write_json_atomic(folder / EXPERIMENT_COLLAPSE_JSON, json.loads(json.dumps(rows)))
    return doc, rows


def _config(study_json):
    return build_config(
        {
            **TOY,
            "contact": {**TOY["contact"], **MODULI},
            "report": {**TOY["report"], "approximant_study": str(study_json)},
        }
    )


@pytest.fixture(scope="module")
def run_with_study(tmp_path_factory):
    base = tmp_path_factory.mktemp("approx")
    doc, rows = _study(base / "study")
    root = base / "toy"
    with Pipeline(_config(base / "study" / "study.json"), root) as pipe:
        pipe.run()
    return base, root, doc, rows


def test_the_report_tables_the_study_from_its_own_files(run_with_study):
    _, root, doc, rows = run_with_study
    report = (root / "report.html").read_text()
    assert "Toward the incommensurate contact: the approximant study" in report
    assert "none of its cells has this run" in report  # the toy is no cell of the study
    for cell in doc["cells"][:3]:
        assert f"<td>{cell['label']}</td>" in report
        assert f"<td>{fmt(cell['tau0_mpa'])}</td>" in report
    collapses = [r["collapse_stress_mpa"] for r in rows["cells"] if r["collapse_stress_mpa"]]
    assert len(collapses) == 3
    for value in collapses:
        assert f"<td>{fmt(value)}</td>" in report
    assert "refused: refused" in report  # the cell the study could not run says so


def test_a_changed_study_reruns_the_report_only(run_with_study, tmp_path):
    """τ0 and σ0 of every cell ×1000 (so every collapse ×1000: homogeneous in the laws): the
    report reruns with the new numbers; build, scan and contact do not."""
    base, root, _, _ = run_with_study
    study = tmp_path / "study"
    shutil.copytree(base / "study", study)
    copy = tmp_path / "toy"
    shutil.copytree(root, copy)
    doc, rows = _study(study, scale=1e3)
    with Pipeline(_config(study / "study.json"), copy) as pipe:
        pipe.run()
        actions = {name: res.action for name, res in pipe.results.items()}
    assert actions["report"] == "ran"
    assert all(actions[s] != "ran" for s in ("build", "scan", "analyze", "laws", "contact"))
    report = (copy / "report.html").read_text()
    assert f"<td>{fmt(doc['cells'][0]['tau0_mpa'])}</td>" in report
    assert f"<td>{fmt(rows['cells'][0]['collapse_stress_mpa'])}</td>" in report


def test_the_runs_own_cell_is_marked():
    doc = _fake_doc()
    build = {"recipe": {"twist_angle_deg": 15.8, "match": {"kind": "twist", "n_atoms": 76}}}
    assert this_run_label(doc, build) == "twist-2-3"
    build["recipe"]["twist_angle_deg"] = 13.1736  # same atoms, another twist
    assert this_run_label(doc, build) is None
    assert this_run_label(doc, {"recipe": {"kind": "toy-lj"}}) is None


def test_a_file_that_is_not_an_approximant_study_is_refused_before_any_stage(tmp_path):
    wrong = tmp_path / "study.json"
    wrong.write_text(json.dumps({"study": "convergence", "cells": []}))
    with pytest.raises(InputError) as info:
        Pipeline(_config(wrong), tmp_path / "run")
    text = str(info.value)
    assert "\n" not in text and "report.approximant_study" in text and "'convergence'" in text
    assert not (tmp_path / "run" / "01-build").exists()
