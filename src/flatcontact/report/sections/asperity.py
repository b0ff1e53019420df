"""The report's section of the asperity stage: the verdict sentence, atoms against the model
per load, sizes and cost, the figures (``asperity.json``; docs/asperity.md)."""

from __future__ import annotations

from pathlib import Path

from flatcontact.foundation.layout import (
    FIG_ASPERITY_FORCE,
    FIG_ASPERITY_RAMP,
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
            (FIG_ASPERITY_RAMP, "lock-in stiffness k′ against the force amplitude (Fig. 6)"),
        )
        if (folder / png(stem)).exists()
    ]
    notes = list(doc.get("warnings", []))
    tables = [table]
    if doc.get("ramp"):
        paragraphs.append(ramp_sentence(doc))
        tables.append(ramp_table(doc))
    return Section("The asperity in atoms", paragraphs, tables, figures, notes)


def _opt(value) -> str:
    return "–" if value is None else fmt(value)


def ramp_table(doc: dict) -> Table:
    """Per load and amplitude: the atoms' lock-in stiffness k′ = Q_amp/u′₁ and loss tangent,
    the model's k′ (Hertz and measured pressure) at the same Q_amp/Q_peak, the ratios."""
    rows = []
    for p0, ramp in zip(doc["target_p0_gpa"], doc["ramp"], strict=True):
        for r in ramp["amplitudes"]:
            rows.append(
                (
                    fmt(p0),
                    fmt(r["displacement_amplitude_angstrom"]),
                    fmt(r["force_amplitude_n"] * 1e9),
                    _opt(r["q_amp_over_q_peak"]),
                    fmt(r["atoms_lockin_n_per_m"]),
                    fmt(r["atoms_loss_tangent"]),
                    _opt(r.get("model_hertz_lockin_n_per_m")),
                    _opt(r.get("model_measured_pressure_lockin_n_per_m")),
                    _opt(r.get("ratio_atoms_over_model_hertz")),
                )
            )
    return Table(
        (
            "p0 (GPa)",
            "U (Å)",
            "Q_amp (nN)",
            "Q_amp/Q_peak",
            "k′ atoms (N/m)",
            "loss tangent atoms",
            "k′ model, Hertz p (N/m)",
            "k′ model, measured p (N/m)",
            "atoms/model (Hertz)",
        ),
        rows,
    )


def ramp_sentence(doc: dict) -> str:
    """How much the atoms' lock-in stiffness falls over the ramp, against the model's."""
    rows = doc["ramp"][0]["amplitudes"]
    first, last = rows[0], rows[-1]
    atoms = last["atoms_lockin_n_per_m"] / first["atoms_lockin_n_per_m"]
    text = (
        f"Amplitude ramp (first load): the atoms' lock-in stiffness falls to {atoms:.2f} of its "
        f"value at U = {fmt(first['displacement_amplitude_angstrom'])} Å by "
        f"U = {fmt(last['displacement_amplitude_angstrom'])} Å"
    )
    m0, m1 = first.get("model_hertz_lockin_n_per_m"), last.get("model_hertz_lockin_n_per_m")
    if m0 and m1:
        text += f"; the model's (Hertz p, same Q_amp/Q_peak) to {m1 / m0:.2f}"
    return text + " (k′ = Q_amp/u′₁, the first harmonic a lock-in reads)."


#: The columns of docs/asperity.md's measured table (:func:`measured_row`).
MEASURED_HEADERS = (
    "case",
    "geometry",
    "R (nm)",
    "atoms",
    "a atoms / Hertz (Å)",
    "Q_peak atoms (nN)",
    "model, Hertz p (nN)",
    "model, measured p (nN)",
    "atoms / Hertz",
    "atoms / measured p",
    "Q_peak/area atoms (MPa)",
    "c/a at Q ≥ Q_peak/2: atoms / model",
    "K0 atoms (N/m)",
    "k′(U)/k′(U₁), U₁→U (Å): atoms / model",
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
        doc["geometry"],
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
        _ramp_cell(doc),
        f"{wall_seconds:.0f}",
    )


def _ramp_cell(doc: dict) -> str:
    """The first load's ramp: k′(Uₙ)/k′(U₁) of the atoms / of the model (Hertz p, same
    Q_amp/Q_peak), Uₙ the largest amplitude where the model has a steady cycle; "–" without
    a ramp."""
    if not doc.get("ramp"):
        return "–"
    rows = doc["ramp"][0]["amplitudes"]
    key = "model_hertz_lockin_n_per_m"
    with_model = [r for r in rows if r.get(key) is not None]
    last = with_model[-1] if len(with_model) > 1 else rows[-1]
    first = rows[0]
    atoms = last["atoms_lockin_n_per_m"] / first["atoms_lockin_n_per_m"]
    model = (
        "–" if first.get(key) is None or last.get(key) is None else f"{last[key] / first[key]:.3f}"
    )
    return (
        f"{fmt(first['displacement_amplitude_angstrom'])}→"
        f"{fmt(last['displacement_amplitude_angstrom'])}: {atoms:.3f} / {model}"
    )


def markdown_table(rows) -> str:
    """The rows under :data:`MEASURED_HEADERS` as a Markdown table."""
    lines = ["| " + " | ".join(MEASURED_HEADERS) + " |", "|" + "---|" * len(MEASURED_HEADERS)]
    lines += ["| " + " | ".join(r) + " |" for r in rows]
    return "\n".join(lines)
