"""Result files read back as if true: every JSON file a stage, the report or a study reads
back goes through its checked reader (flatcontact.foundation.result_json): truncated, of the wrong
types, or inconsistent with the stage record and the settings is one line naming it; an
ispes.nc of another grid beside a record claiming this run's is refused; a file that is not a
regular file (a FIFO) is refused before it is opened; export-uncertainty's inputs and --out
are checked the same way."""

from __future__ import annotations

import hashlib
import json
import math
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest
from tests.hardening.helpers import finished_toy_run, refused, run_cli

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.result_json import LAWS, SCAN, SUMMARY, check_document, read_result_json


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    return finished_toy_run(tmp_path_factory.mktemp("finished"))


@pytest.fixture
def copy(finished, tmp_path):
    conf, run = finished
    shutil.copytree(conf, tmp_path / "conf")
    shutil.copytree(run, tmp_path / "run")
    return tmp_path / "conf" / "run.yaml", tmp_path / "run"


def plant(run, rel: str, data: bytes, *rerun: str) -> None:
    """Write ``data`` to ``run/rel`` and make its stage record claim it (digest updated);
    remove the stage folders ``rerun`` so the stages that read it run again."""
    path = run / rel
    path.write_bytes(data)
    record = path.parent / "stage.json"
    doc = json.loads(record.read_text())
    doc["outputs"][path.name] = hashlib.sha256(data).hexdigest()
    record.write_text(json.dumps(doc))
    for name in rerun:
        shutil.rmtree(run / name)


def _edited(run, rel: str, edit) -> bytes:
    doc = json.loads((run / rel).read_text())
    edit(doc)
    return json.dumps(doc).encode()


def _truncated(run, rel):
    return (run / rel).read_bytes()[:100]


def _set(path: str, value):
    def edit(doc):
        *head, last = path.split(".")
        for key in head:
            doc = doc[int(key)] if isinstance(doc, list) else doc[key]
        doc[int(last) if isinstance(doc, list) else last] = value

    return edit


CASES = {
    # (file, how it is planted, stage folders to rerun, names in the one line)
    "laws-truncated": ("04-laws/laws.json", _truncated, ["06-contact"], ["laws.json", "JSON"]),
    "laws-intervals-text": (
        "04-laws/laws.json",
        lambda r, f: _edited(r, f, _set("internal.intervals", "wide")),
        ["06-contact"],
        ["laws.json", "internal.intervals", "mapping"],
    ),
    "laws-interval-component-text": (
        "04-laws/laws.json",
        lambda r, f: _edited(
            r, f, _set("internal.intervals.k_mpa_per_gpa.components", {"fit": "0.1"})
        ),
        ["06-contact"],
        ["laws.json", "components.fit"],
    ),
    "laws-k-text": (
        "04-laws/laws.json",
        lambda r, f: _edited(r, f, _set("k_mpa_per_gpa", "4.5")),
        ["06-contact"],
        ["laws.json", "k_mpa_per_gpa", "finite number"],
    ),
    "laws-other-form": (
        "04-laws/laws.json",
        lambda r, f: _edited(r, f, _set("energy_form", "enthalpy")),
        ["06-contact"],
        ["laws.json", "energy_form", "settings"],
    ),
    "scan-truncated": ("02-scan/scan.json", _truncated, ["06-contact"], ["scan.json", "JSON"]),
    "scan-points-of-another-grid": (
        "02-scan/scan.json",
        lambda r, f: _edited(r, f, _set("points_total", 160)),
        ["06-contact"],
        ["scan.json", "points_total", "3x3"],
    ),
    "summary-truncated": (
        "06-contact/summary.json",
        _truncated,
        ["07-report"],
        ["summary.json", "JSON"],
    ),
    "summary-other-loads": (
        "06-contact/summary.json",
        lambda r, f: _edited(r, f, _set("results.0.p0_gpa", 2.0)),
        ["07-report"],
        ["summary.json", "p0"],
    ),
    "analyze-not-a-mapping": (
        "03-analyze/analyze.json",
        lambda r, f: b"[1, 2]",
        ["07-report"],
        ["analyze.json", "not a mapping"],
    ),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_a_planted_result_file_is_one_line(copy, capsys, case):
    conf, run = copy
    rel, make, rerun, names = CASES[case]
    plant(run, rel, make(run, rel), *rerun)
    code, _, err = run_cli(["run", conf, "--out", run], capsys)
    refused(code, err, *names)


def test_an_ispes_of_another_grid_beside_this_runs_record_is_refused(copy, capsys, tmp_path):
    """A real 4x4 scan's ispes.nc planted beside the record of this 3x3 run (analysis rerun):
    the analysis ran on the foreign landscape before."""
    from tests.studies.toy import toy_scan

    conf, run = copy
    toy_scan(tmp_path / "foreign", 4, 3, 0.05)
    data = (tmp_path / "foreign" / "ispes.nc").read_bytes()
    plant(run, "02-scan/ispes.nc", data, "03-analyze", "04-laws", "06-contact", "07-report")
    code, _, err = run_cli(["run", conf, "--out", run], capsys)
    refused(code, err, "ispes.nc", "4x4", "3x3")
    assert not (run / "03-analyze").exists()


def test_the_contracts_accept_the_files_a_run_writes_and_additive_fields(finished):
    _, run = finished
    laws = read_result_json(run / "04-laws" / "laws.json", energy_form="internal")
    read_result_json(run / "02-scan" / "scan.json", grid=[3, 3])
    read_result_json(run / "06-contact" / "summary.json", p0_gpa=[1.0, 0.5])
    read_result_json(run / "03-analyze" / "analyze.json")
    laws["internal"]["intervals"]["k_mpa_per_gpa"]["grid_width"] = 0.3  # another helper's
    laws["a_new_block"] = {"anything": [1, "x"]}
    check_document(laws, LAWS, {"energy_form": "internal"})


@pytest.mark.parametrize("bad", [math.inf, -math.inf, math.nan, True, None, "1"])
def test_a_law_coefficient_must_be_a_finite_number(finished, bad):
    _, run = finished
    doc = json.loads((run / "04-laws" / "laws.json").read_text())
    doc["tau0_mpa"] = bad
    with pytest.raises(ValueError, match="tau0_mpa"):
        check_document(doc, LAWS)


def test_scan_and_summary_contracts_refuse_impossible_counts(finished):
    _, run = finished
    scan = json.loads((run / "02-scan" / "scan.json").read_text())
    for key, value in (("points_done", 10**6), ("force_calls_total", -1), ("area_angstrom2", 0)):
        doc = {**scan, key: value}
        with pytest.raises(ValueError, match=key):
            check_document(doc, SCAN)
    summary = json.loads((run / "06-contact" / "summary.json").read_text())
    summary["parameters"]["radius_um"] = [5.0]
    with pytest.raises(ValueError, match="radius_um"):
        check_document(summary, SUMMARY)


def _fifo(path):
    os.mkfifo(path)
    return path


def test_a_fifo_result_file_is_refused_before_it_is_opened(tmp_path):
    fifo = _fifo(tmp_path / "laws.json")
    with pytest.raises(InputError, match="not a regular file"):
        read_result_json(fifo)


def test_a_fifo_measured_csv_is_one_line_not_a_hang(tmp_path):
    """In a child process with a timeout: before, the read blocked for ever."""
    fifo = _fifo(tmp_path / "measured.csv")
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "flatcontact",
            "contact",
            "--experiment-csv",
            str(fifo),
            "--out",
            str(tmp_path / "out"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
        cwd=tmp_path,
        env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)},
    )
    refused(proc.returncode, proc.stderr, str(fifo), "not a regular file")


# ---- export-uncertainty --------------------------------------------------------------------


def _study(path, **block):
    uncertainty = {
        "convergence_internal": {
            "k_mpa_per_gpa": 1.0,
            "tau0_mpa": 1.0,
            "mu_mpa_per_gpa": 0.5,
            "sigma0_mpa": 0.5,
        },
        "measured_on": {"structure_sha256": "a" * 64, "model_sha256": "b" * 64},
        "source": "a toy study",
        **block,
    }
    path.write_text(json.dumps({"study": "convergence", "uncertainty": uncertainty}))
    return path


def test_export_of_a_well_formed_study_writes_the_file(tmp_path, capsys):
    study = _study(tmp_path / "study.json")
    code, _, err = run_cli(
        ["study", "export-uncertainty", study, "--out", tmp_path / "u.json"], capsys
    )
    assert code == 0, err
    assert json.loads((tmp_path / "u.json").read_text())["convergence_internal"]["tau0_mpa"] == 1


EXPORT_CASES = {
    "block-not-a-mapping": ({"convergence_internal": 5}, ["convergence_internal", "mapping"]),
    "measured-on-a-list": ({"measured_on": ["a", "b"]}, ["measured_on", "mapping"]),
    "source-not-text": ({"source": 5}, ["uncertainty.source", "text"]),
    "width-text": (
        {"convergence_internal": {"k_mpa_per_gpa": "1"}},
        ["convergence_internal.k_mpa_per_gpa", "finite"],
    ),
}


@pytest.mark.parametrize("case", sorted(EXPORT_CASES))
def test_export_refuses_a_malformed_study_in_one_line(tmp_path, capsys, case):
    block, names = EXPORT_CASES[case]
    study = _study(tmp_path / "study.json", **block)
    out = tmp_path / "u.json"
    code, _, err = run_cli(["study", "export-uncertainty", study, "--out", out], capsys)
    refused(code, err, str(study), *names)
    assert not out.exists()


def test_export_refuses_a_fifo_study_and_an_out_directory(tmp_path, capsys):
    fifo = _fifo(tmp_path / "study.json")
    code, _, err = run_cli(
        ["study", "export-uncertainty", fifo, "--out", tmp_path / "u.json"], capsys
    )
    refused(code, err, str(fifo), "not a regular file")
    study = _study(tmp_path / "good.json")
    (tmp_path / "dir").mkdir()
    code, _, err = run_cli(
        ["study", "export-uncertainty", study, "--out", tmp_path / "dir"], capsys
    )
    refused(code, err, "--out", "not a regular file")
    assert list((tmp_path / "dir").iterdir()) == []


def test_a_name_with_a_newline_is_quoted_in_the_one_line(tmp_path, capsys):
    study = _study(tmp_path / "bad\nname.json", convergence_internal=5)
    code, _, err = run_cli(
        ["study", "export-uncertainty", study, "--out", tmp_path / "u.json"], capsys
    )
    line = refused(code, err, "bad\\nname.json")
    assert "\n" not in line
    np.testing.assert_equal(len(err.strip().splitlines()), 1)


# ---- an approximant study's cells (report.approximant_study) -------------------------------


def _approximant_study(folder, edit):
    from tests.studies.test_approximants_study import _fake_doc

    from flatcontact.studies.output import write_approximants

    doc = _fake_doc()
    write_approximants(doc, folder, "flatcontact study approximants (test)")
    path = folder / "study.json"
    written = json.loads(path.read_text())
    edit(written)
    path.write_text(json.dumps(written))
    return path


@pytest.mark.parametrize(
    ("edit", "names"),
    [
        (lambda d: d.__setitem__("cells", ["junk", 3]), ["cells[0]", "mapping"]),
        (lambda d: d["cells"][0].__setitem__("tau0_mpa", "12.5"), ["cells[0].tau0_mpa"]),
        (lambda d: d["cells"][1].__setitem__("n_atoms", -4), ["cells[1].n_atoms", "count"]),
        (lambda d: d["cells"][0].__setitem__("strain_percent_slab1", "0 0"), ["strain"]),
        (lambda d: d["cells"][0].__setitem__("gates", {"fired": "none"}), ["gates.fired"]),
    ],
)
def test_an_approximant_studys_junk_cells_are_one_line_before_any_stage(tmp_path, edit, names):
    from tests.wiring.test_wiring_approximant_study import _config

    from flatcontact.pipeline import Pipeline

    path = _approximant_study(tmp_path / "study", edit)
    with pytest.raises(InputError) as info:
        Pipeline(_config(path), tmp_path / "run")
    text = str(info.value)
    assert "\n" not in text and "report.approximant_study" in text, text
    for name in names:
        assert name in text, (name, text)
    assert not (tmp_path / "run" / "01-build").exists()
