"""``flatcontact run`` (the whole study in a run directory) and ``flatcontact config``.

Thin: loads and validates the configuration (:mod:`flatcontact.config`), runs
:class:`flatcontact.pipeline.Pipeline` with rich progress (:mod:`flatcontact.cli.progress`)
and prints where the report is.
Ctrl-C stops cleanly; the same command resumes.
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from flatcontact.cli.app import app, check_out_dir, console, say_interrupted
from flatcontact.cli.progress import ScanBar, StageLines
from flatcontact.cli.settings import config_source
from flatcontact.foundation.layout import RUN_MARKER

_PRESET_HELP = "quick (default: minutes on a 2-core laptop) or paper (the paper's grids and loads)."


@app.command("run")
def run_command(
    config: Annotated[
        Path | None,
        typer.Argument(help="Run configuration (YAML); default: the built-in default (preset)."),
    ] = None,
    out: Annotated[
        Path, typer.Option("--out", help="Run directory (created; rerun to resume).")
    ] = Path("flatcontact-run"),
    preset: Annotated[str | None, typer.Option("--preset", help=_PRESET_HELP)] = None,
) -> None:
    """Interface -> ISPES scan -> τ, σ per load -> load laws -> modified Mindlin contact -> report.

    Rerunning skips stages whose inputs did not change and resumes an interrupted scan.
    """
    from flatcontact.config import load_config
    from flatcontact.pipeline import Pipeline
    from flatcontact.stages import _calculator

    cfg = load_config(config, preset)
    if not (out / RUN_MARKER).is_file():  # an existing run may be read-only: Pipeline decides
        check_out_dir(out)
    with (
        StageLines(console) as lines,
        Pipeline(
            cfg, out, on_event=lines, scan_progress=ScanBar(console), source=config_source(config)
        ) as pipe,
    ):
        console.print(
            f"flatcontact run: preset {cfg.preset}, {cfg.structure.kind}, "
            f"{_calculator.label(cfg)} -> {out}",
            highlight=False,
        )
        try:
            report = pipe.run()
        except KeyboardInterrupt:
            say_interrupted(f"finished work is kept in {out}")
            raise typer.Exit(130) from None
        _print_contact_range(pipe)
    console.print(f"report: {report.resolve()}", highlight=False)


def _print_contact_range(pipe) -> None:
    """The contact's adhesion regime and each p0 past the critical size of concurrent slip
    (``06-contact/summary.json``; the report has them in boxes above the contact numbers)."""
    from flatcontact.contact.slip_size import slip_sentences

    if "contact" not in pipe.results:  # a run that stopped before the contact stage
        return
    summary = pipe.contact_summary()
    lines = [(summary.get("adhesion_regime") or {}).get("sentence"), summary.get("moduli_note")]
    for line in [x for x in lines if x] + slip_sentences(summary.get("slip_size")):
        console.print(f"contact: {line}", highlight=False)


@app.command("config")
def config_command(
    show_default: Annotated[
        bool, typer.Option("--show-default", help="Print the default configuration as YAML.")
    ] = False,
    preset: Annotated[str | None, typer.Option("--preset", help=_PRESET_HELP)] = None,
    check: Annotated[
        Path | None,
        typer.Option("--check", help="Validate this YAML file and print it fully resolved."),
    ] = None,
    comments: Annotated[
        bool, typer.Option("--comments/--no-comments", help="Describe each field in a comment.")
    ] = True,
) -> None:
    """Print the default run configuration (with every field described) or check a file."""
    from flatcontact.config import load_config, to_yaml
    from flatcontact.foundation.errors import InputError
    from flatcontact.stages.preflight import check_inputs

    if not show_default and check is None:
        raise InputError("config: give --show-default [--preset quick|paper] or --check FILE")
    cfg = load_config(check, preset)
    if check is not None:  # what `run` refuses before its first stage, refused here too
        check_inputs(cfg, str(check))
    typer.echo(to_yaml(cfg, comments=comments), nl=False)
