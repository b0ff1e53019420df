"""The paper preset's quartz uncertainty file is what the studies measured.

``src/flatcontact/data/measured/law_uncertainty.json`` was written by ``flatcontact study
export-uncertainty`` from the two stored studies in ``docs/measured/quartz-study``
(``examples/quartz-convergence.yaml`` and ``examples/quartz-models.yaml``). Checked here,
without rerunning anything:

* the file equals the export of the stored ``study.json`` files (numbers, fingerprints,
  their SHA-256) — the command's own merge (:func:`flatcontact.studies.export.merge_studies`);
* each study's block is recomputed in the test from its variants' fitted laws by the rules
  of docs/studies.md (δ_conv = the largest |Δc| over each counted setting's last step;
  δ_model = half the max − min range), written out here, not through the study's code;
* the docs table (docs/convergence.md, "Measured law uncertainty of the paper preset")
  shows these numbers;
* the file is measured on the paper preset's structure and model, the preset carries it,
  and the fingerprints refuse it on another structure or model.
"""

import json
import re
from pathlib import Path

import pytest

from flatcontact.analysis.uncertainty import LAW_COEFFICIENTS
from flatcontact.config import MEASURED_LAW_UNCERTAINTY, build_config
from flatcontact.config.presets import LAW_UNCERTAINTY_FILE
from flatcontact.config.uncertainty import UncertaintyConfig
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import file_sha256
from flatcontact.stages.measured_on import check_measured_on, measured_on
from flatcontact.studies.export import merge_studies

ROOT = Path(__file__).resolve().parents[2]
STUDIES = ROOT / "docs" / "measured" / "quartz-study"
CONVERGENCE = STUDIES / "convergence" / "study.json"
MODELS = STUDIES / "models" / "study.json"
FORMS = ("internal", "enthalpy")
BLOCKS = tuple(f"{kind}_{form}" for kind in ("convergence", "model_spread") for form in FORMS)


def _sig3(x: float) -> float:
    return float(f"{x:.3g}")


@pytest.fixture(scope="module")
def data_file() -> dict:
    return json.loads(LAW_UNCERTAINTY_FILE.read_text())


@pytest.fixture(scope="module")
def studies() -> dict[str, dict]:
    return {str(p.relative_to(ROOT)): json.loads(p.read_text()) for p in (CONVERGENCE, MODELS)}


def test_the_file_is_the_export_of_the_stored_studies(data_file, studies):
    merged = merge_studies(studies)
    for block in BLOCKS:
        assert data_file[block] == merged[block], block
    assert data_file["measured_on"] == merged["measured_on"]
    recorded = {s["file"]: s for s in data_file["provenance"]["studies"]}
    assert set(recorded) == set(studies)
    for name in studies:
        assert recorded[name]["sha256"] == file_sha256(ROOT / name), name
        assert recorded[name]["provenance"] == studies[name]["uncertainty"]["provenance"]
    assert {b for s in recorded.values() for b in s["blocks"]} == set(BLOCKS)
    assert "study export-uncertainty" in data_file["provenance"]["command"]


@pytest.mark.parametrize("form", FORMS)
def test_convergence_block_is_the_bases_error_over_the_counted_ladders(studies, form):
    """δ_conv recomputed from the variants (docs/studies.md): every setting that is not ``not
    refined`` and had an analysable step counts with |c(finest) − c(base)|, its finest
    analysable variant being the last of its ladder's variants in study.json."""
    doc = studies[str(CONVERGENCE.relative_to(ROOT))]
    laws = {v["name"]: v["laws"][form] for v in doc["variants"]}
    finest = {}
    for v in doc["variants"]:
        if v["setting"] != "base" and v["level"] > finest.get(v["setting"], (0, ""))[0]:
            finest[v["setting"]] = (v["level"], v["name"])
    counted = [
        finest[s][1]
        for s, st in doc["settings"].items()
        if st["state"] != "not refined" and s in finest
    ]
    assert counted, "no setting was measured"
    block = doc["uncertainty"][f"convergence_{form}"]
    for key in LAW_COEFFICIENTS:
        delta = max(abs(float(laws[name][key]) - float(laws["base"][key])) for name in counted)
        assert block[key] == _sig3(delta), key


@pytest.mark.parametrize("form", FORMS)
def test_model_block_is_half_the_range_over_the_models_that_ran(studies, form):
    doc = studies[str(MODELS.relative_to(ROOT))]
    assert len(doc["variants"]) >= 2
    block = doc["uncertainty"][f"model_spread_{form}"]
    for key in LAW_COEFFICIENTS:
        vals = [float(v["laws"][form][key]) for v in doc["variants"]]
        assert block[key] == _sig3((max(vals) - min(vals)) / 2), key


def test_the_numbers_are_the_docs_table(data_file):
    """docs/convergence.md, "Measured law uncertainty of the paper preset": one row per block."""
    text = (ROOT / "docs" / "convergence.md").read_text()
    section = text.split("## Measured law uncertainty of the paper preset", 1)[1].split("\n## ")[0]
    rows = {}
    for line in section.splitlines():
        m = re.match(r"\| `(\w+)` \|(.+)\|\s*$", line)
        if m:
            rows[m.group(1)] = [float(c) for c in m.group(2).split("|")]
    assert set(rows) == set(BLOCKS)
    for block in BLOCKS:
        assert rows[block] == [data_file[block][k] for k in LAW_COEFFICIENTS]


def test_the_file_is_an_uncertainty_block_measured_on_the_paper_preset(data_file, studies):
    block = UncertaintyConfig.model_validate(data_file)
    paper = build_config({}, "paper")
    assert block.measured_on == measured_on(paper)
    for doc in studies.values():
        assert doc["uncertainty"]["measured_on"] == measured_on(paper)
    # the preset carries it (numbers and fingerprints), and its own run passes the check
    assert paper.uncertainty.measured_on == data_file["measured_on"]
    assert paper.uncertainty.convergence_internal == data_file["convergence_internal"]
    assert MEASURED_LAW_UNCERTAINTY["measured_on"] == data_file["measured_on"]
    check_measured_on(paper)


def test_the_paper_block_carried_to_another_structure_or_model_is_refused():
    """build_config drops the preset's block when the file changes structure or potential;
    a block given explicitly (copied) is caught by its fingerprints."""
    block = {k: v for k, v in MEASURED_LAW_UNCERTAINTY.items()}
    thicker = build_config({"structure": {"layers": 12}, "uncertainty": block}, "paper")
    with pytest.raises(InputError, match="another structure"):
        check_measured_on(thicker, "thicker")
    shorter = build_config(
        {"potential": {"lj": {"cutoff_angstrom": 10.0}}, "uncertainty": block}, "paper"
    )
    with pytest.raises(InputError, match="another potential"):
        check_measured_on(shorter, "shorter")
    # other scan settings of the same interface and model: the block applies
    check_measured_on(build_config({"scan": {"grid": [8, 8]}, "uncertainty": block}, "paper"))
