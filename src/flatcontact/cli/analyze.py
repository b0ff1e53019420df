"""``flatcontact analyze``: ISPES grid → τ, σ_MSS, shear stiffness per load and the load laws.

Thin: its flags are the run settings' ``analysis`` section and ``report.svg``, one per
setting, derived from the settings (:mod:`flatcontact.cli.options`); it runs the analyze and the
laws stages (:mod:`flatcontact.stages.analyze`, :mod:`flatcontact.stages.laws`, the ones
``flatcontact run`` runs), prints a table or JSON and, with ``--out``, the stages write their
files there: ``friction.csv``, ``friction.nc``, ``analyze.json``, Fig. 2 per load,
``laws.json`` and Fig. 3.

``--p-gpa`` takes several values after one flag (``--p-gpa 0.5 1 2``), repeated
flags or comma-separated lists; negative (tensile) loads are accepted.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

from flatcontact.cli.app import (
    app,
    bounded,
    check_out_dir,
    console,
    print_warning,
    setting_bounds,
    split_list,
)
from flatcontact.cli.options import flags_of, setting_options, settings_command
from flatcontact.config.analysis import AnalysisConfig
from flatcontact.foundation import limits
from flatcontact.foundation.errors import InputError

#: The settings the command exposes, one flag each (:mod:`flatcontact.cli.options`);
#: ``analysis.p_gpa`` is ``--p-gpa``, whose values may also follow the ISPES file.
PATHS = (
    "analysis.direction_deg",
    "analysis.energy_form",
    "analysis.load_source",
    "analysis.energy_zero",
    "analysis.threshold_gpa",
    "analysis.allow_missing",
    "analysis.with_mep",
    "report.svg",
)
OPTIONS = setting_options(PATHS, {})
#: Settings paths and core parameters -> the flag that sets them, to name it in errors.
FLAG_OF = {**flags_of(OPTIONS), "analysis.p_gpa": "--p-gpa", "p_gpa": "--p-gpa"}
_P_GPA_HELP = setting_options(["analysis.p_gpa"], {"analysis.p_gpa": "none"})[0].help


def _split_arguments(items: list[str], p_values: list[str] | None) -> tuple[Path, list[float]]:
    """The ISPES path and the pressures from the positional items and ``--p-gpa`` values."""
    files, numbers = [], []
    for part in split_list(list(p_values or []) + list(items), "--p-gpa", whitespace=False):
        try:
            numbers.append(float(part))
        except ValueError:
            files.append(part)
    if len(files) != 1:
        raise InputError(
            f"analyze: expected one ISPES file and numeric --p-gpa values, got {files or 'no file'}"
        )
    if not numbers:
        raise InputError("--p-gpa: give at least one target pressure in GPa (e.g. --p-gpa 0.5 1 2)")
    # the run's analysis.p_gpa bounds: the loads replace the setting without revalidating it
    limits.check("loads", len(numbers), "--p-gpa", "loads")
    bounds = setting_bounds(AnalysisConfig, "p_gpa")
    return Path(files[0]), [bounded(x, "--p-gpa", bounds) for x in numbers]


@app.command(
    "analyze",
    context_settings={"ignore_unknown_options": True, "allow_interspersed_args": True},
)
@settings_command(OPTIONS)
def analyze_command(
    settings: dict,
    items: Annotated[
        list[str],
        typer.Argument(
            help="ISPES.nc, followed by more --p-gpa values if given after the flag.",
            show_default=False,
        ),
    ],
    p_gpa: Annotated[
        list[str] | None,
        typer.Option(
            "--p-gpa",
            metavar="NUMBERS",
            help=_P_GPA_HELP.removesuffix(" Default: none.")
            + " Give them as --p-gpa 0.5 1 2 (or repeat/comma-separate); one is enough here.",
        ),
    ] = None,
    out: Annotated[
        Path | None,
        typer.Option("--out", help="Directory for friction.csv/.nc, laws.json and the figures."),
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print the results as JSON.")] = False,
) -> None:
    """Constant-pressure ISPES, sliding path, τ, σ_MSS, shear stiffness and load laws."""
    from flatcontact.analysis.outputs import per_pressure_rows, summary_json
    from flatcontact.cli.settings import flag_errors, settings_from_flags
    from flatcontact.foundation.layout import FRICTION_CSV, OTHER_FORM_JSON
    from flatcontact.stages.analyze import AnalyzeInputs, analyze_stage
    from flatcontact.stages.laws import LawsInputs, laws_stage

    # the settings before the file is opened (analyze_ispes checks them again for library callers)
    cfg = settings_from_flags(settings, FLAG_OF)
    path, pressures = _split_arguments(items, p_gpa)
    if out is not None:
        check_out_dir(out)
    with flag_errors(FLAG_OF):
        # one load is enough here (the run's config asks for two, to fit the laws)
        cfg = cfg.model_copy(
            update={"analysis": cfg.analysis.model_copy(update={"p_gpa": pressures})}
        )
        analyzed = analyze_stage(cfg, AnalyzeInputs(path), out, other_form=out is not None)
        laws_inputs = (
            LawsInputs.read(out / FRICTION_CSV, out / OTHER_FORM_JSON)  # both forms, as the run
            if out is not None
            else LawsInputs.from_analysis(analyzed.analysis)
        )
        fitted = laws_stage(cfg, laws_inputs, out)
    result = analyzed.analysis
    for line in analyzed.warnings:
        print_warning(line)
    for w in fitted.caught:
        print_warning(f"{w.category.__name__}: {w.message}")
    written = analyzed.files + fitted.files

    if as_json:
        typer.echo(json.dumps({**summary_json(result), "laws": fitted.laws.to_json()}, indent=2))
        return
    from rich.table import Table

    table = Table(
        title=f"{path.name}: {cfg.analysis.energy_form} energy, {cfg.analysis.load_source} "
        "load, pulling at " + _direction_title(result)
    )
    for col in (
        "P (GPa)",
        "τ (MPa)",
        "σ_MSS (MPa)",
        "G_int (GPa/nm)",
        "τ limited by",
        "jumps",
        "noise (MPa)",
    ):
        table.add_column(col, justify="right")
    for row in per_pressure_rows(result):
        table.add_row(
            f"{row['p_gpa']:g}",
            _fmt(row["tau_mpa"]),
            _fmt(row["sigma_mss_mpa"]),
            _fmt(row["shear_stiffness_gpa_per_nm"]),
            str(row["tau_limited_by"]),
            str(row["n_jumps"]),
            _fmt(row["force_noise_mpa"]),
        )
    console.print(table)
    laws = fitted.laws.to_json()
    if laws["k_mpa_per_gpa"] is not None:
        console.print(
            f"τ = ({_fmt(laws['k_mpa_per_gpa'])} ± {_fmt(laws['k_stderr_mpa_per_gpa'])}) MPa/GPa · P "
            f"+ ({_fmt(laws['tau0_mpa'])} ± {_fmt(laws['tau0_stderr_mpa'])}) MPa"
        )
    if laws["mu_mpa_per_gpa"] is not None:
        console.print(
            f"σ = ({_fmt(laws['mu_mpa_per_gpa'])} ± {_fmt(laws['mu_stderr_mpa_per_gpa'])}) MPa/GPa · P "
            f"+ ({_fmt(laws['sigma0_mpa'])} ± {_fmt(laws['sigma0_stderr_mpa'])}) MPa   (P ≤ {laws['p_max_gpa']} GPa)"
        )
    sym = result.pressures[0].symmetry
    if sym is not None:
        console.print(
            f"symmetry at P = {result.pressures[0].p_gpa:g} GPa: {sym.summary()}", highlight=False
        )
    for p in written:
        console.print(f"wrote {p}", highlight=False)


def _fmt(v: float | None) -> str:
    return "n/a" if v is None else f"{v:.4g}"


def _direction_title(result) -> str:
    """The direction the analysis pulled along (auto's choice included)."""
    path = result.pressures[0].path if result.pressures else None
    angle = getattr(path, "direction_deg", None)
    rule = getattr(result, "direction_rule", "given")
    if angle is None:
        return "the requested direction"
    return f"{angle:g}°" + ("" if rule == "given" else f" ({rule})")
