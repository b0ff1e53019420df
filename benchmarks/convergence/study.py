"""Convergence study of the SiO₂ ISPES laws (issue 12): one refinement of each setting alone.

Usage (from the repository root, one variant at a time, in the background on a shared machine)::

    python -m benchmarks.convergence.study run ref grid16 ...   # scans + analysis -> results/<name>.json
    python -m benchmarks.convergence.study reanalyze ref ...    # stored grids, analysis only
    python -m benchmarks.convergence.study table                # results/convergence.{csv,md}

Every variant is the ``paper`` preset of :func:`flatcontact.config.preset` with ONE change
(:data:`VARIANTS`), run through :class:`flatcontact.pipeline.Pipeline` (build, scan,
analyze, laws) into ``$FLATCONTACT_CONVERGENCE_RUNS/<name>`` (default
``/tmp/flatcontact-convergence``). The result file keeps per load τ, σ_MSS, G_int, the
path facts (what limits τ, jumps, where τ is reached), the load noise, the work of
separation W, the fitted laws with standard errors and the wall time of each stage.
The comparison (:func:`flatcontact.analysis.convergence.per_load_changes`,
:func:`~flatcontact.analysis.convergence.law_changes`) is done by ``table``.
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
#: Energy form of the analysis (``FLATCONTACT_STUDY_FORM``: internal, the paper's, or
#: enthalpy); enthalpy results go to ``results/enthalpy/``. The scans are the same.
FORM = os.environ.get("FLATCONTACT_STUDY_FORM", "internal")
RESULTS = HERE / "results" if FORM == "internal" else HERE / "results" / FORM
RUNS = Path(os.environ.get("FLATCONTACT_CONVERGENCE_RUNS", "/tmp/flatcontact-convergence"))

#: The study's reference LJ cutoff (the paper preset's before this study set it to 18 Å).
STUDY_LJ_CUTOFF_ANGSTROM = 10.0
#: Thickness ranges of the thick-slab variants: the paper preset's load spacing at the probe
#: stacking ((5.5 + 0.3)/19 GPa) and lower bound. Up to session 4 the scan placed slab 2
#: rigidly, so the whole elastic compression of the free layers first landed in the gap, and
#: the 1.0 Å overlap guard of ``place_slab2`` allowed 2.0 Å of compression: the stiffest
#: probed stacking (0.5, 0) carried > 5.5 GPa with 6 layers, 5.2–5.5 GPa with 9 and only
#: 3.9 GPa with 12 (measured, LJ 10 Å). ``place_slab2`` now spreads a compression the gap
#: cannot take over the stack, and every thick slab is scanned over the 9-layer range; the
#: rigid-slab diagnostics (never deformed) keep the capped 12-layer range.
_P_STEP_GPA = (5.5 + 0.3) / 19
THICK_SLAB_P_RANGE = {
    9: {"lo_gpa": -0.3, "hi_gpa": round(-0.3 + 18 * _P_STEP_GPA, 6), "n": 19},
    "rigid12": {"lo_gpa": -0.3, "hi_gpa": round(-0.3 + 11 * _P_STEP_GPA, 6), "n": 12},
}


def _thick_slab_overrides(layers: int, **scan) -> dict:
    """Config overrides of a thick-slab step: 8x8, the 9-layer load range, ``layers`` per slab."""
    return {
        "scan": {"grid": [8, 8], "p_range_gpa": THICK_SLAB_P_RANGE[9], **scan},
        "structure": {"layers": layers},
    }


def _paper_preset_on_grid(n: int) -> dict:
    """Overrides of the paper preset (9 layers, LJ 18 Å) on an n x n grid; 2 workers, which
    do not change a number (the executors agree to 1e-12)."""
    return {
        "potential": {"lj": {"cutoff_angstrom": 18.0}},
        "structure": {"layers": 9},
        "scan": {
            "grid": [n, n],
            "p_range_gpa": THICK_SLAB_P_RANGE[9],
            "executor": "processes",
            "workers": 2,
        },
    }


#: name -> (setting varied, what, config overrides laid over the paper preset, the run it is
#: compared with). Variants on an 8x8 grid (``*_g8``) measure a setting's effect at the
#: coarser grid, to fit the CPU budget of a shared 2-core machine.
VARIANTS: dict[str, tuple[str, str, dict, str]] = {
    "ref": (
        "reference",
        "paper preset: 12x12, 20 thicknesses, fmax 0.005, 6 layers, LJ 10 Å",
        {},
        "ref",
    ),
    "grid8": ("lateral grid", "8x8 (one step coarser)", {"scan": {"grid": [8, 8]}}, "ref"),
    "grid16": ("lateral grid", "16x16 (one step finer)", {"scan": {"grid": [16, 16]}}, "ref"),
    "thick30": (
        "thicknesses",
        "30 thicknesses over the same load range (spacing x2/3)",
        {"scan": {"p_range_gpa": {"lo_gpa": -0.3, "hi_gpa": 5.5, "n": 30}}},
        "ref",
    ),
    "fmax0025": (
        "force tolerance",
        "fmax 0.0025 eV/Å (half)",
        {"scan": {"fmax_ev_per_angstrom": 0.0025}},
        "ref",
    ),
    "fmax01_g8": (
        "force tolerance",
        "fmax 0.01 eV/Å (double; 8x8 grid; grid8 at 0.005 is its refinement)",
        {"scan": {"grid": [8, 8], "fmax_ev_per_angstrom": 0.01}},
        "grid8",
    ),
    "cutoff14_g8": (
        "LJ cutoff",
        "cross-interface LJ cutoff 14 Å (8x8 grid; compared with grid8)",
        {"scan": {"grid": [8, 8]}, "potential": {"lj": {"cutoff_angstrom": 14.0}}},
        "grid8",
    ),
    "cutoff18_g8": (
        "LJ cutoff",
        "cross-interface LJ cutoff 18 Å (8x8 grid; compared with cutoff14_g8)",
        {"scan": {"grid": [8, 8]}, "potential": {"lj": {"cutoff_angstrom": 18.0}}},
        "cutoff14_g8",
    ),
    "fmax0025_g8": (
        "force tolerance",
        "fmax 0.0025 eV/Å (half; 8x8 grid; compared with grid8)",
        {"scan": {"grid": [8, 8], "fmax_ev_per_angstrom": 0.0025}},
        "grid8",
    ),
    "paper": (
        "preset",
        "the new paper preset (12x12, 20 thicknesses, fmax 0.005, LJ 18 Å)",
        {"potential": {"lj": {"cutoff_angstrom": 18.0}}},
        "ref",
    ),
    "layers6_g8": (
        "slab layers",
        "6 O-Si-O layers per slab (the shipped slab): grid8 scanned again with the code of the "
        "slab-thickness steps, their baseline (compared with grid8: code drift)",
        {"scan": {"grid": [8, 8]}, "structure": {"layers": 6}},
        "grid8",
    ),
    "layers9_g8": (
        "slab layers",
        "9 O-Si-O layers per slab (shipped dense slab + 1 bulk c-repeat of the SNAP's own "
        "alpha-quartz, SNAP-relaxed; 8x8 grid, thicknesses up to 5.2 GPa; compared with "
        "layers6_g8)",
        {
            "scan": {"grid": [8, 8], "p_range_gpa": THICK_SLAB_P_RANGE[9]},
            "structure": {"layers": 9},
        },
        "layers6_g8",
    ),
    "layers12_g8": (
        "slab layers",
        "12 O-Si-O layers per slab (shipped dense slab + 2 bulk c-repeats; 8x8 grid, "
        "thicknesses up to 5.2 GPa as layers9_g8, compression spread over the stack where the "
        "gap cannot take it; compared with layers9_g8)",
        _thick_slab_overrides(12),
        "layers9_g8",
    ),
    "layers9_f25_g8": (
        "force tolerance (thick slabs)",
        "9 layers at fmax 0.0025 eV/Å (half; compared with layers9_g8): the relaxation noise "
        "of a compliant stack",
        _thick_slab_overrides(9, fmax_ev_per_angstrom=0.0025),
        "layers9_g8",
    ),
    "layers12_f25_g8": (
        "slab layers",
        "12 layers at fmax 0.0025 eV/Å (compared with layers9_f25_g8)",
        _thick_slab_overrides(12, fmax_ev_per_angstrom=0.0025),
        "layers9_f25_g8",
    ),
    "layers15_f25_g8": (
        "slab layers",
        "15 layers at fmax 0.0025 eV/Å (compared with layers12_f25_g8)",
        _thick_slab_overrides(15, fmax_ev_per_angstrom=0.0025),
        "layers12_f25_g8",
    ),
    "paper_layers6": (
        "slab layers",
        "the paper preset (12x12, LJ 18 Å, 6 layers) scanned again with the code of the "
        "slab-thickness steps (compared with paper: code drift)",
        {"potential": {"lj": {"cutoff_angstrom": 18.0}}, "structure": {"layers": 6}},
        "paper",
    ),
    "paper_layers9": (
        "slab layers",
        "the paper preset (12x12, LJ 18 Å) with 9 layers per slab (thicknesses up to 5.19 GPa; "
        "compared with paper_layers6)",
        {
            "potential": {"lj": {"cutoff_angstrom": 18.0}},
            "structure": {"layers": 9},
            "scan": {"p_range_gpa": THICK_SLAB_P_RANGE[9]},
        },
        "paper_layers6",
    ),
    "paper_grid16": (
        "lateral grid",
        "the paper preset (9 layers, LJ 18 Å) on a 16x16 lateral grid (one step finer; "
        "compared with paper_layers9; 2 workers, which do not change a number)",
        _paper_preset_on_grid(16),
        "paper_layers9",
    ),
    "paper_grid20": (
        "lateral grid",
        "the paper preset (9 layers, LJ 18 Å) on a 20x20 lateral grid (compared with "
        "paper_grid16; 2 workers)",
        _paper_preset_on_grid(20),
        "paper_grid16",
    ),
    "layers6_rigid_g8": (
        "slab layers (diagnostic)",
        "6 layers, rigid slabs (no relaxation at any point: the interface's own corrugation; "
        "8x8 grid)",
        {"scan": {"grid": [8, 8], "relax_mode": "rigid"}, "structure": {"layers": 6}},
        "layers6_g8",
    ),
    "layers9_rigid_g8": (
        "slab layers (diagnostic)",
        "9 layers, rigid slabs (8x8 grid, thicknesses up to 5.2 GPa; compared with "
        "layers6_rigid_g8)",
        {
            "scan": {
                "grid": [8, 8],
                "relax_mode": "rigid",
                "p_range_gpa": THICK_SLAB_P_RANGE[9],
            },
            "structure": {"layers": 9},
        },
        "layers6_rigid_g8",
    ),
    "layers12_rigid_g8": (
        "slab layers (diagnostic)",
        "12 layers, rigid slabs (8x8 grid, thicknesses up to 3.06 GPa, loads up to 2.5 GPa; "
        "compared with layers9_rigid_g8)",
        {
            "scan": {
                "grid": [8, 8],
                "relax_mode": "rigid",
                "p_range_gpa": THICK_SLAB_P_RANGE["rigid12"],
            },
            "structure": {"layers": 12},
            "analysis": {"p_gpa": [0.0, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 2.5]},
            "report": {"fig2_p_gpa": [0.5, 1.0, 2.5]},
        },
        "layers9_rigid_g8",
    ),
}
#: Analysis-only variants: a subset of another run's grid (no new scan): name -> (setting,
#: what, base run, xarray isel of its ispes.nc, the run it is compared with).
DERIVED: dict[str, tuple[str, str, str, dict, str]] = {
    "thick10": (
        "thicknesses",
        "every second thickness of ref (10, keeping the largest; spacing x2)",
        "ref",
        {"thickness": slice(1, None, 2)},
        "ref",
    ),
    "grid6": (
        "lateral grid",
        "every second lateral point of ref (6x6)",
        "ref",
        {"shift_a": slice(None, None, 2), "shift_b": slice(None, None, 2)},
        "ref",
    ),
}

#: Per-load columns of friction.csv kept in the result files.
LOAD_COLUMNS = [
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


def config_for(name: str, form: str | None = None):
    """The validated run configuration of variant ``name`` (paper preset + its overrides)."""
    from flatcontact.config import build_config, merge_config

    overrides = merge_config(
        {
            "scan": {"workers": 1, "executor": "serial"},
            "analysis": {"energy_form": form or FORM},
            "potential": {"lj": {"cutoff_angstrom": STUDY_LJ_CUTOFF_ANGSTROM}},
        },
        VARIANTS[name][2],
    )
    return build_config(overrides, "paper", f"variant {name}")


def run_variant(name: str) -> dict:
    """Run variant ``name`` (resuming its run directory) and write ``results/<name>.json``."""
    from flatcontact.pipeline import Pipeline

    cfg = config_for(name)
    # the scan does not depend on the analysis settings: one run directory per variant
    scan_cfg = cfg.model_copy(update={"analysis": config_for(name, "internal").analysis})
    timings = {}
    with Pipeline(scan_cfg, RUNS / name) as pipe:
        for stage in ("build", "scan"):
            t0 = time.perf_counter()
            ds = getattr(pipe, stage)()
            timings[stage] = time.perf_counter() - t0
        summary = pipe.scan_summary()
        stage_times = {}
        for stage in ("build", "scan"):
            doc = json.loads((pipe.folder(stage) / "stage.json").read_text())
            stage_times[stage] = doc.get("seconds")
    rows, laws, notes, timings["analyze"] = analyze_grid(ds, cfg.analysis)
    doc = {
        "name": name,
        "setting": VARIANTS[name][0],
        "description": VARIANTS[name][1],
        "overrides": VARIANTS[name][2],
        "compare_with": VARIANTS[name][3],
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
        "analysis_warnings": notes,
        "machine_load_1min": os.getloadavg()[0],
    }
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / f"{name}.json").write_text(json.dumps(doc, indent=1, default=float) + "\n")
    return doc


def analyze_grid(ds, analysis) -> tuple[list[dict], dict, list[str], float]:
    """τ, σ_MSS, G_int per load and the laws of ``ds`` with the run's analysis settings.

    The same call as the pipeline's analyze and laws stages
    (:func:`flatcontact.analysis.analyze.analyze_ispes`), without figures and the symmetry
    report (neither changes a number). Returns (rows, laws, warnings, seconds).
    """
    import io
    import warnings

    import pandas as pd

    from flatcontact.analysis.analyze import analyze_ispes
    from flatcontact.analysis.diagnostics import AnalysisWarning
    from flatcontact.analysis.outputs import friction_csv_text

    t0 = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", AnalysisWarning)
        result = analyze_ispes(
            ds,
            analysis.p_gpa,
            direction_deg=analysis.direction_deg,
            form=analysis.energy_form,
            load_source=analysis.load_source,
            energy_zero=analysis.energy_zero,
            threshold_gpa=analysis.threshold_gpa,
            with_symmetry=False,
        )
    table = pd.read_csv(io.StringIO(friction_csv_text(result)))
    rows = table[[c for c in LOAD_COLUMNS if c in table.columns]].to_dict(orient="records")
    notes = [f"{w.category.__name__}: {w.message}" for w in caught]
    return rows, result.laws.to_json(), notes, time.perf_counter() - t0


def run_derived(name: str) -> dict:
    """Analyse a subset of another variant's grid (:data:`DERIVED`) like the pipeline does."""
    from flatcontact.ispes.contract import open_ispes

    setting, description, base, isel, compare_with = DERIVED[name]
    base_doc = json.loads((HERE / "results" / f"{base}.json").read_text())
    ds = open_ispes(RUNS / base / "02-scan" / "ispes.nc").isel(isel)
    rows, laws, notes, seconds = analyze_grid(ds, config_for(base).analysis)
    doc = {
        **{k: base_doc[k] for k in ("work_of_separation_j_per_m2", "adhesion")},
        "name": name,
        "setting": setting,
        "description": description,
        "derived_from": base,
        "isel": {k: [v.start, v.stop, v.step] for k, v in isel.items()},
        "compare_with": compare_with,
        "loads": rows,
        "laws": laws,
        "wall_time_s_this_call": {"analyze": seconds},
        "analysis_warnings": notes,
    }
    (RESULTS / f"{name}.json").write_text(json.dumps(doc, indent=1, default=float) + "\n")
    return doc


def reanalyze_variant(name: str) -> dict:
    """Analyse variant ``name``'s stored grid again and update ``results/<name>.json``.

    For a change that leaves the stored scans as they are: a stage's fingerprint includes
    its own code (:func:`flatcontact.pipeline.stage_code_digest`), so ``run`` rescans after any edit
    of the build or scan code, even one that cannot change a finished point (e.g. the
    spread compression of ``place_slab2``, which only acts where a rigid placement
    overlaps). This reads ``RUNS/<name>/02-scan/ispes.nc`` as it is and replaces the loads,
    laws and warnings of the results file (scan facts, timings and W are the scan's and
    stay); ``reanalyzed`` records when.
    """
    from flatcontact.ispes.contract import open_ispes

    path = RESULTS / f"{name}.json"
    if not path.is_file():
        sys.exit(f"error: {path} does not exist; 'run {name}' first")
    doc = json.loads(path.read_text())
    ds = open_ispes(RUNS / name / "02-scan" / "ispes.nc")
    rows, laws, notes, seconds = analyze_grid(ds, config_for(name).analysis)
    doc.update(
        loads=rows,
        laws=laws,
        analysis_warnings=notes,
        reanalyzed={"at": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "analyze_s": seconds},
    )
    path.write_text(json.dumps(doc, indent=1, default=float) + "\n")
    return doc


def main(argv: list[str]) -> None:
    if not argv or argv[0] not in ("run", "reanalyze", "table"):
        sys.exit(
            "usage: python -m benchmarks.convergence.study run NAME ... | reanalyze NAME ... | table"
        )
    if argv[0] in ("run", "reanalyze"):
        unknown = [n for n in argv[1:] if n not in VARIANTS and n not in DERIVED]
        if unknown:
            known = sorted([*VARIANTS, *DERIVED])
            sys.exit(f"error: unknown variant(s) {unknown}; expected some of {known}")
        for name in argv[1:]:
            t0 = time.perf_counter()
            if name in DERIVED:
                doc = run_derived(name)
            elif argv[0] == "reanalyze":
                doc = reanalyze_variant(name)
            else:
                doc = run_variant(name)
            print(
                f"{name}: done in {time.perf_counter() - t0:.0f} s; laws {doc['laws']}", flush=True
            )
    else:
        from benchmarks.convergence.table import write_tables

        write_tables(RESULTS)


if __name__ == "__main__":
    main(sys.argv[1:])
