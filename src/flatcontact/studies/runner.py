"""One variant of a study: an ordinary run directory through build, scan, analyze and laws.

:func:`run_variant` is a module-level function of plain arguments, so an executor of
:mod:`flatcontact.ispes.executors` (local processes, Dask) can run variants side by side. It
runs :class:`flatcontact.pipeline.Pipeline` (the stages' own functions and fingerprints), so a
rerun of the study skips every finished stage, and returns per load τ and σ_MSS (MPa), the
work of separation W (J/m²), the laws of both energy forms, and the force calls the scan
stored with the scan stage's action (``ran``, ``resumed`` or ``skipped``).

Sharing: a variant whose structure and model equal the base's (:func:`flatcontact.studies.
variants.shares_build`) starts from a copy of the base's finished build stage; the run
directory's fingerprint check accepts it as done (identical inputs), so the interface is
built and relaxed once per study.
"""

from __future__ import annotations

import math
import shutil
import time
from collections.abc import Callable
from pathlib import Path

import pandas as pd

from flatcontact.config.run import RunConfig
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import refuse_link
from flatcontact.foundation.layout import FRICTION_CSV, RUN_MARKER, STAGES
from flatcontact.pipeline import Pipeline


def _copy_build(source: Path, target: Path) -> None:
    """Copy the finished build stage folder of run ``source`` into run ``target`` (if absent)."""
    name = f"{STAGES['build']:02d}-build"
    src, dst = source / name, target / name
    if src.is_dir() and not dst.exists():
        target.mkdir(parents=True, exist_ok=True)
        shutil.copy2(source / RUN_MARKER, target / RUN_MARKER)  # a run directory, not a stray
        shutil.copytree(src, dst)


def run_variant(config: dict, folder: str, share_build_from: str | None = None) -> dict:
    """Run one variant (``config``: a validated configuration's ``to_dict()``) in ``folder``.

    The variant's own scan runs serially: the variants are the parallel units.

    Returns
    -------
    dict
        ``loads`` (``p_gpa``, ``tau_mpa``, ``sigma_mss_mpa``; NaN where the load is not
        reached; ``energy_noise_mev_per_a2``, the analysis's own estimate of the landscape's
        relaxation noise at that load), ``laws`` (energy form -> coefficients and standard errors),
        ``work_of_separation_j_per_m2``, ``thickness_angstrom`` (the scan's, Å),
        ``force_calls`` (stored by the scan),
        ``force_calls_spent`` (0 when the scan stage was skipped), ``scan_action``,
        ``seconds``.
    """
    cfg = RunConfig.model_validate(config)
    cfg = cfg.model_copy(
        update={"scan": cfg.scan.model_copy(update={"executor": "serial", "workers": 1})}
    )
    root = Path(folder)
    refuse_link(root, "a study's variant folder")  # planted after the study's own check
    if share_build_from is not None:
        _copy_build(Path(share_build_from), root)
    t0 = time.perf_counter()
    with Pipeline(cfg, root) as pipe:
        laws = pipe.laws()
        scan = pipe.scan_summary()
        action = pipe.results["scan"].action
        table = pd.read_csv(pipe.folder("analyze") / FRICTION_CSV)
    loads = [
        {
            "p_gpa": float(row["p_gpa"]),
            "tau_mpa": float(row["tau_mpa"]),
            "sigma_mss_mpa": float(row["sigma_mss_mpa"]),
            "energy_noise_mev_per_a2": float(row.get("energy_noise_mev_per_a2", math.nan)),
        }
        for _, row in table.iterrows()
    ]
    forms = {f: laws[f] for f in ("internal", "enthalpy") if isinstance(laws.get(f), dict)}
    adhesion = scan.get("adhesion") or {}
    w = adhesion.get("work_of_separation_j_per_m2")
    calls = int(scan.get("force_calls_total") or 0)
    return {
        "folder": str(root),
        "loads": loads,
        "laws": {
            form: {k: v for k, v in block.items() if not isinstance(v, (dict, list))}
            for form, block in forms.items()
        },
        "energy_form": laws.get("energy_form"),
        "work_of_separation_j_per_m2": float(w) if w is not None else math.nan,
        "thickness_angstrom": [float(z) for z in scan.get("thickness_angstrom") or []],
        "force_calls": calls,
        "force_calls_spent": 0 if action == "skipped" else calls,
        "scan_action": action,
        "seconds": time.perf_counter() - t0,
    }


def run_jobs(executor, task: Callable, jobs: list[tuple], on_done: Callable | None = None) -> dict:
    """Run ``jobs`` = [(key, *arguments of task)] through ``executor``; ``{key: result}``.

    A job that ``task`` refuses (:class:`~flatcontact.foundation.errors.InputError`: a variant or cell the
    builder, model or analysis refuses) gives ``{"error": message}`` and the others go on; a
    job that fails otherwise (an engine error, a defect) gives ``{"error": "Type: first
    line", "unexpected": True}``: one variant must not take hours of the others' results
    down with it (the quartz study's 26 Å cutoff variant did, with LAMMPS's neighbour list
    overflow). ``KeyboardInterrupt`` still stops the study.
    ``on_done(key, result)`` is told as each job ends; a serial executor runs a job when it is
    submitted, so there the jobs are submitted one at a time and each is told as it ends.
    """
    if executor.workers == 1 and len(jobs) > 1:
        out: dict = {}
        for job in jobs:
            out.update(run_jobs(executor, task, [job], on_done))
        return out
    handles = {executor.submit(task, *args): key for key, *args in jobs}
    out = {}
    pending = set(handles)
    while pending:
        done, pending = executor.wait_first(pending)
        for h in done:
            try:
                out[handles[h]] = executor.result(h)
            except InputError as exc:
                out[handles[h]] = {"error": str(exc)}
            except Exception as exc:
                # an engine error (LAMMPS: "Neighbor list overflow") or a defect in one
                # variant: the others' results stand and the study is written; the
                # variant's own run.log has the traceback
                first = (str(exc).strip().splitlines() or [""])[0]
                out[handles[h]] = {"error": f"{type(exc).__name__}: {first}", "unexpected": True}
            if on_done is not None:
                on_done(handles[h], out[handles[h]])
    return out
