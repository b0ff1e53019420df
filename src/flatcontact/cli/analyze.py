"""``flatcontact analyze``: ISPES grid → τ, σ_MSS, shear stiffness per load and the load laws.

Thin: maps the flags to run settings (``analysis``, ``report.svg``), runs the analyze and the
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

from flatcontact import limits
from flatcontact.cli.app import (
    app,
    bounded,
    check_out_dir,
    console,
    print_warning,
    setting_bounds,
    split_list,
)
from flatcontact.config.analysis import AnalysisConfig
from flatcontact.errors import InputError

#: Settings paths and core parameters -> the flag that sets them, to name it in errors.
_FLAG_OF = {
    "analysis.p_gpa": "--p-gpa",
    "analysis.direction_deg": "--direction-deg",
    "analysis.energy_form": "--energy",
    "analysis.load_source": "--load-source",
    "analysis.energy_zero": "--energy-zero",
    "analysis.threshold_gpa": "--threshold-gpa",
    "analysis.allow_missing": "--allow-missing",
    "analysis.with_mep": "--mep",
    "p_gpa": "--p-gpa",
}


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
def analyze_command(
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
            help="Target normal pressure(s) P in GPa: --p-gpa 0.5 1 2 (or repeat/comma-separate).",
        ),
    ] = None,
    direction_deg: Annotated[
        str,
        typer.Option(
            "--direction-deg",
            help="Pulling direction, degrees from x (90 = y, the paper's), or 'auto': the "
            "lowest-barrier direction of the lowest load's landscape (stated in the outputs).",
        ),
    ] = "90",
    energy: Annotated[
        str,
        typer.Option("--energy", help="'internal' (paper: U at z*(P)) or 'enthalpy' (U + P·A·z*)."),
    ] = "internal",
    load_source: Annotated[
        str,
        typer.Option(
            "--load-source",
            help="Where P comes from: 'energy' (-(1/A) dU/dz of the spline of U(z); default) "
            "or 'stress' (the stored normal_stress).",
        ),
    ] = "energy",
    energy_zero: Annotated[
        str,
        typer.Option(
            "--energy-zero",
            help="Energy zero: 'lowest-p' (global minimum at the lowest P), 'each', 'none'.",
        ),
    ] = "lowest-p",
    threshold_gpa: Annotated[
        float, typer.Option("--threshold-gpa", help="Fit the load laws on P <= this (GPa).")
    ] = 3.0,
    allow_missing: Annotated[
        bool,
        typer.Option(
            "--allow-missing",
            help="Interpolate columns with missing (NaN) points instead of refusing.",
        ),
    ] = False,
    mep: Annotated[
        bool, typer.Option("--mep", help="Also compute the string-method minimum-energy path.")
    ] = False,
    out: Annotated[
        Path | None,
        typer.Option("--out", help="Directory for friction.csv/.nc, laws.json and the figures."),
    ] = None,
    svg: Annotated[bool, typer.Option("--svg/--no-svg", help="Also write SVG figures.")] = True,
    as_json: Annotated[bool, typer.Option("--json", help="Print the results as JSON.")] = False,
) -> None:
    """Constant-pressure ISPES, sliding path, τ, σ_MSS, shear stiffness and load laws."""
    from flatcontact.analysis.analyze import ENERGY_ZEROS
    from flatcontact.analysis.constant_pressure import FORMS, LOAD_SOURCES
    from flatcontact.analysis.outputs import per_pressure_rows, summary_json
    from flatcontact.cli.settings import FLAGS_SOURCE, flag_errors
    from flatcontact.config import build_config
    from flatcontact.layout import FRICTION_CSV, OTHER_FORM_JSON
    from flatcontact.stages.analyze import AnalyzeInputs, analyze_stage
    from flatcontact.stages.laws import LawsInputs, laws_stage

    for flag, value, allowed in (
        ("--energy", energy, FORMS),
        ("--load-source", load_source, LOAD_SOURCES),
        ("--energy-zero", energy_zero, ENERGY_ZEROS),
    ):  # before the file is opened (analyze_ispes checks them again for library callers)
        if value not in allowed:
            raise InputError(f"{flag}: expected one of {', '.join(allowed)}, got {value!r}")
    path, pressures = _split_arguments(items, p_gpa)
    if out is not None:
        check_out_dir(out)
    section = {
        "direction_deg": _direction(direction_deg),
        "energy_form": energy,
        "load_source": load_source,
        "energy_zero": energy_zero,
        "threshold_gpa": threshold_gpa,
        "allow_missing": allow_missing,
        "with_mep": mep,
    }
    with flag_errors(_FLAG_OF):
        cfg = build_config({"analysis": section, "report": {"svg": svg}}, source=FLAGS_SOURCE)
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
        title=f"{path.name}: {energy} energy, {load_source} load, pulling at "
        + _direction_title(result)
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


def _direction(text: str) -> float | str:
    """``--direction-deg`` as an angle in degrees or ``'auto'`` (one line naming the flag)."""
    if text.strip().lower() == "auto":
        return "auto"
    try:
        return float(text)
    except ValueError:
        raise InputError(
            f"--direction-deg: expected an angle in degrees or 'auto', got {text!r}"
        ) from None


def _direction_title(result) -> str:
    """The direction the analysis pulled along (auto's choice included)."""
    path = result.pressures[0].path if result.pressures else None
    angle = getattr(path, "direction_deg", None)
    rule = getattr(result, "direction_rule", "given")
    if angle is None:
        return "the requested direction"
    return f"{angle:g}°" + ("" if rule == "given" else f" ({rule})")
