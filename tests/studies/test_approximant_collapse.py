"""Each approximant cell's laws at the paper's experiment (``studies/approximant_collapse``):
the contact stage's number for the same laws, homogeneity in the laws, and the cells that
have no collapse stress say why."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from flatcontact.config.load import build_config, load_config
from flatcontact.contact.parameters import ContactParameters
from flatcontact.contact.tip_comparison import LAW_KEYS
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.reference import PAPER, PAPER_EXPERIMENT_COLLAPSE_MPA
from flatcontact.stages.contact import experiment_comparison
from flatcontact.studies.approximant_collapse import approximant_collapse, cell_collapse

EXAMPLES = Path(__file__).parents[2] / "examples"
STUDIES = sorted(EXAMPLES.glob("passivated-tip-*-approximants.yaml"))
CFG = load_config(EXAMPLES / "passivated-tip-h-diamond-graphene-approximants.yaml")
#: The H-diamond/graphene lock's laws as measured in phase 1 (examples/README.md).
LOCK = {"k_mpa_per_gpa": 151.2, "tau0_mpa": 293.9, "mu_mpa_per_gpa": 47.6, "sigma0_mpa": 92.4}


def _cell(label="zsl-1pct", laws=LOCK, **extra) -> dict:
    return {
        "label": label,
        "n_atoms": 407,
        "twist_deg": 10.893,
        "strain_percent_slab1": 0.0,
        "strain_percent_slab2": 0.683,
        **laws,
        "barrier_mev_per_a2": 1.0,
        "noise_mev_per_a2": 1e-8,
        "resolved": True,
        "gates": {"fired": []},
        **extra,
    }


def test_a_cell_gets_the_contact_stage_number_for_its_laws():
    """The cell's collapse is the contact stage's experiment comparison of a run whose
    fitted laws are the cell's (the stage builds its own parameters from the settings)."""
    row = cell_collapse(_cell(), CFG)
    c = CFG.contact
    params = ContactParameters(
        radius_um=c.radius_um,
        contact_modulus_gpa=c.contact_modulus_gpa,
        shear_modulus_gpa=c.shear_modulus_gpa,
        **LOCK,
    )
    stage = experiment_comparison(CFG, params)["run"]
    assert row["collapse_stress_mpa"] == pytest.approx(stage["collapse_stress_mpa"], rel=1e-12)
    for name, measured in PAPER_EXPERIMENT_COLLAPSE_MPA.items():
        assert row["ratio_to_measured"][name] == pytest.approx(
            row["collapse_stress_mpa"] / measured
        )
    # the lock sits between σ_MSS and τ at the mean pressure 2 p0 / 3 (examples/README.md)
    p_mean = 2 * c.experiment.p0_gpa / 3
    sigma = LOCK["mu_mpa_per_gpa"] * p_mean + LOCK["sigma0_mpa"]
    tau = LOCK["k_mpa_per_gpa"] * p_mean + LOCK["tau0_mpa"]
    assert sigma < row["collapse_stress_mpa"] < tau


@pytest.mark.parametrize("scale", [1e-3, 0.1, 7.0])
def test_the_collapse_is_homogeneous_of_degree_one_in_the_laws(scale):
    """Scaling all four law coefficients by λ scales the Mindlin tractions, the slip
    displacements and so Q at each state of the cycle by λ, while d<Q>/d<u> at corresponding
    states is unchanged: the collapse stress scales by λ (the reason a 1000x smaller τ0 of an
    incommensurate cell means a ~1000x smaller collapse)."""
    base = cell_collapse(_cell(), CFG)["collapse_stress_mpa"]
    scaled = cell_collapse(_cell(laws={k: scale * v for k, v in LOCK.items()}), CFG)
    assert scaled["collapse_stress_mpa"] == pytest.approx(scale * base, rel=2e-3)


def test_cells_without_a_collapse_say_why():
    nan = {k: math.nan for k in LAW_KEYS}
    unresolved = cell_collapse(
        _cell(laws=nan, resolved=False, barrier_mev_per_a2=3e-9, noise_mev_per_a2=2e-9), CFG
    )
    assert unresolved["collapse_stress_mpa"] is None
    assert "not resolved" in unresolved["reason"] and "3e-09" in unresolved["reason"]
    refused = cell_collapse({"label": "zsl-0.1pct", "error": "builder refused"}, CFG)
    assert refused["collapse_stress_mpa"] is None
    assert refused["reason"] == "cell refused: builder refused"
    negative = cell_collapse(_cell(laws={**LOCK, "tau0_mpa": -1.0}), CFG)
    assert negative["collapse_stress_mpa"] is None
    assert negative["reason"].startswith("the contact model refuses the laws: ")
    gated = cell_collapse(_cell(gates={"fired": ["degenerate_minima"]}), CFG)
    assert gated["collapse_stress_mpa"] is not None
    assert gated["reason"] == "gates fired: degenerate_minima"


def test_the_study_rows_carry_the_quartz_laws_and_need_the_experiment():
    doc = {"cells": [_cell("zsl-3pct"), _cell()]}
    out = approximant_collapse(doc, CFG)
    assert [r["label"] for r in out["cells"]] == ["zsl-3pct", "zsl-1pct"]
    assert out["p0_gpa"] == 1.77 and out["measured_mpa"] == dict(PAPER_EXPERIMENT_COLLAPSE_MPA)
    paper = next(r for r in out["references"] if "paper" in r["label"])
    assert paper["tau0_mpa"] == PAPER["tau0_mpa"]
    # the paper's quartz laws through the same model: the paper's own comparison (~26.7 MPa)
    assert 0.5 < paper["ratio_to_measured"]["graphene-passivated SiOx"] < 1.5
    plain = build_config({"contact": {"radius_um": 5.0}})
    with pytest.raises(InputError, match=r"^contact.experiment.compare: not set"):
        approximant_collapse(doc, plain)


@pytest.mark.parametrize("path", STUDIES, ids=lambda p: p.stem)
def test_the_study_examples_are_their_runs_with_an_approximant_ladder(path):
    """Each companion differs from its run example only by the approximants: section, the
    rigid-layers mode, the scan's force tolerance (0.0005 eV/Å: the larger cells' corrugations
    lie below the relaxation floor at the runs' 0.005), the executor, the title and the build
    relaxation (none: an ideal reference keeps the shift lattice): same interface, model, loads,
    contact."""
    run = load_config(path.with_name(path.name.replace("-approximants", ""))).to_dict()
    study = load_config(path).to_dict()
    assert study["approximants"]["max_atoms"] >= 559 and study["scan"]["relax_mode"] == (
        "rigid-layers"
    )
    assert study["structure"].pop("fmax_ev_per_angstrom") == 10.0
    run["structure"].pop("fmax_ev_per_angstrom")
    for key in ("structure", "potential", "analysis", "contact"):
        assert study[key] == run[key], key
    for key in ("grid", "p_range_gpa"):
        assert study["scan"][key] == run["scan"][key]
    assert study["scan"]["fmax_ev_per_angstrom"] == pytest.approx(
        0.1 * run["scan"]["fmax_ev_per_angstrom"]
    )


@pytest.mark.slow
def test_the_h_diamond_study_leaves_the_lock_far_below_it(tmp_path, capsys):
    """``flatcontact study approximants`` on the H-diamond/graphene companion, lock and 1 %
    cell (~6 min on a loaded 2-core machine): the lock's collapse is the contact stage's for
    the phase-1 laws within their spread (rigid-layers against normal: same τ0 within 1 %),
    the 407-atom cell's corrugation is resolved above its noise floor and its collapse is
    orders of magnitude below the lock's; the rows are printed and written."""
    import json

    import yaml
    from tests.cli.cli_helpers import run_cli

    doc = yaml.safe_load(
        (EXAMPLES / "passivated-tip-h-diamond-graphene-approximants.yaml").read_text()
    )
    doc["structure"]["bulk"] = str(EXAMPLES / doc["structure"]["bulk"])
    doc["approximants"]["max_cells"] = 2
    config = tmp_path / "study.yaml"
    config.write_text(yaml.safe_dump(doc))
    code, out, err = run_cli(
        ["study", "approximants", str(config), "--out", str(tmp_path / "s")], capsys
    )
    assert code in (0, None), err
    rows = json.loads((tmp_path / "s" / "experiment_collapse.json").read_text())
    lock, cell = rows["cells"]
    assert (lock["label"], cell["label"]) == ("zsl-3pct", "zsl-1pct")
    assert lock["tau0_mpa"] == pytest.approx(LOCK["tau0_mpa"], rel=0.01)
    assert lock["collapse_stress_mpa"] == pytest.approx(
        cell_collapse(_cell(), CFG)["collapse_stress_mpa"], rel=0.01
    )
    assert cell["resolved"] and cell["barrier_mev_per_a2"] > 10 * cell["noise_mev_per_a2"]
    assert cell["collapse_stress_mpa"] < 1e-2 * lock["collapse_stress_mpa"]
    assert "collapse stress at p0 = 1.77 GPa" in out and "zsl-1pct: 407 atoms" in out
