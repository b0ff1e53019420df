"""The paper preset's quartz uncertainty file: its numbers are the stored study results and the
docs table, it carries the fingerprints of the paper preset's structure and model, and the
fingerprint refusal guards it (not only build_config's comparison)."""

import json
import re
from pathlib import Path

import pytest

from flatcontact.analysis.uncertainty import LAW_COEFFICIENTS
from flatcontact.config import MEASURED_LAW_UNCERTAINTY, build_config
from flatcontact.config.presets import LAW_UNCERTAINTY_FILE
from flatcontact.config.uncertainty import UncertaintyConfig
from flatcontact.errors import InputError
from flatcontact.stages.measured_on import check_measured_on, measured_on

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "docs" / "measured" / "convergence"
BLOCKS = (
    "convergence_internal",
    "convergence_enthalpy",
    "model_spread_internal",
    "model_spread_enthalpy",
)
#: (coarser, finer) stored runs of the legacy quartz study whose largest |Δc| is δ_conv
#: (the rule of docs/convergence.md, "Measured law uncertainty of the paper preset").
REFINEMENTS = (
    ("grid8", "ref"),
    ("ref", "thick30"),
    ("grid8", "fmax0025_g8"),
    ("cutoff14_g8", "cutoff18_g8"),
    ("layers9_f25_g8", "layers12_f25_g8"),
    ("layers9_g8", "layers9_f25_g8"),
    ("paper_layers9", "paper_grid16"),
    ("paper_grid16", "paper_grid20"),
)


def _sig3(x: float) -> float:
    return float(f"{x:.3g}")


def _laws(name: str, form: str) -> dict:
    folder = RESULTS if form == "internal" else RESULTS / form
    return json.loads((folder / f"{name}.json").read_text())["laws"]


@pytest.fixture(scope="module")
def data_file() -> dict:
    return json.loads(LAW_UNCERTAINTY_FILE.read_text())


@pytest.mark.parametrize("form", ["internal", "enthalpy"])
def test_convergence_numbers_are_the_largest_change_over_the_stored_refinements(data_file, form):
    for key in LAW_COEFFICIENTS:
        delta = max(
            abs(float(_laws(fine, form)[key]) - float(_laws(coarse, form)[key]))
            for coarse, fine in REFINEMENTS
        )
        assert data_file[f"convergence_{form}"][key] == _sig3(delta)


@pytest.mark.parametrize("form", ["internal", "enthalpy"])
def test_model_spread_is_half_the_range_over_every_model_of_the_comparison(data_file, form):
    doc = json.loads((RESULTS / f"ispes_compare_{form}.json").read_text())
    assert len(doc) >= 2 and "snap" in doc
    for key in LAW_COEFFICIENTS:
        vals = [m["laws"][key] for m in doc.values() if m["laws"].get(key) is not None]
        assert data_file[f"model_spread_{form}"][key] == _sig3((max(vals) - min(vals)) / 2)


def test_the_numbers_are_the_docs_table(data_file):
    """docs/convergence.md, "Measured law uncertainty of the paper preset": one row per block."""
    text = (ROOT / "docs" / "convergence.md").read_text()
    section = text.split("## Measured law uncertainty of the paper preset", 1)[1]
    rows = {}
    for line in section.splitlines():
        m = re.match(r"\| `(\w+)` \|(.+)\|\s*$", line)
        if m:
            rows[m.group(1)] = [float(c) for c in m.group(2).split("|")]
    assert set(rows) == set(BLOCKS)
    for block in BLOCKS:
        assert rows[block] == [data_file[block][k] for k in LAW_COEFFICIENTS]


def test_the_file_is_an_uncertainty_block_measured_on_the_paper_preset(data_file):
    block = UncertaintyConfig.model_validate(data_file)
    paper = build_config({}, "paper")
    assert block.measured_on == measured_on(paper)
    assert "converted" in data_file["provenance"]
    assert "flatcontact study export-uncertainty" in data_file["provenance"]["regenerate"]
    for f in data_file["provenance"]["result_files"]:
        assert (ROOT / f).is_file(), f
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
