"""``uncertainty: FILE`` in a run configuration: the block ``flatcontact study
export-uncertainty`` writes (JSON) or a study's ``uncertainty.yaml``, read in place of a pasted
block (a new user on Ni(111) had to paste the exported JSON into the YAML by hand)."""

from __future__ import annotations

import json

import pytest
import yaml
from tests.studies.toy import toy_data, write_yaml

from flatcontact.analysis.uncertainty import LAW_COEFFICIENTS
from flatcontact.config import build_config, load_config
from flatcontact.foundation.errors import InputError
from flatcontact.stages.measured_on import check_measured_on, measured_on


def _block() -> dict:
    cfg = build_config(toy_data(), None, "toy")
    numbers = {k: 0.25 * (i + 1) for i, k in enumerate(LAW_COEFFICIENTS)}
    return {
        "convergence_internal": numbers,
        "model_spread_internal": {k: 2 * v for k, v in numbers.items()},
        "coverage": 2.0,
        "source": "test",
        "measured_on": measured_on(cfg),
        "provenance": {"command": "test"},
    }


@pytest.mark.parametrize("form", ["export json", "study yaml", "study json", "study directory"])
def test_a_file_named_by_uncertainty_is_the_block_it_holds(tmp_path, form):
    """The file, relative to the config file, gives the same configuration as the block
    pasted inline; its measured_on is checked as the inline one's."""
    block = _block()
    (tmp_path / "studies").mkdir()
    if form == "export json":
        (tmp_path / "studies" / "u.json").write_text(json.dumps(block))
        name = "studies/u.json"
    elif form == "study json":  # study.json holds the block beside the study's results
        doc = {"study": "convergence", "variants": [], "uncertainty": block}
        (tmp_path / "studies" / "study.json").write_text(json.dumps(doc))
        name = "studies/study.json"
    else:
        text = "# measured by flatcontact study\n" + yaml.safe_dump({"uncertainty": block})
        (tmp_path / "studies" / "uncertainty.yaml").write_text(text)
        name = "studies/uncertainty.yaml" if form == "study yaml" else "studies"
    (tmp_path / "run").mkdir()
    by_file = load_config(
        write_yaml(tmp_path / "run" / "a.yaml", toy_data(uncertainty=f"../{name}"))
    )
    inline = load_config(write_yaml(tmp_path / "run" / "b.yaml", toy_data(uncertainty=block)))
    assert by_file.to_dict() == inline.to_dict()
    assert by_file.uncertainty.coverage == 2.0
    check_measured_on(by_file)


def test_a_missing_or_empty_uncertainty_file_is_one_line_naming_the_field(tmp_path):
    conf = write_yaml(tmp_path / "a.yaml", toy_data(uncertainty="nope.json"))
    with pytest.raises(InputError) as err:
        load_config(conf)
    text = str(err.value)
    assert "\n" not in text and text.startswith(f"{conf}: uncertainty: file ")
    assert "nope.json not found" in text
    (tmp_path / "empty.json").write_text("[]")
    conf = write_yaml(tmp_path / "b.yaml", toy_data(uncertainty="empty.json"))
    with pytest.raises(InputError, match="holds no uncertainty block"):
        load_config(conf)
