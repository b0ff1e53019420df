"""``flatcontact contact``: the continuum contact model (Hertz, adhesion, modified Mindlin).

Thin: parses flags named by quantity and unit, calls :mod:`flatcontact.contact`,
prints a rich table or JSON and, with ``--out``, writes figures, ``summary.json``
and ``contact.nc`` atomically.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

from flatcontact.cli.app import app, check_out_dir, console, parse_floats
from flatcontact.errors import InputError, require

_DEFAULT_HELP = "(default: the paper's value)"


def _parse_p0(values: list[str] | None) -> list[float]:
    from flatcontact.contact.parameters import DEFAULT_P0_GPA, check_p0_gpa

    if not values:
        return list(DEFAULT_P0_GPA)
    out = parse_floats(values, "--p0-gpa", "GPa")
    return check_p0_gpa(out, "--p0-gpa")


@app.command("contact")
def contact_command(
    p0_gpa: Annotated[
        list[str] | None,
        typer.Option(
            "--p0-gpa",
            help="Peak Hertz pressure(s) p0 in GPa; repeat or comma-separate. Default 0.5,1,1.77,2,3.",
        ),
    ] = None,
    radius_um: Annotated[
        float, typer.Option("--radius-um", help=f"Tip radius R (µm) {_DEFAULT_HELP}.")
    ] = 5.0,
    contact_modulus_gpa: Annotated[
        float,
        typer.Option(
            "--contact-modulus-gpa", help=f"Hertz contact modulus E* (GPa) {_DEFAULT_HELP}."
        ),
    ] = 52.5,
    shear_modulus_gpa: Annotated[
        float,
        typer.Option(
            "--shear-modulus-gpa",
            help="Effective shear modulus G* (GPa) in the paper's convention q0 = G*·u/(πa) (= 4× Johnson's G*_J); default 29.",
        ),
    ] = 29.0,
    johnson: Annotated[
        bool,
        typer.Option(
            "--johnson-shear-modulus",
            help="Read --shear-modulus-gpa as Johnson's G*_J (converted: G* = 4 G*_J).",
        ),
    ] = False,
    k_mpa_per_gpa: Annotated[
        float,
        typer.Option(
            "--k-mpa-per-gpa",
            help="k in τ = k·p + τ0 (MPa/GPa; may be < 0, then p0 < τ0/|k|); default 4.52.",
        ),
    ] = 4.52,
    tau0_mpa: Annotated[
        float, typer.Option("--tau0-mpa", help="τ0 in τ = k·p + τ0 (MPa); default 26.7.")
    ] = 26.7,
    mu_mpa_per_gpa: Annotated[
        float,
        typer.Option(
            "--mu-mpa-per-gpa",
            help="μ in σ = μ·p + σ0 (MPa/GPa; may be < 0, then p0 <= σ0/|μ|); default 0.21.",
        ),
    ] = 0.21,
    sigma0_mpa: Annotated[
        float, typer.Option("--sigma0-mpa", help="σ0 in σ = μ·p + σ0 (MPa); default 11.1.")
    ] = 11.1,
    work_of_adhesion_j_m2: Annotated[
        float | None,
        typer.Option(
            "--work-of-adhesion-j-m2",
            help="Work of adhesion w (J/m²): adds DMT/JKR radii and their change vs Hertz.",
        ),
    ] = None,
    maugis_lambda: Annotated[
        float | None,
        typer.Option(
            "--maugis-lambda", help="Maugis parameter λ: adds the Maugis–Dugdale radius (needs w)."
        ),
    ] = None,
    knee_fraction: Annotated[
        float,
        typer.Option(
            "--knee-fraction", help="The knee is where the stiffness falls to this fraction of k0."
        ),
    ] = 0.5,
    experiment: Annotated[
        Path | None,
        typer.Option(
            "--experiment",
            help="CSV of mean shear stress vs lateral stiffness, units in the header.",
        ),
    ] = None,
    experiment_p0_gpa: Annotated[
        float,
        typer.Option(
            "--experiment-p0-gpa", help="p0 (GPa) of the measured data; default 1.77 (the paper's)."
        ),
    ] = 1.77,
    experiment_stress_measure: Annotated[
        str,
        typer.Option(
            "--experiment-stress-measure",
            help="'amplitude' (Q_max/πa², the paper's experiment) or 'rms' (<Q>/πa²).",
        ),
    ] = "amplitude",
    collapse_fraction: Annotated[
        float,
        typer.Option(
            "--collapse-fraction",
            help="Collapse = stiffness first below this fraction of its low-stress value.",
        ),
    ] = 0.2,
    out: Annotated[
        Path | None,
        typer.Option("--out", help="Directory for figures, summary.json and contact.nc."),
    ] = None,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the per-p0 results as JSON.")
    ] = False,
) -> None:
    """Hertz + adhesion + modified Mindlin: Q(u), peak and gross-sliding forces, oscillatory stiffness."""
    from flatcontact.contact import experiment as exp
    from flatcontact.contact.mindlin import paper_shear_modulus_from_johnson
    from flatcontact.contact.parameters import ContactParameters, check_positive
    from flatcontact.contact.summary import analyse

    # ---- validate everything before any work --------------------------------------
    p0_list = _parse_p0(p0_gpa)
    g = float(paper_shear_modulus_from_johnson(shear_modulus_gpa)) if johnson else shear_modulus_gpa
    try:
        params = ContactParameters(
            radius_um=radius_um,
            contact_modulus_gpa=contact_modulus_gpa,
            shear_modulus_gpa=g,
            k_mpa_per_gpa=k_mpa_per_gpa,
            tau0_mpa=tau0_mpa,
            mu_mpa_per_gpa=mu_mpa_per_gpa,
            sigma0_mpa=sigma0_mpa,
            work_of_adhesion_j_m2=0.0 if work_of_adhesion_j_m2 is None else work_of_adhesion_j_m2,
        )
        # τ > 0 and σ >= 0 on the whole contact (limits p0 when k or μ < 0)
        params.check_p0_gpa(p0_list, "--p0-gpa")
        if experiment is not None:
            params.check_p0_gpa(experiment_p0_gpa, "--experiment-p0-gpa")
    except InputError as e:
        msg = str(e)
        for field in ContactParameters.__dataclass_fields__:
            msg = msg.replace(field, "--" + field.replace("_", "-"))
        raise InputError(msg) from None
    if work_of_adhesion_j_m2 is not None:
        check_positive("--work-of-adhesion-j-m2", work_of_adhesion_j_m2)
    if maugis_lambda is not None:
        check_positive("--maugis-lambda", maugis_lambda)
        require(work_of_adhesion_j_m2 is not None, "--maugis-lambda needs --work-of-adhesion-j-m2")
    require(0.0 < knee_fraction < 1.0, f"--knee-fraction must be in (0, 1), got {knee_fraction!r}")
    require(
        0.0 < collapse_fraction < 1.0,
        f"--collapse-fraction must be in (0, 1), got {collapse_fraction!r}",
    )
    require(
        experiment_stress_measure in ("amplitude", "rms"),
        f"--experiment-stress-measure must be 'amplitude' or 'rms', got {experiment_stress_measure!r}",
    )
    check_positive("--experiment-p0-gpa", experiment_p0_gpa)
    measured = exp.load_stiffness_csv(experiment) if experiment is not None else None
    if out is not None:
        check_out_dir(out)

    # ---- compute ---------------------------------------------------------------------
    analysis = analyse(p0_list, params, maugis_lambda=maugis_lambda, knee_fraction=knee_fraction)
    records = analysis.records()
    exp_summary = None
    fitted = None
    if measured is not None:
        comparison = exp.compare_with_measurement(
            measured,
            experiment_p0_gpa,
            params,
            fraction=collapse_fraction,
            measure=experiment_stress_measure,
        )
        fitted = comparison.fitted_params
        exp_summary = comparison.to_json()

    # ---- write -----------------------------------------------------------------------
    doc = {
        "parameters": params.as_dict(),
        "conventions": {
            "shear_modulus": "paper: q0 = G* u/(pi a); Johnson's G*_J = G*/4",
            "effective_shear_strength_mpa": "amplitude Q_peak/(pi a^2)",
            "effective_shear_strength_rms_mpa": "Q_peak/(sqrt(2) pi a^2)",
            "knee": f"stress where d<Q>/d<u> = {knee_fraction:g} x initial stiffness",
        },
        "results": records,
    }
    if exp_summary is not None:
        doc["experiment"] = exp_summary
    if out is not None:
        _write_outputs(out, doc, analysis, measured, fitted, exp_summary)

    if as_json:
        typer.echo(json.dumps(doc, indent=2))
        return
    _print_table(records, exp_summary, out)


def _write_outputs(out, doc, analysis, measured, fitted, exp_summary) -> None:
    from flatcontact.fileio import write_json_atomic
    from flatcontact.plots import save_figure
    from flatcontact.plots.contact import fig4_traction, fig5_force_and_stiffness, fig6_overlay

    out.mkdir(parents=True, exist_ok=True)
    p0_fig4 = 1.0 if 1.0 in analysis.p0_gpa else analysis.p0_gpa[0]
    figs = {
        "fig4_traction": fig4_traction(analysis.params, p0_fig4, 0.2),
        "fig5_force_stiffness": fig5_force_and_stiffness(analysis, "amplitude"),
        "fig5_force_stiffness_rms": fig5_force_and_stiffness(analysis, "rms"),
    }
    if measured is not None:
        figs["fig6_experiment"] = fig6_overlay(
            measured,
            exp_summary["p0_gpa"],
            {
                f"τ0 = {analysis.params.tau0_mpa:g} MPa": analysis.params,
                f"fitted τ0 = {fitted.tau0_mpa:.3g} MPa": fitted,
            },
            measure=exp_summary["stress_measure"],
            measured_collapse_mpa=exp_summary["measured_collapse_stress_mpa"],
        )
    for name, fig in figs.items():
        save_figure(fig, out / name)
    analysis.write_netcdf(out / "contact.nc")
    write_json_atomic(out / "summary.json", doc)


def _print_table(records, exp_summary, out) -> None:
    from rich.table import Table

    rows = [
        ("contact_radius_nm", "Hertz contact radius a (nm)", "{:.1f}"),
        ("normal_load_un", "normal load P (µN)", "{:.3f}"),
        ("contact_radius_change_dmt_percent", "DMT radius change vs Hertz (%)", "{:.1f}"),
        ("contact_radius_change_jkr_percent", "JKR radius change vs Hertz (%)", "{:.1f}"),
        (
            "contact_radius_change_maugis_dugdale_percent",
            "M–D radius change vs Hertz (%)",
            "{:.1f}",
        ),
        ("peak_lateral_force_un", "peak lateral force Q_peak (µN)", "{:.4g}"),
        ("displacement_at_peak_nm", "displacement at peak (nm)", "{:.4g}"),
        ("stick_radius_at_peak_nm", "stick radius at peak (nm)", "{:.1f}"),
        ("saturated_lateral_force_un", "gross-sliding force Q_sat (µN)", "{:.4g}"),
        ("effective_shear_strength_mpa", "eff. shear strength Q_peak/πa² (MPa)", "{:.2f}"),
        ("effective_shear_strength_rms_mpa", "  same, rms Q_peak/(√2 πa²) (MPa)", "{:.2f}"),
        ("gross_sliding_stress_mpa", "gross sliding Q_sat/πa² (MPa)", "{:.2f}"),
        ("uniform_shear_strength_mpa", "uniform τ at mean pressure (MPa)", "{:.2f}"),
        ("knee_stress_amplitude_mpa", "knee, amplitude stress (MPa)", "{:.2f}"),
        ("initial_lateral_stiffness_n_per_m", "initial lateral stiffness (N/m)", "{:.0f}"),
    ]
    rows = [r for r in rows if r[0] in records[0]]
    table = Table(title="modified Mindlin contact")
    table.add_column("quantity")
    for rec in records:
        table.add_column(f"p0 = {rec['p0_gpa']:g} GPa", justify="right")
    for key, label, fmt in rows:
        table.add_row(label, *(fmt.format(rec[key]) for rec in records))
    console.print(table)
    if exp_summary is not None:
        e = exp_summary
        console.print(
            f"experiment {e['source']} at p0 = {e['p0_gpa']:g} GPa ({e['stress_measure']} stress; collapse = "
            f"stiffness first < {e['collapse_fraction']:g} x plateau): measured collapse "
            f"{e['measured_collapse_stress_mpa']:.2f} MPa, model {e['model_collapse_stress_mpa']:.2f} MPa; "
            f"fitted tau0 = {e['fitted_tau0_mpa']:.2f} MPa"
        )
    if out is not None:
        console.print(f"wrote figures, summary.json and contact.nc to {out}")
