"""Convergence study of the SiO₂ ISPES laws (issue 12): one refinement of each setting alone.

Usage (from the repository root, one variant at a time, in the background on a shared machine)::

    python -m benchmarks.convergence.study run ref grid16 ...   # scans + analysis -> results/<name>.json
    python -m benchmarks.convergence.study table                # results/convergence.{csv,md}

Every variant is the ``paper`` preset of :func:`flatcontact.config.preset` with ONE change
(:data:`VARIANTS`), run through :class:`flatcontact.pipeline.Pipeline` (build, scan,
analyze, laws) into ``$FLATCONTACT_CONVERGENCE_RUNS/<name>`` (default
``/tmp/flatcontact-convergence``). The result file keeps per load τ, σ_MSS, G_int, the
path facts (what limits τ, jumps, where τ is reached), the load noise, the work of
separation W, the fitted laws with standard errors and the wall time of each stage.
The comparison (:func:`flatcontact.analysis.convergence.compare_runs`) is done by ``table``.
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
RUNS = Path(os.environ.get("FLATCONTACT_CONVERGENCE_RUNS", "/tmp/flatcontact-convergence"))

#: name -> (setting varied, what, config overrides laid over the paper preset)
VARIANTS: dict[str, tuple[str, str, dict]] = {
    "ref": ("reference", "paper preset: 12x12, 20 thicknesses, fmax 0.005, 6 layers, LJ 10 Å", {}),
    "grid8": ("lateral grid", "8x8 (one step coarser)", {"scan": {"grid": [8, 8]}}),
    "grid16": ("lateral grid", "16x16", {"scan": {"grid": [16, 16]}}),
    "thick30": (
        "thicknesses",
        "30 thicknesses over the same load range (spacing x2/3)",
        {"scan": {"p_range_gpa": {"lo_gpa": -0.3, "hi_gpa": 5.5, "n": 30}}},
    ),
    "thick12": (
        "thicknesses",
        "12 thicknesses over the same load range (one step coarser)",
        {"scan": {"p_range_gpa": {"lo_gpa": -0.3, "hi_gpa": 5.5, "n": 12}}},
    ),
    "fmax0025": ("force tolerance", "fmax 0.0025 eV/Å", {"scan": {"fmax_ev_per_angstrom": 0.0025}}),
    "fmax01": (
        "force tolerance",
        "fmax 0.01 eV/Å (one step looser)",
        {"scan": {"fmax_ev_per_angstrom": 0.01}},
    ),
    "cutoff14": (
        "LJ cutoff",
        "cross-interface LJ cutoff 14 Å",
        {"potential": {"lj": {"cutoff_angstrom": 14.0}}},
    ),
    "layers9": (
        "slab layers",
        "9 O-Si-O layers per slab (shipped 6-layer slab + one bulk cell, SNAP-relaxed)",
        {"structure": {"kind": "file", "file": str(HERE / "interface_9L.extxyz")}},
    ),
}


def config_for(name: str):
    """The validated run configuration of variant ``name`` (paper preset + its overrides)."""
    from flatcontact.config import build_config, merge_config

    overrides = merge_config({"scan": {"workers": 1, "executor": "serial"}}, VARIANTS[name][2])
    return build_config(overrides, "paper", f"variant {name}")


def run_variant(name: str) -> dict:
    """Run variant ``name`` (resuming its run directory) and write ``results/<name>.json``."""
    import pandas as pd

    from flatcontact.pipeline import Pipeline

    cfg = config_for(name)
    timings = {}
    with Pipeline(cfg, RUNS / name) as pipe:
        for stage in ("build", "scan", "analyze", "laws"):
            t0 = time.perf_counter()
            getattr(pipe, stage)()
            timings[stage] = time.perf_counter() - t0
        table: pd.DataFrame = pipe.friction_table()
        laws = pipe.laws()
        summary = pipe.scan_summary()
        stage_times = {}
        for stage in ("build", "scan", "analyze", "laws"):
            doc = json.loads((pipe.folder(stage) / "stage.json").read_text())
            stage_times[stage] = doc.get("timing", doc.get("timings"))
        analyze = json.loads((pipe.folder("analyze") / "analyze.json").read_text())
    keep = [
        "p_gpa",
        "tau_mpa",
        "sigma_mss_mpa",
        "shear_stiffness_gpa_per_nm",
        "tau_limited_by",
        "tau_position_angstrom",
        "tau_period_mpa",
        "n_jumps",
        "n_barriers",
        "force_noise_mpa",
        "energy_noise_mev_per_a2",
        "n_degenerate_minima",
        "tau_by_start_mpa",
    ]
    rows = table[[c for c in keep if c in table.columns]].to_dict(orient="records")
    doc = {
        "name": name,
        "setting": VARIANTS[name][0],
        "description": VARIANTS[name][1],
        "overrides": VARIANTS[name][2],
        "loads": rows,
        "laws": laws,
        "work_of_separation_j_per_m2": summary["adhesion"]["work_of_separation_j_per_m2"],
        "adhesion": summary["adhesion"],
        "force_calls_total": summary["force_calls_total"],
        "points_total": summary["points_total"],
        "converged": summary["converged"],
        "thickness_angstrom": summary["thickness_angstrom"],
        "wall_time_s_this_call": timings,
        "stage_timing": stage_times,
        "analysis_warnings": analyze.get("warnings", []),
        "machine_load_1min": os.getloadavg()[0],
    }
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / f"{name}.json").write_text(json.dumps(doc, indent=1, default=float) + "\n")
    return doc


def main(argv: list[str]) -> None:
    if not argv or argv[0] not in ("run", "table"):
        sys.exit("usage: python -m benchmarks.convergence.study run NAME ... | table")
    if argv[0] == "run":
        unknown = [n for n in argv[1:] if n not in VARIANTS]
        if unknown:
            sys.exit(f"error: unknown variant(s) {unknown}; expected some of {sorted(VARIANTS)}")
        for name in argv[1:]:
            t0 = time.perf_counter()
            doc = run_variant(name)
            print(
                f"{name}: done in {time.perf_counter() - t0:.0f} s; laws {doc['laws']}", flush=True
            )
    else:
        from benchmarks.convergence.table import write_tables

        write_tables(RESULTS)


if __name__ == "__main__":
    main(sys.argv[1:])
