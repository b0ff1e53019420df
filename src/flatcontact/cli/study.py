"""``flatcontact study convergence|models``: studies over many runs of one interface.

Thin: loads the run configuration, calls :mod:`flatcontact.studies` and prints one line per
finished variant and where the study's files are (docs/studies.md).
"""

from __future__ import annotations

import shlex
import sys
from pathlib import Path
from typing import Annotated

import typer

from flatcontact.cli.app import app, check_out_dir, console

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
    from flatcontact.studies.convergence import run_convergence
    from flatcontact.studies.estimate import estimate_lines
    from flatcontact.studies.output import write_study

    def _estimate(est: dict) -> None:
        for line in estimate_lines(est):
            console.print(line, highlight=False)

    cfg = load_config(config)
    check_out_dir(out)
    console.print(f"flatcontact study convergence: {config} -> {out}", highlight=False)
    doc = run_convergence(
        cfg, out, on_done=_progress, on_estimate=_estimate, estimate_only=estimate
    )
    if estimate:
        return
    write_study(doc, cfg, out, _command_line())
    for s, st in doc["settings"].items():
        if st["state"] == "failed":
            console.print(f"{s}: failed at step {st['steps']}: {st['error']}", highlight=False)
            continue
        ch = st.get("last_change", {})
        console.print(
            f"{s}: {st['state']} after {st['steps']} step(s); last step moved "
            f"{ch.get('quantity')} at {ch.get('p_gpa')} GPa by {ch.get('max_pct', 0):.3g} %",
            highlight=False,
        )
    for s, why in doc["skipped_settings"].items():
        console.print(f"{s}: not refined ({why})", highlight=False)
    c = doc["cost"]
    console.print(
        f"force calls: {c['force_calls_study']} (each setting from scratch: "
        f"{c['force_calls_from_scratch']}); study: {(out / 'study.json').resolve()}",
        highlight=False,
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
    doc = run_models(cfg, models, out, on_done=_progress)
    write_study(doc, cfg, out, _command_line())
    for form, spread in doc["spread"].items():
        text = ", ".join(f"{k} {v:.3g}" for k, v in spread.items())
        console.print(f"spread ({form}): {text}", highlight=False)
    console.print(f"study: {(out / 'study.json').resolve()}", highlight=False)


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
    from flatcontact.fileio import write_json_atomic
    from flatcontact.studies.export import export_uncertainty

    doc = export_uncertainty(studies, source, _command_line())
    check_out_dir(out.parent, "--out")
    write_json_atomic(out, doc)
    blocks = [k for k in doc if k.startswith(("convergence_", "model_spread_"))]
    console.print(f"wrote {out} ({', '.join(blocks)})", highlight=False)
