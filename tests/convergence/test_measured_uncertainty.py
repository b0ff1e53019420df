"""The paper preset's measured law uncertainty is what the stored benchmark results give."""

from pathlib import Path

import pytest
from benchmarks.convergence.uncertainty import measured_uncertainty

from flatcontact.config import MEASURED_LAW_UNCERTAINTY

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "benchmarks" / "convergence" / "results"
pytestmark = pytest.mark.skipif(
    not (RESULTS / "ispes_compare_internal.json").is_file(), reason="benchmark results not present"
)


@pytest.fixture(scope="module")
def measured():
    return measured_uncertainty()


@pytest.mark.parametrize(
    "block",
    [
        "convergence_internal",
        "convergence_enthalpy",
        "model_spread_internal",
        "model_spread_enthalpy",
    ],
)
def test_config_numbers_are_the_results_files(measured, block):
    assert MEASURED_LAW_UNCERTAINTY[block] == pytest.approx(measured[block], rel=1e-9)


def test_model_spread_is_over_every_model_of_the_comparison(measured):
    import json

    from flatcontact.analysis.uncertainty import LAW_COEFFICIENTS

    for form in ("internal", "enthalpy"):
        doc = json.loads((RESULTS / f"ispes_compare_{form}.json").read_text())
        assert len(doc) >= 2 and "snap" in doc
        for key in LAW_COEFFICIENTS:
            vals = [m["laws"][key] for m in doc.values() if m["laws"].get(key) is not None]
            assert measured[f"model_spread_{form}"][key] == pytest.approx(
                (max(vals) - min(vals)) / 2, rel=5e-3
            )
