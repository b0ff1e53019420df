"""The report's section on the analyze stage: direction, energy form, τ and σ per load, Fig. 2.

Also what other sections read from ``friction.csv``: the named stackings
(:func:`stacking_rows`) and where τ(P) falls with load (:func:`monotonicity_paragraph`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from flatcontact.analysis.convergence import monotonic_violations
from flatcontact.foundation.layout import analyze_figure, png
from flatcontact.report.format import fmt, grouped_warnings
from flatcontact.report.html import Figure, Section, Table
from flatcontact.report.stacking_names import display_names

#: Where the load at each thickness comes from, by ``analysis.load_source``.
LOAD_SOURCE_TEXT = {
    "energy": "−(1/A) dU/dz of each column's energy spline (analysis.load_source = energy)",
    "stress": "the stored normal stress (analysis.load_source = stress)",
}
#: The energy zero of the maps and profiles, by ``analysis.energy_zero``.
ENERGY_ZERO_TEXT = {
    "lowest-p": "the global minimum at the lowest load analysed",
    "each": "the global minimum at each load",
    "none": "none (energies as computed, per area)",
}


def row_energies(row) -> dict[str, float]:
    """The named stackings' energies of one ``friction.csv`` row (``name=value;...``, meV/Å²)."""
    text = str(getattr(row, "stacking_energies_mev_per_a2", ""))
    if text in ("", "nan"):
        return {}
    return {k: float(v) for k, v in (item.split("=") for item in text.split(";") if "=" in item)}


def row_zero_shift(row) -> str:
    """The analysis key of the stacking at the zero shift of one ``friction.csv`` row
    (``zero_shift_stacking``; ``''`` when absent: an empty cell reads back as NaN)."""
    value = getattr(row, "zero_shift_stacking", "")
    return value if isinstance(value, str) else ""


def monotonicity_paragraph(table, family: str = "analysis") -> str:
    """Where τ(P) falls with load by more than its noise, and what limits τ on each side.

    A drop from P_i to P_i+1 counts when τ_i − τ_i+1 > √(ν_i² + ν_i+1²), ν the per-load force
    noise (``force_noise_mpa``; :func:`flatcontact.analysis.convergence.monotonic_violations`).
    For each drop the paragraph names the mechanism that sets τ at both loads (the barrier
    top of the path, a jump, or the path's end), the number of jumps and the start stacking
    (named for ``family``, :func:`flatcontact.report.stacking_names.display_names`), so a
    reader can tell a change of mechanism (the model's physics) from scatter.
    """
    if "tau_mpa" not in table or len(table) < 2:
        return ""
    noise = table["force_noise_mpa"] if "force_noise_mpa" in table else 0.0
    drops = monotonic_violations(table["p_gpa"], table["tau_mpa"], noise)
    if not drops:
        return "τ(P) does not fall with load anywhere by more than its force noise."
    by_p = {float(r.p_gpa): r for r in table.itertuples()}

    def side(p):
        r = by_p[p]
        start = getattr(r, "start_stacking", "")
        if isinstance(start, str) and start:
            names = display_names({start: 0.0} | row_energies(r), family, row_zero_shift(r))
            start = names.get(start, start)
        jumps = int(r.n_jumps) if np.isfinite(r.n_jumps) else 0
        return (
            f"{fmt(r.tau_mpa)} MPa at {p:g} GPa (limited by the {r.tau_limited_by}, {jumps} "
            f"jump{'s' if jumps != 1 else ''}{f', start {start}' if isinstance(start, str) and start else ''})"
        )

    parts = [f"from {side(d['from_p_gpa'])} to {side(d['to_p_gpa'])}" for d in drops]
    return (
        "τ(P) is not monotonic: it falls by more than its noise "
        + "; ".join(parts)
        + ". Where the limiting mechanism or the number of jumps changes between the two loads, "
        "the drop is the model's landscape changing shape with load (a different barrier or a "
        "jump along the path), not scatter; a drop with the same mechanism on both sides is "
        "tested by refining the lateral grid (docs/convergence.md)."
    )


def direction_text(cfg, table) -> str:
    """The pulling direction as run: the given angle, or auto's lowest-barrier direction."""
    if cfg.analysis.direction_deg != "auto":
        return f"{cfg.analysis.direction_deg:g}° from x"
    if "direction_deg" in table:
        angles = ", ".join(f"{v:g}°" for v in sorted(set(np.round(table["direction_deg"], 3))))
        return f"auto: the lowest-barrier direction at the lowest load, {angles} from x"
    return "auto: the lowest-barrier direction at the lowest load"


def stacking_rows(table, family: str = "analysis") -> list[tuple[str, ...]]:
    """(P, name energy, ...) rows of the named stackings (friction.csv), meV/Å² above the
    lowest, named for ``family`` (:func:`flatcontact.report.stacking_names.display_names`)."""
    if "stacking_energies_mev_per_a2" not in table:
        return []
    rows = []
    for r in table.itertuples():
        energies = row_energies(r)
        if not energies:
            continue
        names = display_names(energies, family, row_zero_shift(r))
        low = min(energies.values())
        named = ", ".join(
            f"{names[k]} {v - low:.4g}" for k, v in sorted(energies.items(), key=lambda kv: kv[1])
        )
        rows.append((f"{r.p_gpa:g}", named, fmt(getattr(r, "lowest_barrier_mev_per_a2", None))))
    return rows


def symmetry_table(symmetry: dict) -> Table:
    """Table of analyze.json's ``symmetry`` (per P: tolerance, kept operations, deviations)."""
    tolerance = next(iter(symmetry.values()), {}).get("tolerance_percent", float("nan"))
    rows = [
        (
            p,
            ", ".join(doc["kept"]) or "none",
            ", ".join(f"{name} {dev:.2g}%" for name, dev in doc["deviation_percent"].items()),
        )
        for p, doc in symmetry.items()
    ]
    return Table(
        (
            "P (GPa)",
            f"symmetry operations of the cell kept (rms change < {tolerance:g} %)",
            "rms change of every operation",
        ),
        rows,
    )


def grid_paragraphs(grid: dict | None) -> list[str]:
    """What the grid's estimate of its own error says (``analyze.json["grid"]``,
    :mod:`flatcontact.analysis.grid_error`): how it was made, the largest relative error of τ
    and, above the threshold, that the grid does not resolve τ and which grid would."""
    if not grid:
        return []
    rel = [v for v in grid.get("relative_tau_error") or [] if v is not None]
    n_a, n_b = grid["grid"]
    made = "two interpolants of the same samples (the symmetrised one and the grid's own), the "
    made += "interpolant without its outermost harmonic shell"
    if grid.get("sub_grid"):
        made += (
            f" and the {grid['sub_grid']}, Richardson-scaled by 1/(r^p − 1), r = "
            f"{grid['ratio']:.3g}, p = the convergence order (assumed {grid['assumed_order']:g}; "
            f"{grid['order_rule']})"
        )
    text = (
        f"Grid error of the {n_a}×{n_b} grid: τ, σ_MSS and G_int recomputed from {made}, with "
        "the same symmetry, start rule and direction. Per quantity the largest estimate (rms "
        f"over the loads; τ: {(grid.get('source') or {}).get('tau_mpa', 'n/a')}) is the ± grid "
        "of the table and the grid part of the laws' intervals."
    )
    if rel:
        text += f" Largest |δτ|/τ: {100 * max(rel):.3g} %."
    out = [text]
    if not grid.get("resolved", True):
        rec = grid.get("recommended_grid") or ["?", "?"]
        out.append(
            f"The {n_a}×{n_b} grid does not resolve τ: its estimated error exceeds "
            f"{100 * grid['unresolved_fraction']:g} % of τ; a grid of about {rec[0]}×{rec[1]} "
            "(scan.grid) would resolve it by the same estimate."
        )
    if grid.get("unavailable"):
        out.append(f"Not estimated: {grid['unavailable']}.")
    return out


def analysis_section(cfg, analyze: dict, table, folder: Path, family: str = "analysis") -> Section:
    """Section 3: the per-load table of ``table`` (``friction.csv`` as a DataFrame), the
    warnings (one box per kind, :func:`flatcontact.report.format.grouped_warnings`) and
    symmetry of ``analyze`` (the stage's ``analyze.json``) and Fig. 2 at
    ``report.fig2_p_gpa`` (default: the lowest, middle and highest load) from ``folder``;
    stackings named for ``family`` (:mod:`flatcontact.report.stacking_names`)."""
    ps = cfg.report.fig2_p_gpa
    if ps is None:
        allp = cfg.analysis.p_gpa
        ps = sorted({allp[0], allp[len(allp) // 2], allp[-1]})
    figs = [
        Figure(
            folder / png(analyze_figure(p)),
            f"Fig. 2 at P = {p:g} GPa: (a) constant-pressure ISPES with the sliding path (white) and "
            "the 1×2 rectangular cell (red dotted); (b) energy along the path, barriers ΔU_i "
            "(arrows); (c) force per area with the shear stiffness (dashed) and τ (circle).",
        )
        for p in ps
        if (folder / png(analyze_figure(p))).exists()
    ]
    grid_col = "tau_grid_error_mpa" in table.columns
    rows = [
        (
            fmt(r.p_gpa),
            fmt(r.tau_mpa) + (f" ± {abs(r.tau_grid_error_mpa):.2g}" if grid_col else ""),
            fmt(r.tau_period_mpa),
            fmt(r.sigma_mss_mpa),
            fmt(r.shear_stiffness_gpa_per_nm),
            str(r.tau_limited_by),
            str(r.n_jumps),
        )
        for r in table.itertuples()
    ]
    return Section(
        "3. Constant-pressure ISPES, sliding path, τ and σ",
        paragraphs=[
            f"Pulling direction {direction_text(cfg, table)}; energy form "
            f"'{cfg.analysis.energy_form}' (the paper's is 'internal'). τ is the paper's "
            "shear strength (largest force before leaving the initial minimum); τ_period is "
            "the largest force over a whole period, the pull needed for sustained sliding "
            "(always ≥ σ_MSS). The load laws use τ.",
            f"Load at each z from {LOAD_SOURCE_TEXT[analyze.get('load_source', 'stress')]}. "
            f"Energy zero of the maps and profiles: {ENERGY_ZERO_TEXT[cfg.analysis.energy_zero]}.",
            monotonicity_paragraph(table, family),
            *grid_paragraphs(analyze.get("grid")),
        ],
        notes=grouped_warnings(analyze.get("warnings", [])),
        tables=[
            Table(
                (
                    "P (GPa)",
                    "τ (MPa)" + (" ± grid" if grid_col else ""),
                    "τ_period (MPa)",
                    "σ_MSS (MPa)",
                    "G_int (GPa/nm)",
                    "τ limited by",
                    "jumps",
                ),
                rows,
            ),
            symmetry_table(analyze.get("symmetry", {})),
        ],
        figures=figs,
    )
