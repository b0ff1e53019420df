"""``flatcontact study models``: the same interface and scan with several interaction models.

Each model replaces the configuration's ``potential`` section whole: a preset name of
:data:`flatcontact.potentials.presets.PRESETS` (``graphene-rebo-kc``), or a YAML file holding a
``potential:`` section (LAMMPS styles as data, an ASE calculator such as a teacher). Every model
is one run directory (:func:`flatcontact.studies.runner.run_variant`), run side by side through
the scan's executor. The spread of each law coefficient is half its max − min range over the
models (:func:`flatcontact.analysis.uncertainty.model_spread`), the ``model_spread_<form>`` of
the ``uncertainty`` block; the per-load spread of τ, σ_MSS and W is reported the same way.
"""

from __future__ import annotations

import math
from pathlib import Path

from pydantic import ValidationError

from flatcontact.analysis.uncertainty import model_spread
from flatcontact.config.load import load_config
from flatcontact.config.messages import one_line
from flatcontact.config.run import RunConfig
from flatcontact.foundation.errors import InputError
from flatcontact.ispes.executors import make_executor
from flatcontact.potentials.presets import PRESETS
from flatcontact.stages.preflight import check_inputs
from flatcontact.studies.convergence import FORMS
from flatcontact.studies.runner import run_jobs, run_variant
from flatcontact.studies.study_dir import RUNS, refuse_study_links, variant_folders
from flatcontact.studies.variants import without_foreign_uncertainty


def model_section(spec: str) -> tuple[str, dict]:
    """(label, ``potential`` mapping) of a ``--models`` entry: a preset name or a YAML file."""
    path = Path(spec)
    if spec in PRESETS:
        return spec, {"preset": spec}
    if path.suffix in (".yaml", ".yml") and path.is_file():
        # a run configuration (or one holding only potential:); its files resolved as a run's
        return path.stem, load_config(path).section("potential")
    raise InputError(
        f"--models: {spec!r}: expected a potential preset ({', '.join(sorted(PRESETS))}) "
        "or a YAML file with a potential: section"
    )


def run_models(cfg: RunConfig, models: list[str], out: str | Path, on_done=None) -> dict:
    """Run ``cfg`` with each of ``models`` into ``out``; returns the ``study.json`` document."""
    models = [m for spec in models for m in spec.split(",") if m]  # --models A,B or repeated
    if len(models) < 2:
        raise InputError(f"--models: expected at least two models, got {len(models)}")
    out = Path(out)
    entries = [model_section(m) for m in models]
    labels = [label for label, _ in entries]
    if len(set(labels)) != len(labels):
        raise InputError(f"--models: a model is given twice ({', '.join(labels)})")
    folders = variant_folders(labels, "--models")
    refuse_study_links(out)
    jobs = []
    for label, section in entries:
        data = {**cfg.to_dict(), "potential": section}
        try:
            variant = without_foreign_uncertainty(RunConfig.model_validate(data))
        except ValidationError as exc:
            raise one_line(exc, f"--models {label}") from None
        check_inputs(variant, f"--models {label}")
        jobs.append((label, variant.to_dict(), str(out / RUNS / folders[label]), None))
    executor = make_executor(
        cfg.scan.executor, cfg.scan.workers, cfg.scan.dask_address, cfg.scan.jobqueue
    )
    try:
        results = run_jobs(executor, run_variant, jobs, on_done)
    finally:
        executor.close()
    failed = {label: results[label]["error"] for label in labels if "error" in results[label]}
    variants = [
        {
            "name": label,
            "setting": "model",
            "level": i,
            "label": label,
            "model": models[i],
            "values": {"model": float(i)},
            **results[label],
        }
        for i, label in enumerate(labels)
        if label not in failed
    ]
    if len(variants) < 2:
        why = "; ".join(f"{k}: {v}" for k, v in failed.items())
        raise InputError(
            f"--models: {len(variants)} of {len(labels)} models ran, a spread needs two ({why})"
        )
    spread = {
        form: model_spread({v["name"]: v["laws"].get(form, {}) for v in variants}) for form in FORMS
    }
    per_load = []
    for j, row in enumerate(variants[0]["loads"]):
        entry = {"p_gpa": row["p_gpa"]}
        for q in ("tau_mpa", "sigma_mss_mpa"):
            vals = [v["loads"][j][q] for v in variants if not math.isnan(v["loads"][j][q])]
            entry[f"{q}_half_range"] = (max(vals) - min(vals)) / 2 if len(vals) >= 2 else math.nan
        per_load.append(entry)
    ws = [v["work_of_separation_j_per_m2"] for v in variants]
    return {
        "study": "models",
        "models": models,
        "failed": failed,
        "variants": variants,
        "spread": spread,
        "per_load_spread": per_load,
        "work_of_separation_half_range_j_per_m2": (max(ws) - min(ws)) / 2,
        "cost": {
            "force_calls_study": sum(v["force_calls_spent"] for v in variants),
            "force_calls_stored": sum(v["force_calls"] for v in variants),
            "variants": len(variants),
            "executor": executor.name,
            "workers": executor.workers,
        },
    }
