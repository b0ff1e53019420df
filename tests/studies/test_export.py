"""``flatcontact study export-uncertainty`` on cheap toy studies: it writes the format of the
quartz data file the paper preset reads; ``--models`` entries that are YAML files with a
``potential:`` section; a variant that fails is reported as its setting's failure."""

from __future__ import annotations

import copy
import json
import math

import pytest
import yaml
from tests.studies.toy import EPS_CROSS, toy_data, toy_model, write_yaml

from flatcontact.analysis.uncertainty import LAW_COEFFICIENTS
from flatcontact.config.load import build_config
from flatcontact.config.presets import LAW_UNCERTAINTY_FILE
from flatcontact.config.uncertainty import UncertaintyConfig
from flatcontact.foundation.errors import InputError
from flatcontact.stages.measured_on import check_measured_on, measured_on
from flatcontact.studies import convergence as convergence_module
from flatcontact.studies.export import merge_studies, read_study


def test_export_of_written_study_blocks_is_the_quartz_file_format(tmp_path):
    """Fast: two study documents with the blocks write_study puts in study.json (numbers
    made up), exported by the command; the file has the quartz data file's fields."""
    from flatcontact.studies.output import uncertainty_block

    cfg = build_config(toy_data(), None, "toy")
    numbers = {k: 0.5 + i for i, k in enumerate(LAW_COEFFICIENTS)}
    conv = {
        "study": "convergence",
        "delta": {"internal": numbers, "enthalpy": {k: 2 * v for k, v in numbers.items()}},
        "settings": {"thicknesses": {}},
        "tolerance_pct": 3.0,
        "converged": True,
        "variants": [{"name": "base"}, {"name": "thicknesses1"}],
    }
    mod = {
        "study": "models",
        "spread": {"internal": numbers, "enthalpy": numbers},
        "models": ["a", "b"],
        "variants": [{"name": "a"}, {"name": "b"}],
    }
    paths = []
    for name, doc in (("conv", conv), ("mod", mod)):
        (tmp_path / name).mkdir()
        doc["uncertainty"] = uncertainty_block(doc, cfg, f"flatcontact study {doc['study']}")
        (tmp_path / name / "study.json").write_text(json.dumps(doc))
        paths.append(tmp_path / name)
    target = tmp_path / "u.json"
    code, _out, err = _cli(["study", "export-uncertainty", *paths, "--out", target])
    assert code == 0, err
    exported = json.loads(target.read_text())
    quartz = json.loads(LAW_UNCERTAINTY_FILE.read_text())
    assert set(exported) == set(quartz)
    assert exported["convergence_enthalpy"] == {
        k: float(f"{2 * v:.3g}") for k, v in numbers.items()
    }
    assert exported["model_spread_internal"] == {k: float(f"{v:.3g}") for k, v in numbers.items()}
    assert exported["measured_on"] == measured_on(cfg)
    UncertaintyConfig.model_validate(exported)
    check_measured_on(build_config(toy_data(uncertainty=exported), None, "t"))


@pytest.fixture(scope="module")
def studies(tmp_path_factory):
    """A one-step thickness refinement and a two-model study of the toy (4 runs, ~25 s each
    on the loaded 2-core machine)."""
    root = tmp_path_factory.mktemp("export")
    conf = write_yaml(
        root / "toy.yaml",
        toy_data(refine={"settings": ["thicknesses"], "max_steps": 1}),
    )
    models = []
    for label, eps in EPS_CROSS.items():
        models.append(write_yaml(root / f"toy-{label}.yaml", {"potential": toy_model(eps)}))
    return root, conf, models


def _cli(argv):
    """Run the CLI in-process, returning (code, stdout, stderr) without a capsys fixture."""
    import contextlib
    import io

    from flatcontact.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            main([str(a) for a in argv])
            code = 0
        except SystemExit as exc:
            code = exc.code
    return code, out.getvalue(), err.getvalue()


@pytest.fixture(scope="module")
def ran(studies):
    root, conf, models = studies
    code, _, err = _cli(["study", "convergence", conf, "--out", root / "conv"])
    assert code == 0, err
    code, out, err = _cli(
        ["study", "models", conf, "--models", ",".join(map(str, models)), "--out", root / "mod"]
    )
    assert code == 0, err
    return root, conf, models, out


@pytest.mark.slow
def test_models_given_as_yaml_files_with_a_potential_section_are_scanned_and_spread(ran):
    root, _, models, _ = ran
    doc = json.loads((root / "mod" / "study.json").read_text())
    assert [v["name"] for v in doc["variants"]] == [m.stem for m in models]
    # each model's laws are its own run's laws.json; the spread is half their range
    laws = {
        m.stem: json.loads((root / "mod" / "runs" / m.stem / "04-laws" / "laws.json").read_text())
        for m in models
    }
    a, b = (laws[m.stem]["internal"] for m in models)
    assert a["tau0_mpa"] != pytest.approx(b["tau0_mpa"], rel=1e-3)  # the models differ
    for key in LAW_COEFFICIENTS:
        assert doc["spread"]["internal"][key] == pytest.approx(abs(a[key] - b[key]) / 2)
    # the second model's calculator kwargs reached its run (its settings say so)
    run_cfg = yaml.safe_load((root / "mod" / "runs" / "toy-b" / "config.yaml").read_text())
    assert run_cfg["potential"]["calculator"]["kwargs"] == {"eps_cross_ev": 0.02}


@pytest.mark.slow
def test_export_writes_the_format_of_the_quartz_data_file(ran):
    root, _conf, _, _ = ran
    target = root / "toy_law_uncertainty.json"
    code, out, err = _cli(
        ["study", "export-uncertainty", root / "conv", root / "mod" / "study.json", "--out", target]
    )
    assert code == 0, err
    exported = json.loads(target.read_text())
    quartz = json.loads(LAW_UNCERTAINTY_FILE.read_text())
    assert set(exported) == set(quartz)  # the same blocks and fields
    assert set(exported["provenance"]) >= {"command", "date"}
    for doc in (exported, quartz):
        UncertaintyConfig.model_validate(doc)
        for block in ("convergence_internal", "model_spread_enthalpy"):
            assert set(doc[block]) == set(LAW_COEFFICIENTS)
    # the numbers are the studies' blocks, the fingerprints the toy's
    conv = yaml.safe_load((root / "conv" / "uncertainty.yaml").read_text())["uncertainty"]
    mod = yaml.safe_load((root / "mod" / "uncertainty.yaml").read_text())["uncertainty"]
    assert exported["convergence_internal"] == conv["convergence_internal"]
    assert exported["model_spread_enthalpy"] == mod["model_spread_enthalpy"]
    cfg = build_config(toy_data(uncertainty=exported), None, "toy")
    assert exported["measured_on"] == measured_on(cfg)
    check_measured_on(cfg)
    assert [s["blocks"] for s in exported["provenance"]["studies"]] == [
        ["convergence_internal", "convergence_enthalpy"],
        ["model_spread_internal", "model_spread_enthalpy"],
    ]
    assert "wrote" in out


@pytest.mark.slow
def test_export_refuses_studies_of_other_interfaces_or_the_same_block_twice(ran, tmp_path):
    root, *_ = ran
    conv = read_study(root / "conv")
    other = copy.deepcopy(read_study(root / "mod"))
    other["uncertainty"]["measured_on"]["structure_sha256"] = "0" * 64
    with pytest.raises(InputError, match="different structures or models"):
        merge_studies({"conv": conv, "other": other})
    with pytest.raises(InputError, match="also measured by conv"):
        merge_studies({"conv": conv, "again": copy.deepcopy(conv)})
    bad = tmp_path / "study.json"
    bad.write_text(json.dumps({"study": "convergence"}))
    code, _, err = _cli(["study", "export-uncertainty", bad, "--out", tmp_path / "u.json"])
    assert code == 2 and err.startswith("error: ") and err.count("\n") == 1
    assert "no uncertainty block" in err and not (tmp_path / "u.json").exists()


def _refuse_variant(monkeypatch, variant: str, message: str) -> None:
    """Make the study's run of ``variant`` raise the one-line InputError a refusing builder
    or analysis raises; every other variant runs for real."""
    real = convergence_module.run_variant

    def refusing(config, folder, share=None):
        if folder.endswith(variant):
            raise InputError(message)
        return real(config, folder, share)

    monkeypatch.setattr(convergence_module, "run_variant", refusing)


def _two_step_study(tmp_path, setting: str) -> tuple[dict, str]:
    """The toy's convergence study of one ``setting``, two steps at a 0.01 % tolerance (so the
    second step runs); its study.json and the console text."""
    conf = write_yaml(
        tmp_path / "toy.yaml",
        toy_data(refine={"settings": [setting], "max_steps": 2, "tolerance_pct": 0.01}),
    )
    code, out, err = _cli(["study", "convergence", conf, "--out", tmp_path / "s"])
    assert code == 0, err
    return json.loads((tmp_path / "s" / "study.json").read_text()), out


@pytest.mark.slow
def test_a_variant_that_fails_is_reported_as_its_settings_failure(tmp_path, monkeypatch):
    """A constructed failure: the layers step's run raises the one-line InputError a refusing
    builder raises. The study goes on, study.json and the console name the failure, and the
    other setting's verdict and δ_conv stand."""
    _refuse_variant(monkeypatch, "layers1", "probe column: p(z) is not monotonic (constructed)")
    conf = write_yaml(
        tmp_path / "toy.yaml",
        toy_data(refine={"settings": ["thicknesses", "layers"], "max_steps": 1}),
    )
    code, out, err = _cli(["study", "convergence", conf, "--out", tmp_path / "s"])
    assert code == 0, err
    doc = json.loads((tmp_path / "s" / "study.json").read_text())
    assert doc["settings"]["layers"]["state"] == "failed"
    assert doc["failed"] == {"layers": "probe column: p(z) is not monotonic (constructed)"}
    assert doc["settings"]["thicknesses"]["state"] in ("converged", "not converged")
    assert [v["name"] for v in doc["variants"]] == ["base", "thicknesses1"]
    assert doc["converged"] is False
    text = " ".join(out.split())
    assert "layers1: failed: probe column" in text
    assert "layers: failed at step 1: probe column" in text
    # δ_conv comes from the setting that ran
    by = {v["name"]: v for v in doc["variants"]}
    for key in LAW_COEFFICIENTS:
        a = by["base"]["laws"]["internal"][key]
        b = by["thicknesses1"]["laws"]["internal"][key]
        assert doc["delta"]["internal"][key] == pytest.approx(abs(b - a))


@pytest.mark.slow
def test_a_setting_whose_finer_step_fails_keeps_its_measured_step_in_delta(tmp_path, monkeypatch):
    """The quartz thicknesses ladder: 19 → 29 thicknesses moved τ by more than the tolerance,
    29 → 43 was refused by the analysis. The refused step must not erase the measured one:
    δ_conv is the change of the last analysable step (it was dropped, understating the
    interval), the setting stays ``failed`` with the refused step named."""
    _refuse_variant(monkeypatch, "thicknesses2", "the load folds (constructed)")
    doc, out = _two_step_study(tmp_path, "thicknesses")
    st = doc["settings"]["thicknesses"]
    assert st["state"] == "failed"
    assert st["last_step"] == ["base", "thicknesses1"]
    assert st["failed_step"] == ["thicknesses1", "thicknesses2"]
    by = {v["name"]: v for v in doc["variants"]}
    assert set(by) == {"base", "thicknesses1"}
    moved = 0.0
    for key in LAW_COEFFICIENTS:
        a = by["base"]["laws"]["internal"][key]
        b = by["thicknesses1"]["laws"]["internal"][key]
        assert doc["delta"]["internal"][key] == pytest.approx(abs(b - a))
        moved = max(moved, abs(b - a))
    assert moved > 0.0  # the step moved the laws: the test would see it dropped
    source = yaml.safe_load((tmp_path / "s" / "uncertainty.yaml").read_text())["uncertainty"][
        "source"
    ]
    assert "thicknesses (step thicknesses1; the next failed)" in source
    assert "NOT converged: thicknesses (failed)" in source
    assert "thicknesses: failed at step 2" in " ".join(out.split())


@pytest.mark.slow
def test_delta_is_the_bases_error_the_whole_ladders_movement(tmp_path):
    """A two-step grid ladder that does not converge: δ_conv is |c(grid2) − c(base)|, the
    error of a run at the base settings (where the block is applied), not the last step's
    |c(grid2) − c(grid1)| (the finest level's error)."""
    doc, _out = _two_step_study(tmp_path, "grid")
    st = doc["settings"]["grid"]
    assert st["steps"] == 2 and st["last_step"] == ["grid1", "grid2"]
    assert st["measured_step"] == ["base", "grid2"]
    laws = {v["name"]: v["laws"]["internal"] for v in doc["variants"]}
    differs = False
    for key in LAW_COEFFICIENTS:
        whole = abs(laws["grid2"][key] - laws["base"][key])
        last = abs(laws["grid2"][key] - laws["grid1"][key])
        assert doc["delta"]["internal"][key] == pytest.approx(whole)
        differs |= not math.isclose(whole, last, rel_tol=1e-6, abs_tol=1e-12)
    assert differs  # otherwise the test could not tell the rules apart


def test_counts_in_delta_states():
    """Which settings' last step enters δ_conv, by state (studies.compare.counts_in_delta)."""
    from flatcontact.studies.compare import counts_in_delta

    assert counts_in_delta({"state": "converged", "last_change": {}})
    assert counts_in_delta({"state": "not converged", "last_change": {}})
    assert not counts_in_delta({"state": "not refined", "last_change": {}})
    assert not counts_in_delta({"state": "failed"})  # failed at its first step
    assert counts_in_delta({"state": "failed", "last_change": {}, "last_step": ["a", "b"]})


def test_a_variant_that_crashes_is_its_own_failure_not_the_studys():
    """studies.runner.run_jobs: an engine error in one job (LAMMPS raises a plain Exception)
    is that job's result; the other jobs' results stand; an InputError keeps its message."""
    from flatcontact.ispes.executors import make_executor
    from flatcontact.studies.runner import run_jobs

    def task(x):
        if x == 1:
            raise Exception("ERROR on proc 0: Neighbor list overflow, boost neigh_modify one\nmore")
        if x == 2:
            raise InputError("refused (constructed)")
        return {"value": 10 * x}

    told = []
    executor = make_executor("serial", 1, None, None)
    out = run_jobs(
        executor, task, [("a", 0), ("b", 1), ("c", 2), ("d", 3)], lambda k, r: told.append(k)
    )
    assert out["a"] == {"value": 0} and out["d"] == {"value": 30}
    assert out["b"] == {
        "error": "Exception: ERROR on proc 0: Neighbor list overflow, boost neigh_modify one",
        "unexpected": True,
    }
    assert out["c"] == {"error": "refused (constructed)"}
    assert told == ["a", "b", "c", "d"]


def test_noise_ratio_is_the_median_of_the_per_load_noise_ratios():
    """studies.compare.noise_ratio: fine over coarse energy noise, median over common loads;
    loads missing in one variant, NaN or zero coarse noise are left out."""
    from flatcontact.studies.compare import NOISIER_FACTOR, noise_ratio

    def loads(noise):
        return {
            "loads": [
                {"p_gpa": p, "energy_noise_mev_per_a2": n}
                for p, n in zip((0.0, 1.0, 2.0, 3.0), noise, strict=True)
            ]
        }

    # the quartz 9 -> 12 layer step at fmax 0.005 (friction.csv at 1, 2, 3 GPa): ~5x
    coarse = loads([4.53, 0.00993, 0.0151, 0.0199])
    fine = loads([0.000755, 0.0496, 0.0795, 0.105])
    # four ratios (one < 1 at 0 GPa, where the 9-layer noise estimate is large): the middle two
    assert noise_ratio(coarse, fine) == pytest.approx((0.0496 / 0.00993 + 0.0795 / 0.0151) / 2)
    assert noise_ratio(coarse, fine) >= NOISIER_FACTOR
    assert noise_ratio(fine, coarse) < 1.0
    gaps = loads([math.nan, 0.0, 0.01, 0.02])
    assert noise_ratio(gaps, loads([1.0, 1.0, 0.02, 0.02])) == pytest.approx(1.5)
    assert math.isnan(noise_ratio(loads([math.nan] * 4), fine))


def _convergence_doc(settings: dict) -> dict:
    """A convergence study document with made-up numbers and the given ``settings`` (not all
    converged), as write_study passes it to uncertainty_block."""
    numbers = {k: 1.0 for k in LAW_COEFFICIENTS}
    return {
        "study": "convergence",
        "delta": {"internal": numbers, "enthalpy": numbers},
        "settings": settings,
        "tolerance_pct": 3.0,
        "converged": False,
        "variants": [{"name": "base"}],
    }


def test_the_blocks_source_says_which_step_was_noisier():
    from flatcontact.studies.output import uncertainty_block

    doc = _convergence_doc(
        {
            "grid": {"state": "converged", "last_change": {}},
            "layers": {"state": "not converged", "last_change": {}, "noisier": 5.27},
        }
    )
    source = uncertainty_block(doc, build_config(toy_data(), None, "toy"), "t")["source"]
    assert (
        "layers (its finest variant 5.27x noisier than the base: may be relaxation error)" in source
    )


def test_the_blocks_source_names_each_setting_that_did_not_converge():
    """The source line of a convergence study's block names every setting that is not
    converged with its state, and the refinement steps δ_conv was taken over are only those of
    the settings that neither failed nor did not refine (it said 'NOT all converged: see
    study.json' and listed every setting)."""
    from flatcontact.studies.output import uncertainty_block

    cfg = build_config(toy_data(), None, "toy")
    doc = _convergence_doc(
        {
            "grid": {"state": "converged"},
            "thicknesses": {"state": "not refined"},
            "layers": {"state": "failed"},
            "fmax": {"state": "not converged"},
        }
    )
    source = uncertainty_block(doc, cfg, "t")["source"]
    assert "the finest analysable level of grid, fmax (" in source
    assert (
        "NOT converged: thicknesses (not refined), layers (failed), fmax (not converged)" in source
    )
    doc["settings"] = {"grid": {"state": "converged"}}
    doc["converged"] = True
    assert "of grid (tolerance 3 %; all converged)" in uncertainty_block(doc, cfg, "t")["source"]


def test_the_cost_line_compares_stored_force_calls_with_the_ladders_from_scratch():
    """Ni(111) after --estimate: the study printed 'force calls: 2461 (each setting from
    scratch: 4485)', this invocation's calls (the base, run by --estimate, left out) against
    ladders that count the base once per setting. The line compares the stored calls (what
    the study cost) with the ladders from scratch, and says what this invocation computed."""
    from flatcontact.studies.output import cost_line

    base, variants = 506, [912, 484, 545, 520]
    stored = base + sum(variants)
    cost = {
        "force_calls_study": sum(variants),
        "force_calls_stored": stored,
        "force_calls_from_scratch": stored + 3 * base,
        "variants": 5,
    }
    line = cost_line(cost)
    assert line.startswith(f"force calls: {stored} in 5 runs against {stored + 3 * base} ")
    assert f"{sum(variants)} computed by this invocation" in line
    assert "invocation" not in cost_line({**cost, "force_calls_study": stored})
