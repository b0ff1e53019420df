"""``flatcontact study models`` when a model cannot be used: a model that cannot compute the
interface is refused in one line before any run (Ni(111) with ``cu-eam`` among the models used to
run the other model for minutes, then end in a KeyError traceback); a model whose run a stage
refuses later is that model's failure, named, and the spread is over the models that ran."""

from __future__ import annotations

import json

import pytest
from tests.studies.toy import EPS_CROSS, toy_config, toy_data, toy_model, write_yaml

from flatcontact.analysis.uncertainty import LAW_COEFFICIENTS
from flatcontact.foundation.errors import InputError
from flatcontact.studies import models as models_module
from flatcontact.studies.output import write_study


def test_a_model_that_lacks_an_element_is_refused_before_any_run(tmp_path):
    """Ni(111) with the EAM for copper among the models: the run's own preflight refuses it,
    naming the entry and the element, before the Ni model's run starts (no run directory)."""
    from flatcontact.config.load import build_config

    data = {
        "structure": {"kind": "fcc111", "element": "Ni", "a_angstrom": 3.52, "layers": 3},
        "potential": {"preset": "ni-eam"},
        "scan": {"grid": [3, 3], "p_range_gpa": {"lo_gpa": 0.0, "hi_gpa": 1.0, "n": 3}},
    }
    data["scan"]["executor"] = "serial"
    data["contact"] = {"contact_modulus_gpa": 200.0, "shear_modulus_gpa": 300.0}
    cfg = build_config(data, None, "ni")
    with pytest.raises(InputError) as err:
        models_module.run_models(cfg, ["cu-eam", "ni-eam"], tmp_path / "s")
    text = str(err.value)
    assert text.startswith("--models cu-eam: ") and "\n" not in text
    assert "['Ni']" in text and "cu-eam" in text
    assert not (tmp_path / "s" / "runs").exists()


@pytest.mark.slow
def test_a_model_refused_by_a_stage_is_named_and_left_out_of_the_spread(tmp_path, monkeypatch):
    """Three models of the toy, the third refused by a stage (a constructed refusal, as a
    builder or analysis refuses in one line): the study goes on, names it in study.json and
    the uncertainty block's source, and the spread is half the range of the two that ran (their
    own laws.json). With one model left the study refuses in one line."""
    real = models_module.run_variant

    def refusing(config, folder, share=None):
        if folder.endswith("c"):
            raise InputError("probe column: p(z) is not monotonic (constructed)")
        return real(config, folder, share)

    monkeypatch.setattr(models_module, "run_variant", refusing)
    specs = []
    for label, eps in (*EPS_CROSS.items(), ("c", 0.03)):
        specs.append(str(write_yaml(tmp_path / f"{label}.yaml", {"potential": toy_model(eps)})))
    cfg = toy_config()
    doc = models_module.run_models(cfg, specs, tmp_path / "s")
    assert doc["failed"] == {"c": "probe column: p(z) is not monotonic (constructed)"}
    assert [v["name"] for v in doc["variants"]] == ["a", "b"]
    laws = {
        m: json.loads((tmp_path / "s" / "runs" / m / "04-laws" / "laws.json").read_text())
        for m in ("a", "b")
    }
    for key in LAW_COEFFICIENTS:
        a, b = laws["a"]["internal"][key], laws["b"]["internal"][key]
        assert doc["spread"]["internal"][key] == pytest.approx(abs(a - b) / 2, rel=1e-12)
    write_study(doc, cfg, tmp_path / "s", "test")
    block = json.loads((tmp_path / "s" / "study.json").read_text())["uncertainty"]
    assert "failed, not in the spread: c" in block["source"]
    with pytest.raises(InputError) as err:
        models_module.run_models(cfg, [specs[0], specs[2]], tmp_path / "s")
    assert "1 of 2 models ran" in str(err.value) and "c: probe column" in str(err.value)
    assert toy_data()["scan"]["executor"] == "serial"  # the refusal ran in this process
