"""``flatcontact study convergence``: refine one setting at a time until τ and σ_MSS stop moving.

Rounds: round 0 runs the base (the configuration as given); round ``i`` runs, side by side
through the scan's executor (``scan.executor``/``scan.workers``: local processes or Dask),
level ``i`` of every setting still open (:func:`flatcontact.studies.variants.step`). After
each round a setting whose step moved every per-load τ and σ_MSS by less than
``refine.tolerance_pct`` (:func:`flatcontact.studies.compare.largest_change`) is
``converged`` at its previous level; one still moving after ``refine.max_steps`` steps is
``not converged`` within the budget, and the study says so (``study.json``, the console). A
thicknesses step whose scan is not more finely spaced than the previous one
(:func:`flatcontact.studies.compare.thickness_step_refines`) is ``not refined``, with the
reason: its change says nothing about convergence and stays out of δ_conv.

The uncertainty it measures, per energy form and law coefficient c, is the error of a run at
the base settings (the runs the ``uncertainty`` block is applied to):
``δ_conv(c) = max over settings of |c(finest) − c(base)|``, the total movement of the laws
from the base to each setting's finest analysable level (``settings.<s>.measured_step``); for
a converged setting that is the base's error to the tolerance, for one not converged a lower
bound. With one step per setting it is the one step's change, the rule of
docs/convergence.md; with more it is not the last step's change, which measures the finest
level's error, not the base's (the quartz fmax ladder: 6.65 then 2.64 MPa/GPa in the
internal k). Over the settings neither failed at their first step nor not refined; a setting
whose finer step failed counts with its last analysable level (:func:`counts_in_delta`). A
setting whose finest variant's landscape is ``NOISIER_FACTOR`` times noisier than the base's
(:func:`flatcontact.studies.compare.noise_ratio`) is flagged ``noisier`` (its change may be
relaxation error: refine with a tighter force tolerance); it still counts in δ_conv.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

from flatcontact.analysis.uncertainty import LAW_COEFFICIENTS
from flatcontact.config.run import RunConfig
from flatcontact.foundation.errors import InputError
from flatcontact.ispes.executors import make_executor
from flatcontact.studies.compare import (
    NOISIER_FACTOR,
    counts_in_delta,
    largest_change,
    law_changes,
    noise_ratio,
    thickness_step_refines,
)
from flatcontact.studies.estimate import (
    base_measurements,
    cutoff_call_ratios,
    estimate_convergence,
)
from flatcontact.studies.runner import run_jobs, run_variant
from flatcontact.studies.study_dir import RUNS, refuse_study_links
from flatcontact.studies.variants import (
    base_value,
    chosen_settings,
    shares_build,
    step,
    variant_config,
)

FORMS = ("internal", "enthalpy")


def run_convergence(
    cfg: RunConfig,
    out: str | Path,
    on_done: Callable[[str, dict], None] | None = None,
    on_estimate: Callable[[dict], None] | None = None,
    estimate_only: bool = False,
) -> dict:
    """Run the convergence study of ``cfg`` into ``out``; returns the ``study.json`` document.

    ``on_done(name, result)`` is told when each variant finishes (the CLI prints a line);
    ``on_estimate(estimate)`` once the base has run, with the cost of every rung extrapolated
    from it (:func:`flatcontact.studies.estimate.estimate_convergence`). With
    ``estimate_only`` the study stops there and returns ``{"study": "estimate", **estimate}``
    (the base run stays, shared with the study that follows).
    """
    out = Path(out)
    settings, skipped = chosen_settings(cfg)
    r = cfg.refine
    # every variant's configuration first: a bad step is refused before any work
    ladder = {s: [step(cfg, s, i) for i in range(1, r.max_steps + 1)] for s in settings}
    configs = {
        v.name: variant_config(cfg, v.overrides, f"refine ({v.label})").to_dict()
        for steps in ladder.values()
        for v in steps
    }
    refuse_study_links(out)
    runs_dir = out / RUNS
    base_dir = runs_dir / "base"
    executor = make_executor(
        cfg.scan.executor, cfg.scan.workers, cfg.scan.dask_address, cfg.scan.jobqueue
    )
    try:
        results = run_jobs(
            executor, run_variant, [("base", cfg.to_dict(), str(base_dir), None)], on_done
        )
        if "error" in results["base"]:
            raise InputError(f"the base configuration failed: {results['base']['error']}")
        estimate = estimate_convergence(
            cfg,
            ladder,
            base_measurements(base_dir),
            executor.workers,
            cutoff_call_ratios(cfg, ladder, configs),
        )
        if on_estimate is not None:
            on_estimate(estimate)
        if estimate_only:
            return {"study": "estimate", **estimate}
        status = {s: {"state": "open", "steps": 0} for s in settings}
        previous = {s: "base" for s in settings}
        for level in range(1, r.max_steps + 1):
            open_ = [s for s in settings if status[s]["state"] == "open"]
            if not open_:
                break
            jobs = []
            for s in open_:
                v = ladder[s][level - 1]
                share = str(base_dir) if shares_build(s) else None
                jobs.append((v.name, configs[v.name], str(runs_dir / v.name), share))
            results.update(run_jobs(executor, run_variant, jobs, on_done))
            for s in open_:
                v = ladder[s][level - 1]
                status[s]["steps"] = level
                _judge_step(status[s], s, v, results, previous[s], level, r)
                if status[s]["state"] != "failed":  # a failed step is no setting's previous
                    previous[s] = v.name
    finally:
        executor.close()
    return _study_document(cfg, settings, skipped, ladder, status, results, estimate, executor)


def _judge_step(st: dict, s: str, v, results: dict, previous: str, level: int, r) -> None:
    """Update the status ``st`` of setting ``s`` with its step ``v`` (level ``level``) against
    the ``previous`` variant: failed, converged, not refined (a thickness step that refines
    nothing), not converged (the last step) or still open; the largest law change measured."""
    if "error" in results[v.name] or "error" in results[previous]:
        failed = results[v.name].get("error") or results[previous].get("error")
        # an earlier analysable step (in last_step/last_change) stays this
        # setting's measured change: a refused finer step does not erase it
        st.update(state="failed", error=failed, failed_step=[previous, v.name])
        return
    change = largest_change(results[previous], results[v.name], r.tolerance_floor_mpa)
    st["last_change"] = change
    st["last_step"] = [previous, v.name]
    # the base's error is what the block carries: the total movement of the
    # laws from the base to this (the finest analysable) level
    st["measured_step"] = ["base", v.name]
    ratio = noise_ratio(results["base"], results[v.name])
    if ratio >= NOISIER_FACTOR:
        # counted all the same (an over-estimate, not an erasure), but said
        st["noisier"] = round(ratio, 2)
    else:
        st.pop("noisier", None)
    why = (
        thickness_step_refines(results[previous], results[v.name], v.name, previous)
        if s == "thicknesses"
        else None
    )
    if why is not None:
        st.update(state="not refined", reason=why)
    elif change["max_pct"] < r.tolerance_pct:
        st["state"] = "converged"
        st["converged_at"] = previous
    elif level == r.max_steps:
        st["state"] = "not converged"


def _study_document(
    cfg: RunConfig,
    settings: list[str],
    skipped,
    ladder: dict,
    status: dict,
    results: dict,
    estimate: dict,
    executor,
) -> dict:
    """The ``study.json`` document: every variant that ran, each setting's status, the largest
    law change per energy form (``delta``, the convergence error the laws carry) and the cost."""
    r = cfg.refine
    variants = [
        {
            "name": "base",
            "setting": "base",
            "level": 0,
            "label": "base",
            "values": {s: base_value(cfg, s) for s in settings},
            "overrides": {},
            **results["base"],
        }
    ]
    if "error" in results["base"]:
        raise InputError(f"the base configuration failed: {results['base']['error']}")
    for s in settings:
        for v in ladder[s][: status[s]["steps"]]:
            if "error" in results[v.name]:
                continue
            variants.append(
                {
                    "name": v.name,
                    "setting": s,
                    "level": v.level,
                    "label": v.label,
                    "values": {s: v.value},
                    "overrides": v.overrides,
                    **results[v.name],
                }
            )
    delta = {
        form: {
            key: max(
                (
                    law_changes(
                        results[status[s]["measured_step"][0]],
                        results[status[s]["measured_step"][1]],
                        form,
                    )[key]
                    for s in settings
                    if counts_in_delta(status[s])
                ),
                default=0.0,
            )
            for key in LAW_COEFFICIENTS
        }
        for form in FORMS
    }
    spent = sum(v["force_calls_spent"] for v in variants)
    stored = sum(v["force_calls"] for v in variants)
    base_calls = results["base"]["force_calls"]
    # each setting's ladder run on its own from scratch: its own base and builds
    scratch = stored + base_calls * (len(settings) - 1) if settings else stored
    return {
        "study": "convergence",
        "tolerance_pct": r.tolerance_pct,
        "tolerance_floor_mpa": r.tolerance_floor_mpa,
        "max_steps": r.max_steps,
        "settings": {s: {**status[s], "base_value": base_value(cfg, s)} for s in settings},
        "skipped_settings": skipped,
        "converged": all(status[s]["state"] == "converged" for s in settings),
        "failed": {s: status[s]["error"] for s in settings if status[s]["state"] == "failed"},
        "variants": variants,
        "delta": {
            f: {k: (0.0 if math.isnan(v) else v) for k, v in d.items()} for f, d in delta.items()
        },
        "estimate": estimate,
        "cost": {
            "force_calls_study": spent,
            "force_calls_stored": stored,
            "force_calls_from_scratch": scratch,
            "variants": len(variants),
            "executor": executor.name,
            "workers": executor.workers,
        },
    }
