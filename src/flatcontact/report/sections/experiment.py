"""The report's section on the paper's experiment: the run's interface against the measured
stiffness collapse (``contact.experiment.compare``).

Every number comes from the contact stage's ``summary.json`` (``experiment_comparison``,
:func:`flatcontact.stages.contact.experiment_comparison`) and the build stage's
``build.json`` (the coincidence lock and its strain); nothing is computed here.
"""

from __future__ import annotations

from flatcontact.report.format import fmt
from flatcontact.report.html import Section, Table

#: Why a computed collapse differs from the measured one, whatever the numbers.
READINGS = (
    "The measured contact is a tip of radius 5 µm on an ensemble of nano-asperities; the model "
    "is one ideal Hertz contact with the run's laws everywhere in it.",
    "A commensurate lock (the sheet strained onto the tip's cell, or an aligned AB stack) puts "
    "every atom of the interface in the same registry, so its corrugation, τ0 and k are those "
    "of the best-matched contact: an upper bound for the incommensurate contact of a real tip "
    "on graphene, whose corrugation falls with the contact's size (structural superlubricity).",
    "The laws are those of one interaction model and one cell: another model gives another "
    "corrugation (for AB bilayer graphene KC's saddle barrier is 1.66× ILP's, "
    "examples/README.md).",
    "In the model the collapse stress depends on p0 and the laws alone: E*, G* and R cancel "
    "out of Q/(π a²), so the choice of the counter-body's moduli does not move it.",
)


def lock_text(build: dict | None) -> str:
    """The coincidence lock of the run's interface from ``build.json`` (strain per slab, in
    %), or what the interface is when there is none."""
    rec = (build or {}).get("recipe")
    if not isinstance(rec, dict):
        return "no coincidence lock (one material)"
    match = rec.get("match") or {}
    if match.get("kind") == "twist":
        return (
            f"commensurate twist θ = {float(rec.get('twist_angle_deg', float('nan'))):.4f}°, "
            f"{match.get('n_atoms', '?')} atoms, no strain (an approximant of the twisted "
            "contact, not a lock in one registry)"
        )
    if match.get("kind") != "coincidence":
        return "commensurate by construction (no coincidence match)"
    strains = [
        f"slab {i} {', '.join(f'{v:+.3g}' for v in match.get(f'slab{i}_strain_percent', []))} %"
        for i in (1, 2)
        if any(abs(v) > 1e-9 for v in match.get(f"slab{i}_strain_percent", []))
    ]
    return (
        f"commensurate lock {match.get('slab1_supercell')} on {match.get('slab2_supercell')}, "
        f"{match.get('n_atoms', '?')} atoms, strain " + ("; ".join(strains) if strains else "none")
    )


def comparison_rows(comparison: dict) -> list[tuple[str, ...]]:
    """Rows (contact, τ0, k, collapse stress, /measured per contact) of ``comparison``
    (``summary.json["experiment_comparison"]``): the run, the quartz laws, the measurements."""
    measured = comparison["measured_mpa"]
    rows = []
    for row in (comparison["run"], *comparison["references"]):
        rows.append(
            (
                row["label"] + (" (this run)" if row is comparison["run"] else ""),
                fmt(row["tau0_mpa"]),
                fmt(row["k_mpa_per_gpa"]),
                fmt(row["collapse_stress_mpa"]),
                *(f"{row['ratio_to_measured'][k]:.3g}" for k in measured),
            )
        )
    for name, value in measured.items():
        rows.append((f"measured: {name}", "", "", fmt(value), *("" for _ in measured)))
    return rows


def experiment_section(contact: dict, build: dict | None = None) -> Section | None:
    """The run against the paper's experiment (``summary.json`` of the contact stage,
    ``build.json``), or None when the run does not say it models the experiment."""
    comparison = contact.get("experiment_comparison")
    if not comparison:
        return None
    measured = comparison["measured_mpa"]
    run = comparison["run"]
    p0, p1 = comparison["p0_gpa"], comparison.get("contact_p0_gpa", comparison["p0_gpa"])
    radius = (
        f"the Hertz radius is {fmt(run['contact_radius_nm'])} nm"
        if p1 == p0
        else f"the adhesive contact radius is {fmt(run['contact_radius_nm'])} nm (the model at "
        f"its peak pressure p1 = {p1:.4g} GPa, as in the contact section)"
    )
    return Section(
        "The experiment's interface: collapse stress against the measurement",
        paragraphs=[
            f"The paper's oscillatory-shear experiment: a diamond tip (R = 5 µm) at p0 = "
            f"{comparison['p0_gpa']:g} GPa, lateral stiffness collapsing near "
            + " and ".join(f"{v:g} MPa ({k})" for k, v in measured.items())
            + f". Model criterion: {comparison['criterion']}. This run's interface: "
            f"{run['label']}; {lock_text(build)}. At p0 = {p0:g} GPa {radius} with the run's "
            "E*, G*, R.",
        ],
        notes=["Why the numbers can differ: " + " ".join(READINGS)],
        tables=[
            Table(
                (
                    "contact (laws)",
                    "τ0 (MPa)",
                    "k (MPa/GPa)",
                    f"collapse stress at p0 = {comparison['p0_gpa']:g} GPa (MPa)",
                    *(f"÷ measured {k}" for k in measured),
                ),
                comparison_rows(comparison),
                "Collapse stress (k < "
                f"{comparison['collapse_fraction']:g}·k0, amplitude Q_max/πa², load control): "
                "this run, the quartz laws with the same contact model, and the measurements",
            )
        ],
    )
