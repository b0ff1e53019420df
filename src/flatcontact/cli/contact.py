"""``flatcontact contact``: the continuum contact model (Hertz, adhesion, modified Mindlin).

Thin: its flags are the run settings' ``contact`` section and ``report.svg``, one per
setting, derived from the settings by :mod:`flatcontact.cli.options` (k, τ0, μ, σ0 default
to the paper's, :mod:`flatcontact.foundation.reference`); it runs
the contact stage (:func:`flatcontact.stages.contact.contact_stage`, the one ``flatcontact run``
runs) and prints a rich table or JSON; with ``--out`` the stage writes its figures,
``summary.json`` and ``contact.nc`` there.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Annotated

import typer

from flatcontact.cli.app import app, check_out_dir, console
from flatcontact.cli.options import flags_of, setting_options, settings_command
from flatcontact.foundation.reference import DEFAULT_P0_GPA, PAPER, PAPER_LAW_KEYS

#: The settings the command exposes, one flag each (:mod:`flatcontact.cli.options`).
PATHS = (
    "contact.p0_gpa",
    "contact.radius_um",
    "contact.contact_modulus_gpa",
    "contact.shear_modulus_gpa",
    *(f"contact.{key}" for key in PAPER_LAW_KEYS),
    "contact.work_of_adhesion_j_per_m2",
    "contact.maugis_lambda",
    "contact.equilibrium_separation_angstrom",
    "contact.contact_radius",
    "contact.slip_regime",
    "contact.knee_fraction",
    "contact.collapse_fraction",
    "contact.cycle.enabled",
    "contact.cycle.model",
    "contact.cycle.amplitude_fractions",
    "contact.cycle.amplitudes_un",
    "contact.fit.csv",
    "contact.fit.p0_gpa",
    "contact.fit.free",
    "contact.fit.fixed",
    "contact.fit.stiffness",
    "contact.experiment.csv",
    "contact.experiment.p0_gpa",
    "contact.experiment.stress_measure",
    "report.svg",
)
#: Where the command's default is not the setting's: its loads, and the paper's laws (a run
#: fits them; this command has none to fit).
DEFAULTS = {
    "contact.p0_gpa": list(DEFAULT_P0_GPA),
    **{f"contact.{key}": PAPER[key] for key in PAPER_LAW_KEYS},
}
OPTIONS = setting_options(PATHS, DEFAULTS)
#: Settings path -> flag, to name the flag in errors.
FLAG_OF = flags_of(OPTIONS)


@app.command("contact")
@settings_command(OPTIONS)
def contact_command(
    settings: dict,
    johnson: Annotated[
        bool,
        typer.Option(
            "--johnson-shear-modulus",
            help="Read --shear-modulus-gpa as Johnson's G*_J (converted: G* = 4 G*_J).",
        ),
    ] = False,
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
    out: Annotated[
        Path | None,
        typer.Option("--out", help="Directory for figures, summary.json and contact.nc."),
    ] = None,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print the per-p0 results as JSON.")
    ] = False,
) -> None:
    """Hertz + adhesion + modified Mindlin: Q(u), peak and gross-sliding forces, oscillatory stiffness."""
    from flatcontact.cli.settings import flag_errors, settings_from_flags
    from flatcontact.config import merge_config
    from flatcontact.contact.moduli import paper_shear_modulus_from_johnson
    from flatcontact.stages.contact import ContactInputs, contact_stage

    defaults: dict = {"contact": {}}
    for path, value in DEFAULTS.items():
        defaults["contact"][path.removeprefix("contact.")] = value
    data = merge_config(defaults, settings)
    if johnson:
        g = data["contact"].get("shear_modulus_gpa", PAPER["shear_modulus_gpa"])
        data["contact"]["shear_modulus_gpa"] = float(paper_shear_modulus_from_johnson(g))
    cfg = settings_from_flags(data, FLAG_OF)
    if out is not None:
        check_out_dir(out)
    with flag_errors(FLAG_OF):
        result = contact_stage(
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
    from flatcontact.foundation.errors import InputError

    kinds = (COMMENSURATE, TWISTED, APPROXIMANT)
    if structure not in kinds:
        raise InputError(f"--structure: expected one of {', '.join(kinds)}, got {structure!r}")
    from flatcontact.cli.app import bounded
    from flatcontact.foundation.numbers import Bounds

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
