"""``flatcontact contact``: the continuum contact model (Hertz, adhesion, modified Mindlin).

Thin: maps the flags (named by quantity and unit) to the run settings' ``contact`` section
(k, τ0, μ, σ0 default to the paper's, :mod:`flatcontact.reference`) and ``report.svg``, runs
the contact stage (:func:`flatcontact.stages.contact.run_contact`, the one ``flatcontact run``
runs) and prints a rich table or JSON; with ``--out`` the stage writes its figures,
``summary.json`` and ``contact.nc`` there.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

from flatcontact.cli.app import app, check_out_dir, console, parse_floats, split_list
from flatcontact.reference import DEFAULT_P0_GPA, PAPER, PAPER_EXPERIMENT_P0_GPA

_DEFAULT_HELP = "(default: the paper's value)"
#: Settings paths -> the flag that sets them, to name it in errors.
_FLAG_OF = {
    f"contact.{name}": "--" + name.replace("_", "-")
    for name in (
        "p0_gpa",
        "radius_um",
        "contact_modulus_gpa",
        "shear_modulus_gpa",
        "k_mpa_per_gpa",
        "tau0_mpa",
        "mu_mpa_per_gpa",
        "sigma0_mpa",
        "work_of_adhesion_j_per_m2",
        "maugis_lambda",
        "equilibrium_separation_angstrom",
        "contact_radius",
        "slip_regime",
        "knee_fraction",
        "collapse_fraction",
    )
} | {
    "contact.experiment.csv": "--experiment",
    "contact.experiment.p0_gpa": "--experiment-p0-gpa",
    "contact.experiment.stress_measure": "--experiment-stress-measure",
    "report.svg": "--svg",
    "contact.cycle.enabled": "--cycle",
    "contact.cycle.model": "--model",
    "contact.cycle.amplitude_fractions": "--cycle-amplitude-fractions",
    "contact.cycle.amplitudes_un": "--cycle-amplitude-un",
    "contact.fit.csv": "--fit",
    "contact.fit.p0_gpa": "--fit-p0-gpa",
    "contact.fit.free": "--fit-free",
    "contact.fit.fixed": "--fit-fixed",
    "contact.fit.stiffness": "--fit-stiffness",
}


def _parse_p0(values: list[str] | None) -> list[float]:
    from flatcontact.contact.parameters import check_p0_gpa

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
            help="Peak Hertz pressure(s) p0 in GPa; repeat or comma-separate. Default "
            + ",".join(f"{p:g}" for p in DEFAULT_P0_GPA)
            + ".",
        ),
    ] = None,
    radius_um: Annotated[
        float, typer.Option("--radius-um", help=f"Tip radius R (µm) {_DEFAULT_HELP}.")
    ] = PAPER["radius_um"],
    contact_modulus_gpa: Annotated[
        float,
        typer.Option(
            "--contact-modulus-gpa", help=f"Hertz contact modulus E* (GPa) {_DEFAULT_HELP}."
        ),
    ] = PAPER["contact_modulus_gpa"],
    shear_modulus_gpa: Annotated[
        float,
        typer.Option(
            "--shear-modulus-gpa",
            help="Effective shear modulus G* (GPa) in the paper's convention q0 = G*·u/(πa) "
            f"(= 4× Johnson's G*_J); default {PAPER['shear_modulus_gpa']:g}.",
        ),
    ] = PAPER["shear_modulus_gpa"],
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
            help="k in τ = k·p + τ0 (MPa/GPa; may be < 0, then p0 < τ0/|k|); default "
            f"{PAPER['k_mpa_per_gpa']:g}.",
        ),
    ] = PAPER["k_mpa_per_gpa"],
    tau0_mpa: Annotated[
        float,
        typer.Option(
            "--tau0-mpa", help=f"τ0 in τ = k·p + τ0 (MPa); default {PAPER['tau0_mpa']:g}."
        ),
    ] = PAPER["tau0_mpa"],
    mu_mpa_per_gpa: Annotated[
        float,
        typer.Option(
            "--mu-mpa-per-gpa",
            help="μ in σ = μ·p + σ0 (MPa/GPa; may be < 0, then p0 <= σ0/|μ|); default "
            f"{PAPER['mu_mpa_per_gpa']:g}.",
        ),
    ] = PAPER["mu_mpa_per_gpa"],
    sigma0_mpa: Annotated[
        float,
        typer.Option(
            "--sigma0-mpa", help=f"σ0 in σ = μ·p + σ0 (MPa); default {PAPER['sigma0_mpa']:g}."
        ),
    ] = PAPER["sigma0_mpa"],
    work_of_adhesion_j_per_m2: Annotated[
        float | None,
        typer.Option(
            "--work-of-adhesion-j-per-m2",
            help="Work of adhesion w (J/m²): adds DMT/JKR radii and their change vs Hertz.",
        ),
    ] = None,
    maugis_lambda: Annotated[
        float | None,
        typer.Option(
            "--maugis-lambda", help="Maugis parameter λ: adds the Maugis–Dugdale radius (needs w)."
        ),
    ] = None,
    equilibrium_separation_angstrom: Annotated[
        float | None,
        typer.Option(
            "--equilibrium-separation-angstrom",
            help="Equilibrium separation z0 (Å) of the interface for the Tabor parameter "
            "(default: 3 Å assumed, and said so).",
        ),
    ] = None,
    contact_radius: Annotated[
        str,
        typer.Option(
            "--contact-radius",
            help="adhesive: the radius of the regime the Tabor parameter names (DMT, "
            "Maugis–Dugdale, JKR) in Q_peak/πa² and the model; hertz: the paper's.",
        ),
    ] = "adhesive",
    unstable_stacking_mj_per_m2: Annotated[
        float | None,
        typer.Option(
            "--unstable-stacking-mj-per-m2",
            help="Barrier γ_us of the γ-surface along the sliding path (mJ/m²): reports the "
            "critical contact radius of concurrent slip (commensurate interfaces).",
        ),
    ] = None,
    burgers_angstrom: Annotated[
        float | None,
        typer.Option(
            "--burgers-angstrom",
            help="Burgers vector b (Å): the shift-lattice period along the sliding direction "
            "(the elastic bound of superlubricity of twisted/approximant cells).",
        ),
    ] = None,
    structure: Annotated[
        str,
        typer.Option(
            "--structure", help="commensurate, twisted or approximant (which size limit)."
        ),
    ] = "commensurate",
    slip_regime: Annotated[
        str,
        typer.Option(
            "--slip-regime",
            help="auto (the size-limited strength past the critical size), concurrent or "
            "size-limited.",
        ),
    ] = "auto",
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
            "--experiment-p0-gpa",
            help=f"p0 (GPa) of the measured data; default {PAPER_EXPERIMENT_P0_GPA:g} (the paper's).",
        ),
    ] = PAPER_EXPERIMENT_P0_GPA,
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
    cycle: Annotated[
        bool,
        typer.Option(
            "--cycle",
            help="Steady oscillation cycle per p0: loops, dissipated energy per cycle, lock-in "
            "stiffness Q_amp/u'_1 and quadrature u''_1 (JSON 'cycle' rows, contact.nc loops, "
            "lock-in curve in Fig. 5b/6).",
        ),
    ] = False,
    model: Annotated[
        str,
        typer.Option(
            "--model",
            help="Model of the cycle: 'modified' (the paper's Mindlin model) or 'classical' "
            "(Cattaneo–Mindlin, friction coefficient μ = k·1e-3, Johnson's G*_J = G*/4 with G* "
            "in the paper's convention).",
        ),
    ] = "modified",
    cycle_amplitude_fractions: Annotated[
        list[str] | None,
        typer.Option(
            "--cycle-amplitude-fractions",
            help="Force amplitudes of the cycle as fractions of gross sliding, each in (0, 1); "
            "default 0.2,0.4,0.6,0.8,0.9,0.95.",
        ),
    ] = None,
    cycle_amplitude_un: Annotated[
        list[str] | None,
        typer.Option(
            "--cycle-amplitude-un",
            help="Force amplitudes of the cycle in µN (below gross sliding at every p0); "
            "replaces --cycle-amplitude-fractions.",
        ),
    ] = None,
    fit_files: Annotated[
        list[str] | None,
        typer.Option(
            "--fit",
            help="Measured stiffness CSV(s) to fit at several loads at once (repeat or "
            "comma-separate; one file per load with --fit-p0-gpa, or files with a load column "
            "'p0 [GPa]'/'normal load [uN]'): fit.json and fig6_fit with --out.",
        ),
    ] = None,
    fit_p0_gpa: Annotated[
        list[str] | None,
        typer.Option("--fit-p0-gpa", help="p0 (GPa) of each --fit file without a load column."),
    ] = None,
    fit_free: Annotated[
        list[str] | None,
        typer.Option(
            "--fit-free",
            help="Parameters the fit frees (tau0_mpa, k_mpa_per_gpa, mu_mpa_per_gpa, "
            "sigma0_mpa, shear_modulus_gpa); default tau0_mpa.",
        ),
    ] = None,
    fit_fixed: Annotated[
        list[str] | None,
        typer.Option("--fit-fixed", help="Parameters the fit must hold at their values."),
    ] = None,
    fit_stiffness: Annotated[
        str,
        typer.Option(
            "--fit-stiffness",
            help="Model stiffness compared with the data: 'lockin' (Q_amp/u'_1) or 'paper' "
            "(d<Q>/d<u>).",
        ),
    ] = "lockin",
    out: Annotated[
        Path | None,
        typer.Option("--out", help="Directory for figures, summary.json and contact.nc."),
    ] = None,
    svg: Annotated[bool, typer.Option("--svg/--no-svg", help="Also write SVG figures.")] = True,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the per-p0 results as JSON.")
    ] = False,
) -> None:
    """Hertz + adhesion + modified Mindlin: Q(u), peak and gross-sliding forces, oscillatory stiffness."""
    from flatcontact.cli.settings import flag_errors, settings_from_flags
    from flatcontact.contact.moduli import paper_shear_modulus_from_johnson
    from flatcontact.stages.contact import ContactInputs, run_contact

    p0_list = _parse_p0(p0_gpa)
    g = float(paper_shear_modulus_from_johnson(shear_modulus_gpa)) if johnson else shear_modulus_gpa
    contact = {
        "p0_gpa": p0_list,
        "radius_um": radius_um,
        "contact_modulus_gpa": contact_modulus_gpa,
        "shear_modulus_gpa": g,
        "k_mpa_per_gpa": k_mpa_per_gpa,
        "tau0_mpa": tau0_mpa,
        "mu_mpa_per_gpa": mu_mpa_per_gpa,
        "sigma0_mpa": sigma0_mpa,
        "work_of_adhesion_j_per_m2": work_of_adhesion_j_per_m2,
        "maugis_lambda": maugis_lambda,
        "equilibrium_separation_angstrom": equilibrium_separation_angstrom,
        "contact_radius": contact_radius,
        "slip_regime": slip_regime,
        "knee_fraction": knee_fraction,
        "collapse_fraction": collapse_fraction,
        "experiment": {
            "csv": str(experiment) if experiment is not None else None,
            "p0_gpa": experiment_p0_gpa,
            "stress_measure": experiment_stress_measure,
        },
        "cycle": {"enabled": cycle, "model": model},
        "fit": {"stiffness": fit_stiffness},
    }
    if cycle_amplitude_fractions:
        contact["cycle"]["amplitude_fractions"] = parse_floats(
            cycle_amplitude_fractions, "--cycle-amplitude-fractions"
        )
    if cycle_amplitude_un:
        contact["cycle"]["amplitudes_un"] = parse_floats(
            cycle_amplitude_un, "--cycle-amplitude-un", "µN"
        )
    if fit_files:
        contact["fit"]["csv"] = split_list(fit_files, "--fit", whitespace=False)
    if fit_p0_gpa:
        contact["fit"]["p0_gpa"] = parse_floats(fit_p0_gpa, "--fit-p0-gpa", "GPa")
    if fit_free:
        contact["fit"]["free"] = split_list(fit_free, "--fit-free")
    if fit_fixed:
        contact["fit"]["fixed"] = split_list(fit_fixed, "--fit-fixed")
    cfg = settings_from_flags({"contact": contact, "report": {"svg": svg}}, _FLAG_OF)
    if out is not None:
        check_out_dir(out)
    with flag_errors(_FLAG_OF):
        result = run_contact(
            cfg,
            ContactInputs(
                interface=_given_interface(unstable_stacking_mj_per_m2, burgers_angstrom, structure)
            ),
            out,
        )
    doc = result.to_json()
    if as_json:
        typer.echo(json.dumps(doc, indent=2))
        return
    _print_table(doc["results"], doc.get("experiment"), out)
    _print_range(doc)
    if "cycle" in doc:
        _print_cycle(doc["cycle"])
    if "fit" in doc:
        _print_fit(doc["fit"])


def _print_cycle(rows) -> None:
    from rich.table import Table

    table = Table(title=f"steady cycle ({rows[0]['model']} model); lock-in k' = Q_amp/u'_1")
    cols = [
        ("p0_gpa", "p0 (GPa)", "{:g}"),
        ("lateral_force_amplitude_un", "Q_amp (µN)", "{:.4g}"),
        ("amplitude_fraction_of_gross_sliding", "Q_amp/Q_gross", "{:.3g}"),
        ("dissipated_energy_per_cycle_fj", "W per cycle (fJ)", "{:.4g}"),
        ("lockin_stiffness_n_per_m", "lock-in k' (N/m)", "{:.0f}"),
        ("lockin_quadrature_nm", "u''_1 (nm)", "{:.4g}"),
        ("loss_tangent", "tan δ", "{:.3g}"),
        ("paper_stiffness_n_per_m", "d<Q>/d<u> (N/m)", "{:.0f}"),
    ]
    for _, label, _ in cols:
        table.add_column(label, justify="right")
    for row in rows:
        table.add_row(*(fmt.format(row[key]) for key, _, fmt in cols))
    console.print(table)


def _print_fit(doc) -> None:
    for name in ("modified", "classical"):
        res = doc[name]
        vals = ", ".join(
            f"{k} = {res['fitted'][k]:.4g} ± {res['standard_errors'][k]:.2g}" for k in res["free"]
        )
        console.print(
            f"fit ({name}, {res['stiffness']} stiffness, {res['n_points']} points at "
            f"{len(res['loads_gpa'])} loads): {vals}; AICc {res['aicc']:.1f}"
        )
    console.print(
        f"preferred model: {doc['preferred_model']} (ΔAICc classical − modified = "
        f"{doc['delta_aicc_classical_minus_modified']:.1f})"
    )


def _print_table(records, exp_summary, out) -> None:
    from rich.table import Table

    rows = [
        ("contact_radius_nm", "contact radius a (nm)", "{:.1f}"),
        ("hertz_contact_radius_nm", "Hertz contact radius (nm)", "{:.1f}"),
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


def _given_interface(unstable_stacking_mj_per_m2, burgers_angstrom, structure) -> dict | None:
    """The contact's range facts from the flags (``ContactInputs.interface``); None when
    neither γ_us nor b is given (no size limit is computed)."""
    from flatcontact.contact.slip_size import APPROXIMANT, COMMENSURATE, TWISTED
    from flatcontact.errors import InputError

    kinds = (COMMENSURATE, TWISTED, APPROXIMANT)
    if structure not in kinds:
        raise InputError(f"--structure: expected one of {', '.join(kinds)}, got {structure!r}")
    from flatcontact.cli.app import bounded
    from flatcontact.numbers import Bounds

    for flag, value, bounds in (
        ("--unstable-stacking-mj-per-m2", unstable_stacking_mj_per_m2, Bounds(1e-3, 1e4, "mJ/m²")),
        ("--burgers-angstrom", burgers_angstrom, Bounds(0.1, 100.0, "Å")),
    ):
        if value is not None:
            bounded(value, flag, bounds)
    if unstable_stacking_mj_per_m2 is None and burgers_angstrom is None:
        return None
    path = {"source": "given on the command line"}
    if unstable_stacking_mj_per_m2 is not None:
        path["unstable_stacking_j_per_m2"] = unstable_stacking_mj_per_m2 * 1e-3
    if burgers_angstrom is not None:
        path["burgers_angstrom"] = burgers_angstrom
    return {"structure": structure, "path": path}


def _print_range(doc) -> None:
    """The contact's range: the adhesion regime, and the critical size of concurrent slip."""
    from flatcontact.contact.slip_size import slip_sentences

    if "adhesion_regime" in doc:
        console.print(doc["adhesion_regime"]["sentence"])
    slip = doc.get("slip_size")
    if slip:
        name = (
            "critical radius a_c" if slip["structure"] == "commensurate" else "elastic bound a_el"
        )
        sizes = ", ".join(
            f"{r['p0_gpa']:g} GPa: a = {r['contact_radius_nm']:.4g} nm, {name} = "
            f"{r['critical_radius_nm']:.3g} nm"
            for r in slip["results"]
        )
        console.print(f"{slip['structure']} interface ({slip['estimate']}): {sizes}")
    for line in slip_sentences(slip):
        console.print(line)
