"""The report's section of the asperity stage: the verdict sentence, atoms against the model
per load, sizes and cost, the figures (``asperity.json``; docs/asperity.md)."""

from __future__ import annotations

from pathlib import Path

from flatcontact.layout import (
    FIG_ASPERITY_FORCE,
    FIG_ASPERITY_SLIP,
    FIG_ASPERITY_STICK,
    FIG_ASPERITY_TRACTIONS,
    png,
)
from flatcontact.report.format import fmt
from flatcontact.report.html import Figure, Section, Table


def asperity_section(doc: dict, folder: Path) -> Section:
    """The verdict first (whether the contact stage's numbers hold at this size, by how much
    they differ), then per load Q_peak and Q_peak/area of the atoms and of the model on Hertz
    and on the measured pressure, and the atoms' and Hertz's half-widths."""
    rows = []
    for load in doc.get("loads", []):
        at, mh, mm = load["atoms"], load["model_hertz"], load["model_measured_pressure"]
        ratios = load["ratios_atoms_over_model"]
        rows.append(
            (
                fmt(load["target_p0_gpa"]),
                fmt(at["peak_lateral_force_n"] * 1e9),
                fmt(mh["peak_lateral_force_n"] * 1e9),
                fmt(mm["peak_lateral_force_n"] * 1e9),
                fmt(ratios["peak_lateral_force_hertz"]),
                fmt(at["peak_shear_stress_mpa"]),
                fmt(at["contact_half_width_angstrom"]),
                fmt(mh["half_width_angstrom"]),
                fmt(at["initial_stiffness_n_per_m"]),
            )
        )
    size = doc["sizes"]
    paragraphs = [
        doc["verdict"],
        f"{doc['geometry']} of R = {fmt(doc['radius_angstrom'])} Å, {doc['n_atoms']:,} atoms "
        f"({size['repeats'][0]} × {size['repeats'][1]} cells, {size['flat_layers']} planes in "
        f"the flat), E* = {fmt(doc['contact_modulus_gpa'])} GPa, {fmt(doc['wall_seconds'])} s; "
        f"finite size a/depth = {fmt(doc['finite_size']['a_over_depth'])}, "
        f"2a/period = {fmt(doc['finite_size']['contact_width_over_period'])}.",
    ]
    table = Table(
        (
            "p0 (GPa)",
            "Q_peak atoms (nN)",
            "model, Hertz p (nN)",
            "model, measured p (nN)",
            "atoms/model (Hertz)",
            "Q_peak/area atoms (MPa)",
            "a atoms (Å)",
            "a Hertz (Å)",
            "K0 atoms (N/m)",
        ),
        rows,
    )
    figures = [
        Figure(folder / png(stem), caption)
        for stem, caption in (
            (FIG_ASPERITY_FORCE, "Q(u): atoms and the model (stiffness matched once)"),
            (FIG_ASPERITY_STICK, "stick-zone size c/a against Q/Q_peak"),
            (FIG_ASPERITY_TRACTIONS, "tractions along the contact with τ(p) and σ(p)"),
            (FIG_ASPERITY_SLIP, "slip of facing atoms along the contact, per step"),
        )
        if (folder / png(stem)).exists()
    ]
    notes = list(doc.get("warnings", []))
    return Section("The asperity in atoms", paragraphs, [table], figures, notes)


#: The columns of docs/asperity.md's measured table (:func:`measured_row`).
MEASURED_HEADERS = (
    "case",
    "R (nm)",
    "atoms",
    "a atoms / Hertz (Å)",
    "Q_peak atoms (nN)",
    "model, Hertz p (nN)",
    "model, measured p (nN)",
    "atoms / Hertz",
    "atoms / measured p",
    "Q_peak/2a atoms (MPa)",
    "c/a at Q ≥ Q_peak/2: atoms / model",
    "K0 atoms (N/m)",
    "wall (s)",
)


def measured_row(case: str, doc: dict, wall_seconds: float) -> tuple[str, ...]:
    """One row of docs/asperity.md's measured table from an ``asperity.json`` (first load)."""
    load = doc["loads"][0]
    at, mh, mm = load["atoms"], load["model_hertz"], load["model_measured_pressure"]
    ratios = load["ratios_atoms_over_model"]
    half = next(
        (k for k, f in enumerate(at["q_over_q_peak"]) if f >= 0.5), len(at["q_over_q_peak"]) - 1
    )
    model_c = mh["stick_ratio_at_atoms_q"][half]
    peak = fmt(at["peak_lateral_force_n"] * 1e9) + ("" if at["peak_reached"] else " (≥)")
    return (
        case,
        fmt(doc["radius_angstrom"] / 10),
        f"{doc['n_atoms']:,}",
        f"{fmt(at['contact_half_width_angstrom'])} / {fmt(mh['half_width_angstrom'])}",
        peak,
        fmt(mh["peak_lateral_force_n"] * 1e9),
        fmt(mm["peak_lateral_force_n"] * 1e9),
        fmt(ratios["peak_lateral_force_hertz"]),
        fmt(ratios["peak_lateral_force_measured_pressure"]),
        fmt(at["peak_shear_stress_mpa"]),
        f"{at['stick_ratio'][half]:.2f} / " + ("–" if model_c is None else f"{model_c:.2f}"),
        fmt(at["initial_stiffness_n_per_m"]),
        f"{wall_seconds:.0f}",
    )


def markdown_table(rows) -> str:
    """The rows under :data:`MEASURED_HEADERS` as a Markdown table."""
    lines = ["| " + " | ".join(MEASURED_HEADERS) + " |", "|" + "---|" * len(MEASURED_HEADERS)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)
