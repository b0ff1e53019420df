"""The measured law uncertainty of the paper preset, from the stored results (issue 12).

    python -m benchmarks.convergence.uncertainty          # prints the numbers and the table
    python -m benchmarks.convergence.uncertainty --write  # and writes them to DATA_FILE

Per energy form and law coefficient c ∈ {k, τ0, μ, σ0}:

* ``convergence_<form>``: the largest |Δc| over the refinements :data:`REFINEMENTS` (one
  step finer in lateral grid, thicknesses, force tolerance, LJ cutoff, slab layers;
  ``results/[enthalpy/]<name>.json`` of :mod:`benchmarks.convergence.study`);
* ``model_spread_<form>``: half the max − min range of c over every model of the teacher
  comparison (``results/ispes_compare_<form>.json`` of :mod:`benchmarks.convergence.teachers`,
  :func:`flatcontact.analysis.uncertainty.committee_spread`).

Both are rounded to three significant figures and stored, with their provenance (this
command, the date, the result files read), in the package data file :data:`DATA_FILE`
(``src/flatcontact/data/measured/law_uncertainty.json``), which the ``paper`` preset reads as
``flatcontact.config.MEASURED_LAW_UNCERTAINTY``
(``tests/convergence/test_measured_uncertainty.py`` checks it against the results). The table is
docs/teachers.md "Carried into the laws": the paper preset's laws (``results/[enthalpy/]paper_layers9.json``)
± coverage 1 half-widths and τ, σ at the paper's Hertz peak p0 = 1.77 GPa propagated over
the law box (:func:`flatcontact.analysis.uncertainty.propagate_box`).
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RESULTS = Path(__file__).resolve().parent / "results"
#: The package data file the paper preset reads (flatcontact.config.MEASURED_LAW_UNCERTAINTY).
DATA_FILE = ROOT / "src" / "flatcontact" / "data" / "measured" / "law_uncertainty.json"
#: What the numbers are for (the data file's ``source``, carried into a run's settings).
SOURCE = (
    "measured for the bundled sio2-snap + Hamaker LJ, alpha-quartz (0001) dense, "
    "paper-preset settings (docs/convergence.md, docs/teachers.md); a lower bound for coarser "
    "grids, not a measurement for another model or surface"
)
FORMS = ("internal", "enthalpy")
#: (coarser, finer) result names: one refinement of each scan setting. The slab-thickness
#: step of the paper preset (9 -> 12 layers) is measured at half the force tolerance, where
#: both stacks' relaxation noise is resolved (at 0.005 eV/Å the 12-layer stack's own fmax
#: step moves τ(0) by 8.6 %); the preset's own fmax step at 9 layers is the last entry.
REFINEMENTS = (
    ("grid8", "ref"),  # lateral grid 8 -> 12
    ("ref", "thick30"),  # thicknesses 20 -> 30
    ("grid8", "fmax0025_g8"),  # fmax 0.005 -> 0.0025 eV/Å (6 layers)
    ("cutoff14_g8", "cutoff18_g8"),  # LJ cutoff 14 -> 18 Å
    ("layers9_f25_g8", "layers12_f25_g8"),  # slab layers 9 -> 12
    ("layers9_g8", "layers9_f25_g8"),  # fmax 0.005 -> 0.0025 eV/Å at 9 layers
    ("paper_layers9", "paper_grid16"),  # lateral grid 12 -> 16 of the preset itself
    # 16 -> 20 too: the per-load τ scatters by 5-9 % at both steps without a trend, so the
    # preset's own next step alone would understate the grid's share
    ("paper_grid16", "paper_grid20"),
)
#: the stored run of the paper preset (9 layers per slab since the slab-thickness study)
PAPER_RUN = "paper_layers9"
#: The paper's Hertz peak pressure (GPa) where τ and σ are quoted.
P0_GPA = 1.77


def _sig3(x: float) -> float:
    return float(f"{x:.3g}")


def _study_laws(name: str, form: str) -> dict:
    folder = RESULTS if form == "internal" else RESULTS / form
    return json.loads((folder / f"{name}.json").read_text())["laws"]


def convergence_delta(form: str) -> dict[str, float]:
    """Largest |change| of each law coefficient over :data:`REFINEMENTS` (unrounded)."""
    from flatcontact.analysis.uncertainty import LAW_COEFFICIENTS

    out = {}
    for key in LAW_COEFFICIENTS:
        out[key] = max(
            abs(float(_study_laws(fine, form)[key]) - float(_study_laws(coarse, form)[key]))
            for coarse, fine in REFINEMENTS
        )
    return out


def comparison(form: str) -> dict:
    """The per-model results of the teacher comparison in ``form`` (label -> result)."""
    return json.loads((RESULTS / f"ispes_compare_{form}.json").read_text())


def result_files() -> list[str]:
    """The result files the numbers are computed from (paths relative to the repository)."""
    names = sorted({name for pair in REFINEMENTS for name in pair})
    files = [RESULTS / f"{name}.json" for name in names]
    files += [RESULTS / "enthalpy" / f"{name}.json" for name in names]
    files += [RESULTS / f"ispes_compare_{form}.json" for form in FORMS]
    return [str(f.relative_to(ROOT)) for f in files]


def document(measured: dict | None = None, date: str | None = None) -> dict:
    """The data file's content: the numbers, their ``source`` and a ``provenance`` block."""
    measured = measured or measured_uncertainty()
    return {
        **measured,
        "source": SOURCE,
        "provenance": {
            "study": "convergence of the paper preset's load laws under one refinement of "
            "each scan setting (grid 8->12 at 6 layers, 12->16 and 16->20 at 9 layers, "
            "thicknesses 20->30, fmax 0.005->0.0025 at 6 and at 9 layers, LJ cutoff 14->18 A, "
            "slab layers 9->12) and half the max - min range of the laws over the bundled "
            "SNAPs (sio2-snap, sio2-snap-mf0) and their teachers CHGNet r2SCAN and "
            "SevenNet-MF-0 r2SCAN (4x4 grid, an upper bound); docs/convergence.md, "
            "docs/teachers.md",
            "command": "python -m benchmarks.convergence.uncertainty --write",
            "date": date or datetime.date.today().isoformat(),
            "rounding": "three significant figures",
            "result_files": result_files(),
        },
    }


def measured_uncertainty() -> dict:
    """The measured law uncertainty (three significant figures) from the results."""
    from flatcontact.analysis.uncertainty import committee_spread

    out: dict = {}
    for form in FORMS:
        out[f"convergence_{form}"] = {k: _sig3(v) for k, v in convergence_delta(form).items()}
    for form in FORMS:
        spread = committee_spread(comparison(form))
        out[f"model_spread_{form}"] = {k: _sig3(v) for k, v in spread.items()}
    return out


def carried_table(measured: dict | None = None) -> str:
    """Markdown: per form the paper preset's laws ± half-width and τ, σ at :data:`P0_GPA`."""
    from flatcontact.analysis.uncertainty import law_half_widths, propagate_box

    measured = measured or measured_uncertainty()
    lines = [
        f"| form | k (MPa/GPa) | τ0 (MPa) | μ (MPa/GPa) | σ0 (MPa) | τ({P0_GPA} GPa) (MPa) "
        f"| σ({P0_GPA} GPa) (MPa) |",
        "|---|---|---|---|---|---|---|",
    ]
    fit_only = []
    for form in FORMS:
        laws = _study_laws(PAPER_RUN, form)
        hw = law_half_widths(
            laws,
            convergence=measured[f"convergence_{form}"],
            model=measured[f"model_spread_{form}"],
        )
        central = {k: float(laws[k]) for k in hw}
        band = propagate_box(
            lambda x: {
                "tau": x["k_mpa_per_gpa"] * P0_GPA + x["tau0_mpa"],
                "sigma": x["mu_mpa_per_gpa"] * P0_GPA + x["sigma0_mpa"],
            },
            central,
            hw,
        )
        digits = {"k_mpa_per_gpa": 1, "tau0_mpa": 1, "mu_mpa_per_gpa": 2, "sigma0_mpa": 2}
        cells = [f"{central[k]:.{d}f} ± {hw[k]:.{d}f}" for k, d in digits.items()]
        cells += [
            f"{band[q][1]:.1f} [{band[q][0]:.1f}, {band[q][2]:.1f}]" for q in ("tau", "sigma")
        ]
        lines.append(f"| {form} | " + " | ".join(cells) + " |")
        fit = [laws[k.replace("_mpa", "_stderr_mpa", 1)] for k in digits]
        fit_only.append(f"{form} " + ", ".join(f"{v:.2g}" for v in fit))
    lines.append("")
    lines.append(f"(fit standard errors alone: {'; '.join(fit_only)}.)")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--write", action="store_true", help=f"write {DATA_FILE.name}")
    args = parser.parse_args()
    measured = measured_uncertainty()
    doc = document(measured)
    print(json.dumps(doc, indent=2, ensure_ascii=False))
    if args.write:
        DATA_FILE.parent.mkdir(parents=True, exist_ok=True)
        DATA_FILE.write_text(json.dumps(doc, indent=2, ensure_ascii=False) + "\n")
        print(f"wrote {DATA_FILE.relative_to(ROOT)}")
    for form in FORMS:
        print(f"models in the {form} spread: {', '.join(comparison(form))}")
    print()
    print(carried_table(measured))
    assert all(math.isfinite(v) for d in measured.values() for v in d.values())


if __name__ == "__main__":
    main()
