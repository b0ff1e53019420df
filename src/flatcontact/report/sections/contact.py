"""The report's section on the contact stage: parameters, per-p0 results, intervals, the
oscillation cycle, the multi-load fit and Figs. 4-6 (and the elastic stage's moduli)."""

from __future__ import annotations

from pathlib import Path

from flatcontact.foundation.layout import (
    FIG4_TRACTION,
    FIG5_FORCE_STIFFNESS,
    FIG5C_CYCLE_LOOPS,
    FIG6_EXPERIMENT,
    FIG6_FIT,
    FIG6_LOCKIN,
    FIG_SLIP_SIZE,
    png,
)
from flatcontact.report.format import fmt, pm
from flatcontact.report.html import Figure, Section, Table
from flatcontact.report.sections.elastic import elastic_tables


def contact_section(cfg, contact: dict, elastic: dict | None, folder: Path) -> Section:
    """Section 5: the contact parameters and their provenance, the per-p0 results of
    ``contact`` (the stage's ``summary.json``), the elastic stage's table (``elastic``: its
    ``elastic.json``, ``None`` when it did not run), the intervals, cycle and fit, and the
    figures from ``folder``."""
    params = contact["parameters"]
    prov = contact["provenance"]
    keys = [
        ("contact_radius_nm", "contact radius a (nm)"),
        ("hertz_contact_radius_nm", "Hertz contact radius (nm)"),
        ("normal_load_un", "normal load P (µN)"),
        ("contact_radius_change_dmt_percent", "DMT radius change vs Hertz (%)"),
        ("peak_lateral_force_un", "peak lateral force Q_peak (µN)"),
        ("saturated_lateral_force_un", "gross-sliding force Q_sat (µN)"),
        ("effective_shear_strength_mpa", "effective shear strength Q_peak/πa² (MPa)"),
        ("gross_sliding_stress_mpa", "gross sliding Q_sat/πa² (MPa)"),
        ("uniform_shear_strength_mpa", "τ at the mean pressure 2p0/3 (MPa)"),
        ("overshoot", "overshoot (Q_peak > Q_sat)"),
        ("knee_stress_amplitude_mpa", "stiffness knee, amplitude stress (MPa)"),
    ]
    res = contact["results"]
    keys = [k for k in keys if k[0] in res[0]]
    ct_rows = [(label, *(fmt(r[k]) for r in res)) for k, label in keys] + range_rows(contact)
    contact_figs = [
        Figure(
            folder / png(FIG4_TRACTION),
            "Fig. 4: τ(r), σ(r) and the full-stick q(r) at 60 % of the displacement at the peak "
            "force (p0 = 1 GPa, or the first p0); stick and slip zones.",
        ),
        Figure(
            folder / png(FIG5_FORCE_STIFFNESS),
            "Fig. 5: (a) Q(u) per p0 (dots: peak); (b) oscillatory stiffness vs mean shear stress (amplitude)"
            + (
                ": the paper's d⟨Q⟩/d⟨u⟩ (solid) and the lock-in stiffness Q_amp/u′₁ of the steady "
                "cycle (dash-dot), which is what a lock-in measurement corresponds to."
                if "cycle" in contact
                else "."
            ),
        ),
    ]
    notes = [
        *range_boxes(contact),
        "Where the parameters come from: "
        + "; ".join(f"{k}: {v}" for k, v in prov.items() if k != "moduli")
        + ".",
    ]
    if "slip_size" in contact:
        contact_figs.append(
            Figure(
                folder / png(FIG_SLIP_SIZE),
                "Effective shear strength against contact radius: concurrent slip (the modified "
                "Mindlin number, dashed) and the size-limited strength (solid, or the elastic "
                "bound, dotted); dots: this run's contacts (docs/contact.md).",
            )
        )
    if "experiment" in contact:
        e = contact["experiment"]
        contact_figs.append(
            Figure(
                folder / png(FIG6_EXPERIMENT),
                f"Fig. 6: measured stiffness ({e['source']}) at p0 = {e['p0_gpa']:g} GPa with the model.",
            )
        )
        notes.append(
            f"Measured collapse {e['measured_collapse_stress_mpa']:.3g} MPa, model "
            f"{e['model_collapse_stress_mpa']:.3g} MPa ({e['stress_measure']} stress); τ0 that "
            f"matches the data: {e['fitted_tau0_mpa']:.3g} MPa."
        )
    cyc_tables, cyc_figs, cyc_notes = cycle_and_fit(contact, folder)
    cyc_tables = interval_tables(contact) + cyc_tables
    notes += cyc_notes
    contact_figs += cyc_figs
    return Section(
        "5. Modified Mindlin contact",
        paragraphs=[
            f"R = {params['radius_um']:g} µm, E* = {params['contact_modulus_gpa']:g} GPa, G* = "
            f"{params['shear_modulus_gpa']:g} GPa ({prov.get('moduli')}); k = {params['k_mpa_per_gpa']:.3g} "
            f"MPa/GPa, τ0 = {params['tau0_mpa']:.3g} MPa, μ = {params['mu_mpa_per_gpa']:.3g} MPa/GPa, "
            f"σ0 = {params['sigma0_mpa']:.3g} MPa ; "
            f"w = {params['work_of_adhesion_j_per_m2']:.3g} J/m² ({prov.get('work_of_adhesion_j_per_m2')}).",
        ],
        notes=notes,
        tables=[
            Table(("quantity", *(f"p0 = {r['p0_gpa']:g} GPa" for r in res)), ct_rows),
            *elastic_tables(elastic),
            *cyc_tables,
        ],
        figures=contact_figs,
    )


def cycle_and_fit(contact: dict, folder: Path) -> tuple[list, list, list[str]]:
    """Tables, figures and notes of the oscillation cycle (``contact.cycle.enabled``) and of the
    multi-load fit (``contact.fit.csv``), from the contact stage's ``summary.json``."""
    tables, figs, notes = [], [], []
    rows = contact.get("cycle")
    if rows:
        model = rows[0]["model"]
        tables.append(
            Table(
                (
                    "p0 (GPa)",
                    "Q_amp (µN)",
                    "Q_amp/Q_gross",
                    "W per cycle (fJ)",
                    "lock-in Q_amp/u′₁ (N/m)",
                    "u″₁ (nm)",
                    "loss tangent",
                    "paper d⟨Q⟩/d⟨u⟩ (N/m)",
                ),
                [
                    (
                        fmt(r["p0_gpa"]),
                        fmt(r["lateral_force_amplitude_un"]),
                        fmt(r["amplitude_fraction_of_gross_sliding"], 3),
                        fmt(r["dissipated_energy_per_cycle_fj"]),
                        fmt(r["lockin_stiffness_n_per_m"]),
                        fmt(r["lockin_quadrature_nm"]),
                        fmt(r["loss_tangent"], 3),
                        fmt(r["paper_stiffness_n_per_m"]),
                    )
                    for r in rows
                ],
                f"Steady load-controlled cycle, {model} model (W = π·Q_amp·u″₁)",
            )
        )
        notes.append(
            "A lock-in amplifier referenced to the drive Q_amp·sin(2πνt) reads the first harmonic "
            "of u: the measured stiffness is Q_amp/u′₁ (in phase) with the loss u″₁ (quadrature), "
            "not the paper's d⟨Q⟩/d⟨u⟩, which is built from the loading quarter cycle alone. "
            + contact["conventions"].get("cycle", "")
        )
        figs.append(
            Figure(
                folder / png(FIG5C_CYCLE_LOOPS),
                f"Steady hysteresis loops u(Q) at several amplitudes ({model} model; dashed: "
                "loading from rest); the area of each loop is the energy dissipated per cycle.",
            )
        )
        figs.append(
            Figure(
                folder / png(FIG6_LOCKIN),
                "Lock-in stiffness Q_amp/u′₁ (solid; what a lock-in measures) next to the "
                "paper's d⟨Q⟩/d⟨u⟩ (dashed) against the stress amplitude, and the loss tangent.",
            )
        )
    fit = contact.get("fit")
    if fit:
        fit_rows = []
        for name in ("modified", "classical"):
            res = fit[name]
            for key in res["free"]:
                fit_rows.append(
                    (
                        name,
                        key,
                        pm(res["fitted"][key], res["standard_errors"][key]),
                        fmt(res["aicc"]),
                        fmt(res["rms_residual_n_per_m"]),
                    )
                )
        tables.append(
            Table(
                ("model", "parameter", "fitted ± standard error", "AICc", "rms residual (N/m)"),
                fit_rows,
                f"Multi-load fit of {', '.join(f['name'] for f in fit['files'])} "
                f"({fit['modified']['stiffness']} stiffness, loads "
                f"{', '.join(f'{p:g}' for p in fit['modified']['loads_gpa'])} GPa); preferred: "
                f"{fit['preferred_model']} (ΔAICc classical − modified = "
                f"{fit['delta_aicc_classical_minus_modified']:.3g})",
            )
        )
        figs.append(
            Figure(
                folder / png(FIG6_FIT),
                "Measured stiffness curves with the fitted modified (solid) and classical (dotted) "
                "models, and the residuals.",
            )
        )
    return tables, figs, notes


def _interval_cell(q: dict) -> str:
    """``value [low, high]`` and, when the laws' parts are carried, ``(fit ±…, conv. ±…,
    models ±…)``: the half-range of the quantity over the box of each part alone."""
    text = f"{q['value']:.3g} [{q['low']:.3g}, {q['high']:.3g}]"
    parts = q.get("components")
    if parts:
        short = {"fit": "fit", "convergence": "conv.", "models": "models", "grid": "grid"}
        text += (
            " ("
            + ", ".join(f"{short.get(p, p)} ±{(hi - lo) / 2:.2g}" for p, (lo, hi) in parts.items())
            + ")"
        )
    return text


def interval_tables(contact: dict) -> list:
    """The contact outputs with the laws' uncertainty carried through (``summary.json``
    ``intervals``), when any law coefficient has a nonzero half-width."""
    iv = contact.get("intervals") or {}
    if not iv.get("results") or not any(iv.get("half_widths", {}).values()):
        return []
    labels = {
        "effective_shear_strength_mpa": "effective shear strength Q_peak/πa² (MPa)",
        "collapse_stress_mpa": "collapse stress, amplitude (MPa)",
        "knee_stress_amplitude_mpa": "stiffness knee, amplitude (MPa)",
    }
    rows = [
        (label, *(_interval_cell(r[key]) for r in iv["results"])) for key, label in labels.items()
    ]
    hw = ", ".join(f"{k} ± {v:.2g}" for k, v in iv["half_widths"].items() if v)
    if iv.get("component_half_widths"):
        hw += (
            "; in parentheses the half-range over the box of each part alone: fit, "
            "convergence, models, grid"
        )
    return [
        Table(
            ("quantity", *(f"p0 = {r['p0_gpa']:g} GPa" for r in iv["results"])),
            rows,
            f"Contact outputs over the laws' intervals ({hw}; every corner of the box)",
        )
    ]


def range_boxes(contact: dict) -> list[str]:
    """The boxes above the contact numbers: the adhesion regime, configured moduli of
    another material or potential, and one sentence per p0 whose contact radius exceeds the
    critical size of concurrent slip (:mod:`flatcontact.stages.contact_range`)."""
    from flatcontact.contact.slip_size import slip_sentences

    out = []
    if "adhesion_regime" in contact:
        out.append("Contact regime: " + contact["adhesion_regime"]["sentence"] + ".")
    if contact.get("moduli_note"):
        out.append(contact["moduli_note"] + ".")
    return out + slip_sentences(contact.get("slip_size"))


def range_rows(contact: dict) -> list[tuple]:
    """Rows of the per-p0 table: pull-off/load, the regime, the critical size and the
    size-limited strength beside the concurrent one."""
    rows = []
    adh = (contact.get("adhesion_regime") or {}).get("results")
    if adh:
        rows.append(("adhesion regime", *(r["regime"] for r in adh)))
        rows.append(("pull-off force / load", *(fmt(r["pull_off_over_load"]) for r in adh)))
    slip = contact.get("slip_size")
    if slip:
        crit = (
            "critical radius a_c (nm)"
            if slip["structure"] == "commensurate"
            else ("elastic bound of superlubricity a_el (nm)")
        )
        res = slip["results"]
        rows.append((crit, *(fmt(r["critical_radius_nm"]) for r in res)))
        rows.append(
            (
                "size-limited strength (MPa)",
                *(
                    "—"
                    if r["size_limited_strength_mpa"] is None
                    else fmt(r["size_limited_strength_mpa"])
                    for r in res
                ),
            )
        )
        rows.append(("strength reported (contact.slip_regime)", *(r["reported"] for r in res)))
    return rows


def slip_note(contact: dict, i: int) -> str:
    """A short note for the concurrent-slip Q_peak/πa² of the i-th p0 wherever it appears
    (never silent past the critical size): '' within it."""
    rows = (contact.get("slip_size") or {}).get("results") or []
    if i >= len(rows) or not rows[i]["exceeded"]:
        return ""
    r = rows[i]
    if r["size_limited_strength_mpa"] is None:
        return f" (concurrent slip; a > a_el = {r['critical_radius_nm']:.3g} nm: a lower bound)"
    return (
        f" (concurrent slip; a > a_c = {r['critical_radius_nm']:.3g} nm: size-limited ≈ "
        f"{r['size_limited_strength_mpa']:.4g})"
    )
