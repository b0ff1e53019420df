"""``flatcontact study convergence|models|approximants``: studies over many runs of one interface.

Thin: loads the run configuration, calls :mod:`flatcontact.studies` and prints one line per
finished variant and where the study's files are (docs/studies.md).
"""

from __future__ import annotations

import math
import shlex
import sys
from pathlib import Path
from typing import Annotated

import typer

from flatcontact.cli.app import app, check_out_dir, console
from flatcontact.studies.study_dir import study_directory

study_app = typer.Typer(
    name="study",
    help="Convergence under refinement and spread over models: intervals for the laws.",
    no_args_is_help=True,
)
app.add_typer(study_app, name="study")

_OUT = typer.Option("--out", help="Study directory (created; rerun to resume).")


def _command_line() -> str:
    return "flatcontact " + " ".join(shlex.quote(a) for a in sys.argv[1:])


def _progress(name: str, result: dict) -> None:
    if "error" in result:  # a variant the builder or model refused: the setting's failure
        console.print(f"  {name}: failed: {result['error']}", highlight=False)
        return
    console.print(
        f"  {name}: scan {result['scan_action']}, {result['force_calls']} force calls, "
        f"{result['seconds']:.1f} s",
        highlight=False,
    )


@study_app.command("convergence")
def convergence_command(
    config: Annotated[
        Path, typer.Argument(help="Run configuration (YAML) with a refine: section.")
    ],
    out: Annotated[Path, _OUT] = Path("flatcontact-study"),
    estimate: Annotated[
        bool,
        typer.Option(
            "--estimate",
            help="Run (or reuse) only the base and print each variant's points, force calls "
            "and time extrapolated from it; the study run later reuses the base.",
        ),
    ] = False,
) -> None:
    """Refine grid, thicknesses, layers, fmax, cutoff one at a time until τ and σ_MSS stop moving."""
    from flatcontact.config.load import load_config
    from flatcontact.stages.preflight import check_inputs
    from flatcontact.studies.convergence import run_convergence
    from flatcontact.studies.estimate import estimate_lines
    from flatcontact.studies.output import cost_line, write_study

    def _estimate(est: dict) -> None:
        for line in estimate_lines(est):
            console.print(line, highlight=False)

    cfg = load_config(config)
    check_inputs(cfg, str(config))  # what the base run would refuse, named by CONFIG
    check_out_dir(out)
    console.print(f"flatcontact study convergence: {config} -> {out}", highlight=False)
    with study_directory(out):
        doc = run_convergence(
            cfg, out, on_done=_progress, on_estimate=_estimate, estimate_only=estimate
        )
        if estimate:
            return
        write_study(doc, cfg, out, _command_line())
    for s, st in doc["settings"].items():
        if st["state"] == "failed":
            kept = (
                f" (step {' -> '.join(st['last_step'])} stays in the uncertainty)"
                if "last_change" in st
                else ""
            )
            console.print(
                f"{s}: failed at step {st['steps']}: {st['error']}{kept}", highlight=False
            )
            continue
        if st["state"] == "not refined":
            console.print(
                f"{s}: not refined at step {st['steps']}: {st['reason']}", highlight=False
            )
            continue
        ch = st.get("last_change", {})
        console.print(
            f"{s}: {st['state']} after {st['steps']} step(s); last step moved "
            f"{ch.get('quantity')} at {ch.get('p_gpa')} GPa by {ch.get('max_pct', 0):.3g} %",
            highlight=False,
        )
        if st.get("noisier"):
            console.print(
                f"{s}: its finest variant is {st['noisier']:g}x noisier than the base "
                "(energy_noise_mev_per_a2, median over the loads): its change may be "
                "relaxation error, not the setting; refine it with a tighter "
                "scan.fmax_ev_per_angstrom",
                highlight=False,
            )
    for s, why in doc["skipped_settings"].items():
        console.print(f"{s}: not refined ({why})", highlight=False)
    console.print(
        f"{cost_line(doc['cost'])}; study: {(out / 'study.json').resolve()}", highlight=False
    )


@study_app.command("models")
def models_command(
    config: Annotated[Path, typer.Argument(help="Run configuration (YAML): interface and scan.")],
    models: Annotated[
        list[str],
        typer.Option(
            "--models",
            help="Potential presets or YAML files with a potential: section (A,B or the flag repeated).",
        ),
    ],
    out: Annotated[Path, _OUT] = Path("flatcontact-study"),
) -> None:
    """The same interface and scan with each model: τ, σ_MSS, W of each and their spread."""
    from flatcontact.config.load import load_config
    from flatcontact.studies.models import run_models
    from flatcontact.studies.output import write_study

    cfg = load_config(config)
    check_out_dir(out)
    console.print(f"flatcontact study models: {config} -> {out}", highlight=False)
    with study_directory(out):
        doc = run_models(cfg, models, out, on_done=_progress)
        write_study(doc, cfg, out, _command_line())
    for label, why in doc["failed"].items():
        console.print(f"{label}: failed, not in the spread: {why}", highlight=False)
    for form, spread in doc["spread"].items():
        text = ", ".join(f"{k} {v:.3g}" for k, v in spread.items())
        console.print(f"spread ({form}): {text}", highlight=False)
    console.print(f"study: {(out / 'study.json').resolve()}", highlight=False)


def _cell_progress(label: str, result: dict) -> None:
    if "error" in result:
        console.print(f"  {label}: failed: {result['error']}", highlight=False, soft_wrap=True)
        return
    gates = ", ".join(result["gates"]["fired"]) or "none"
    relaxed = result["relax_noise_mev_per_a2"]
    floor = "" if math.isnan(relaxed) else f", relaxation floor {relaxed:.2g}"
    console.print(
        f"  {label}: scan {result['scan_action']}, {result['force_calls']} force calls, "
        f"tau0 {result['tau0_mpa']:.4g} MPa, corrugation {result['barrier_mev_per_a2']:.4g} "
        f"meV/A^2 (noise {result['noise_mev_per_a2']:.2g}{floor}"
        f"{'' if result['resolved'] else ': NOT resolved'}), gates fired: {gates}, "
        f"{result['wall_s']:.1f} s",
        highlight=False,
        soft_wrap=True,
    )


def _scaling_line(name: str, fit: dict) -> str:
    parts = []
    for key in ("power_law", "offset_power_law"):
        f = fit[key]
        if "refused" in f:
            parts.append(f"{f['model']}: not fitted ({f['refused']})")
        elif key == "power_law":
            parts.append(
                f"{f['model']}: alpha {f['exponent']:.3g} +- {f['exponent_half_width']:.2g}"
            )
        else:
            parts.append(
                f"{f['model']}: alpha {f['exponent']:.3g} +- {f['exponent_half_width']:.2g}, "
                f"y_inf {f['limit']:.3g} +- {f['limit_half_width']:.2g}"
            )
    gated = fit.get("gated") or {}
    if gated:
        parts.append(
            "left out (gates fired): "
            + ", ".join(f"{label} ({', '.join(g)})" for label, g in gated.items())
        )
    return f"{name}: " + "; ".join(parts)


def _print_experiment_collapse(cfg, doc: dict, out: Path) -> None:
    """Each cell's collapse stress at the experiment's conditions (``contact.experiment``):
    printed and written to ``experiment_collapse.json``."""
    from flatcontact.foundation.fileio import write_json_atomic
    from flatcontact.studies.approximant_collapse import (
        EXPERIMENT_COLLAPSE_JSON,
        approximant_collapse,
    )

    rows = approximant_collapse(doc, cfg)
    write_json_atomic(out / EXPERIMENT_COLLAPSE_JSON, rows)
    console.print(
        f"collapse stress at p0 = {rows['p0_gpa']:g} GPa (R {rows['radius_um']:g} um, E* "
        f"{rows['contact_modulus_gpa']:g}, G* {rows['shear_modulus_gpa']:g} GPa; measured "
        + ", ".join(f"{k} {v:g}" for k, v in rows["measured_mpa"].items())
        + " MPa):",
        highlight=False,
        soft_wrap=True,
    )
    for r in rows["cells"]:
        if r["collapse_stress_mpa"] is None:
            value = "-"
        else:
            ratios = ", ".join(f"/{k} {v:.3g}" for k, v in r["ratio_to_measured"].items())
            value = f"{r['collapse_stress_mpa']:.4g} MPa ({ratios})"
        console.print(
            f"  {r['label']}: {r['n_atoms']} atoms, tau0 {r['tau0_mpa']:.4g} MPa, collapse "
            f"{value}" + (f"; {r['reason']}" if r["reason"] else ""),
            highlight=False,
            soft_wrap=True,
        )


@study_app.command("approximants")
def approximants_command(
    config: Annotated[
        Path,
        typer.Argument(help="Run configuration (YAML): structure, model, scan, approximants:."),
    ],
    out: Annotated[Path, _OUT] = Path("flatcontact-study"),
    list_only: Annotated[
        bool,
        typer.Option(
            "--list",
            help="Print the cells, their grid and their cost in seconds (one force call timed "
            "per cell; calibrated on a finished cell in --out if there is one); run no scan.",
        ),
    ] = False,
) -> None:
    """The ISPES study of each commensurate approximant cell: tau0 and corrugation vs size."""
    from flatcontact.config.load import load_config
    from flatcontact.studies.approximants import model_caveats, plan, run_approximants
    from flatcontact.studies.output import write_approximants

    cfg = load_config(config)
    cells = plan(cfg)
    for caveat in model_caveats(cfg):
        console.print(f"caveat: {caveat}", highlight=False, soft_wrap=True)
    console.print(
        f"{len(cells)} cell(s), base grid {cfg.scan.grid[0]}x{cfg.scan.grid[1]} per period of "
        f"the landscape, relax_mode {cfg.scan.relax_mode}:",
        highlight=False,
        soft_wrap=True,
    )
    first = cells[0]["atom_points_planned"] if cells else 1
    for c in cells:
        console.print(
            f"  {c['label']}: {c['n_atoms']} atoms, twist {c['twist_deg']:.4f} deg "
            f"(error {c['angle_error_deg']:+.4f}), strain {c['strain_percent_slab1']:.3g} / "
            f"{c['strain_percent_slab2']:.3g} %, shift lattice index {c['shift_lattice_index']}, "
            f"grid {c['grid'][0]}x{c['grid'][1]}, {c['points_planned']} points planned, "
            f"cost ~ {c['atom_points_planned'] / first:.3g}x the first cell (atoms x points)",
            highlight=False,
            soft_wrap=True,
        )
    if list_only:
        from flatcontact.studies.approximant_cost import cost_lines, estimate_cost

        for line in cost_lines(estimate_cost(cfg, cells, out if out.is_dir() else None)):
            console.print(line, highlight=False, soft_wrap=True)
        return
    check_out_dir(out)
    console.print(
        f"flatcontact study approximants: {config} -> {out}", highlight=False, soft_wrap=True
    )
    with study_directory(out):
        doc = run_approximants(cfg, out, on_done=_cell_progress)
        write_approximants(doc, out, _command_line())
    for key, name in (("tau0_mpa", "tau0"), ("barrier_mev_per_a2", "corrugation")):
        console.print(_scaling_line(name, doc["scaling"][key]), highlight=False, soft_wrap=True)
    if doc["tolerance_advice"]:
        console.print(
            "force tolerance: "
            + "; ".join(f"{label}: {text}" for label, text in doc["tolerance_advice"].items()),
            highlight=False,
            soft_wrap=True,
        )
    if cfg.contact.experiment.compare is not None:
        with study_directory(out):
            _print_experiment_collapse(cfg, doc, out)
    c = doc["cost"]
    console.print(
        f"force calls: {c['force_calls_study']} (stored {c['force_calls_stored']}; "
        f"relaxation floors {c['force_calls_floor']}); "
        f"study: {(out / 'study.json').resolve()}",
        highlight=False,
        soft_wrap=True,
    )


@study_app.command("export-uncertainty")
def export_uncertainty_command(
    studies: Annotated[
        list[Path],
        typer.Argument(
            help="study.json files (or study directories) of convergence/models studies."
        ),
    ],
    out: Annotated[Path, typer.Option("--out", help="Uncertainty data file (JSON) to write.")],
    source: Annotated[
        str | None,
        typer.Option("--source", help="What the numbers are for (default: the studies')."),
    ] = None,
) -> None:
    """One uncertainty file (the paper preset's data-file format) from the studies' blocks."""
    from flatcontact.foundation.errors import InputError
    from flatcontact.foundation.fileio import write_json_atomic
    from flatcontact.studies.export import export_uncertainty

    if out.is_dir() or (out.exists() and not out.is_file()):
        raise InputError(
            f"--out {str(out)!r}: exists and is not a regular file; name the JSON file to write"
        )
    doc = export_uncertainty(studies, source, _command_line())
    check_out_dir(out.parent, "--out")
    write_json_atomic(out, doc)
    blocks = [k for k in doc if k.startswith(("convergence_", "model_spread_"))]
    console.print(f"wrote {out} ({', '.join(blocks)})", highlight=False)
