"""The report's section on the laws stage: the load laws in both energy forms and Fig. 3."""

from __future__ import annotations

from pathlib import Path

from flatcontact.foundation.layout import LAWS_FIGURE, png
from flatcontact.foundation.reference import PAPER
from flatcontact.report.format import LAW_COEFFICIENTS, fmt, grouped_warnings, pm
from flatcontact.report.html import Figure, Section, Table

#: The header of the paper's column in the laws table (quartz runs only).
PAPER_COLUMN = "paper (internal)"
#: Which energy form is the lateral force at constant load, and why the paper's differs.
ENERGY_FORMS_PARAGRAPH = (
    "Which form is the lateral force at constant load: the enthalpy form. At a fixed normal "
    "load P the slabs sit at the gap z*(x, y; P) that makes h = U/A + P·z stationary in z, so by "
    "the envelope theorem the lateral gradient of h at constant P equals the lateral force "
    "∇U at fixed z — the force an atomistic simulation or an instrument at constant load "
    "measures. The paper's internal form Ũ(x, y)|_P = U(x, y, z*) leaves out the work P·A·Δz* "
    "done against the load when the gap rises and falls along the path: ∇Ũ|_P = ∇U|_z − "
    "P·∇z*. Both agree at P = 0 and differ by the load times the gap corrugation, which grows "
    "with P; that is why the paper's slopes k and μ are small and the enthalpy form's are "
    "larger, by up to an order of magnitude. The contact model uses the configured form "
    "(analysis.energy_form)."
)


#: The parts of a coefficient's uncertainty as laws.json names them (``intervals.<c>.components``).
COMPONENT_NAMES = ("fit", "convergence", "models", "grid")


def _has_components(form_doc: dict) -> bool:
    """Does this form's ``intervals`` carry a part beside the fit (a study's block, the grid)?"""
    return any(
        (iv.get("components") or {}).get(p)
        for iv in (form_doc.get("intervals") or {}).values()
        for p in COMPONENT_NAMES[1:]
    )


def _part(value) -> str:
    return "n/a" if value is None else f"{value:.3g}"


def laws_tables(laws: dict, paper: bool = False) -> list:
    """The laws of both energy forms side by side, each coefficient with its standard error
    and its interval (fit, convergence and model spread), and what the interval is made of;
    with the paper's column only when ``paper`` (the run's slabs are the paper's α-quartz)."""
    forms = [f for f in ("internal", "enthalpy") if isinstance(laws.get(f), dict)]
    if not forms:
        return []
    configured = laws.get("energy_form")
    split = {f: _has_components(laws[f]) for f in forms}
    rows = []
    for key, err, label in LAW_COEFFICIENTS:
        row = [label]
        for form in forms:
            d = laws[form]
            iv = d.get("intervals", {}).get(key)
            row.append(pm(d.get(key), d.get(err)))
            row.append(f"[{iv['low']:.3g}, {iv['high']:.3g}]" if iv else "n/a")
            if split[form]:
                parts = (iv or {}).get("components") or {}
                row.append(" / ".join(_part(parts.get(p, 0.0)) for p in COMPONENT_NAMES))
        if paper:
            row.append(f"{PAPER[key]:g}")
        rows.append(tuple(row))
    header = ["coefficient"]
    for form in forms:
        tag = f"{form}{' (used)' if form == configured else ''}"
        header += [f"{tag} ± s.e.", f"{form} interval"]
        if split[form]:
            header.append(f"{form}: fit / convergence / models / grid")
    if paper:
        header.append(PAPER_COLUMN)
    u = laws.get("uncertainty", {})
    parts = "fit standard error"
    if any(u.get(f"convergence_{f}") for f in forms):
        parts += ", convergence"
    if any(u.get(f"model_spread_{f}") for f in forms):
        parts += ", model spread"
    if any(split.values()):
        parts += ", grid (the run's own estimate, section 3)"
    caption = (
        f"Load laws in both energy forms; intervals: coefficient ± {u.get('coverage', 1):g} × "
        f"the combined standard error ({parts}, in quadrature)"
        + (
            "; the fit / convergence / models / grid columns are the parts before the coverage "
            "multiple (coefficient units; n/a: not estimated)"
            if any(split.values())
            else ""
        )
        + (f"; {u['source']}" if u.get("source") else "")
    )
    return [Table(tuple(header), rows, caption)]


def laws_section(laws: dict, folder: Path, paper: bool = False) -> Section:
    """Section 4: the laws of ``laws`` (the stage's ``laws.json``) with their standard
    errors, the range they hold in, both energy forms side by side and Fig. 3 from ``folder``;
    the paper's laws beside them only when ``paper`` (:func:`laws_tables`)."""
    section = Section(
        "4. Load laws",
        paragraphs=[
            f"τ = ({pm(laws.get('k_mpa_per_gpa'), laws.get('k_stderr_mpa_per_gpa'))}) MPa/GPa · P + "
            f"({pm(laws.get('tau0_mpa'), laws.get('tau0_stderr_mpa'))}) MPa; "
            f"σ = ({pm(laws.get('mu_mpa_per_gpa'), laws.get('mu_stderr_mpa_per_gpa'))}) MPa/GPa · P + "
            f"({pm(laws.get('sigma0_mpa'), laws.get('sigma0_stderr_mpa'))}) MPa, fitted on P ≤ "
            f"{fmt(laws.get('p_max_gpa'))} GPa (± one standard error). τ linear up to "
            f"{fmt(laws.get('tau_linear_until_gpa'))} GPa, σ up to {fmt(laws.get('sigma_linear_until_gpa'))} GPa.",
        ],
        notes=grouped_warnings(laws.get("warnings", [])),
        tables=laws_tables(laws, paper),
        figures=[
            Figure(
                folder / png(LAWS_FIGURE),
                "Fig. 3: τ and σ against P with the linear fits"
                + (
                    " and their bands over the coefficient intervals of the table "
                    "(every corner of the box of slope and intercept)."
                    if any(
                        (laws.get(laws.get("energy_form", ""), {}) or {})
                        .get("half_widths", {})
                        .values()
                    )
                    else "."
                ),
            )
        ],
    )
    if laws.get("internal") and laws.get("enthalpy"):
        section.paragraphs.append(ENERGY_FORMS_PARAGRAPH)
    return section
