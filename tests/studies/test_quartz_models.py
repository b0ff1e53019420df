"""examples/quartz-models.yaml and the four model files of the quartz model spread: the paper
preset's interface at the legacy 4x4 grid, each model the paper's LJ across with another model
inside the slabs, and the preset's measured block kept only where it was measured."""

from __future__ import annotations

from pathlib import Path

import pytest

from flatcontact.config.load import build_config, load_config
from flatcontact.config.run import RunConfig
from flatcontact.stages.measured_on import check_measured_on
from flatcontact.studies.models import model_section
from flatcontact.studies.variants import step, variant_config, without_foreign_uncertainty

EXAMPLES = Path(__file__).parents[2] / "examples"
MODELS = ["sio2-snap", "sio2-snap-mf0", "chgnet-r2scan", "sevennet-mf-0-r2scan"]


def test_the_models_example_is_the_paper_preset_at_the_legacy_grid():
    cfg = load_config(EXAMPLES / "quartz-models.yaml").to_dict()
    paper = build_config({}, "paper").to_dict()
    assert cfg["scan"]["grid"] == [4, 4]
    cfg["scan"]["grid"] = paper["scan"]["grid"]
    assert cfg == paper


@pytest.mark.parametrize("name", MODELS)
def test_each_model_keeps_the_paper_lj_and_only_the_bundled_snap_keeps_the_block(name):
    cfg = load_config(EXAMPLES / "quartz-models.yaml")
    assert cfg.uncertainty.measured_on  # the paper preset's quartz block
    label, section = model_section(str(EXAMPLES / "data" / "quartz-models" / f"{name}.yaml"))
    assert label == name
    variant = without_foreign_uncertainty(
        RunConfig.model_validate({**cfg.to_dict(), "potential": section})
    )
    assert variant.potential.lj == cfg.potential.lj
    assert variant.potential.lj.cutoff_angstrom == 18.0
    check_measured_on(variant, name)  # no model is refused in preflight any more
    if name == "sio2-snap":
        assert variant.uncertainty == cfg.uncertainty  # the model the block was measured on
    else:
        assert not variant.uncertainty.measured_on


def test_quartz_convergence_layers_and_cutoff_rungs_run_without_the_preset_block():
    cfg = load_config(EXAMPLES / "quartz-convergence.yaml")
    for setting, keeps in (
        ("grid", True),
        ("thicknesses", True),
        ("layers", False),
        ("cutoff", False),
    ):
        v = step(cfg, setting, 1)
        variant = variant_config(cfg, v.overrides, v.name)
        check_measured_on(variant, v.name)
        assert bool(variant.uncertainty.measured_on) is keeps, setting
        if keeps:  # the scan rungs' configuration is the base's but for the step
            assert variant.uncertainty == cfg.uncertainty
