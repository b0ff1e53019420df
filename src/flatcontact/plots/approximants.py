"""Figure of an approximant study: τ0 and the ISPES corrugation against the cell's atoms.

Two log-log panels (τ0 in MPa, corrugation = max − min of the constant-pressure ISPES at
the lowest load in meV/Å²) over the cells of ``study.json``; each panel draws the fitted
power law ``y = c·N^−α`` and, when fitted, ``y = y∞ + c·N^−α``, and states the exponent and
the extrapolated limit with their intervals, or why a model was refused
(:mod:`flatcontact.studies.scaling`). Values ≤ 0 cannot be drawn on a log axis: they are
named in the panel, not dropped silently; a cell whose corrugation is not resolved above the
noise floor (the round-off, or for a relaxed scan the relaxation floor when it is larger) is
drawn as an open triangle and left out of the fits.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

#: study.json cell key -> (panel title, axis label)
PANELS = {
    "tau0_mpa": ("τ0 (law intercept)", "τ0 (MPa)"),
    "barrier_mev_per_a2": ("ISPES corrugation at the lowest load", "corrugation (meV/Å²)"),
}


def _fit_text(fit: dict, unit: str) -> str:
    lines = []
    for key, name in (("power_law", "c·N^−α"), ("offset_power_law", "y∞ + c·N^−α")):
        f = fit.get(key, {})
        if "refused" in f:
            lines.append(f"{name}: not fitted ({f['refused']})")
            continue
        text = f"{name}: α = {f['exponent']:.3g} ± {f['exponent_half_width']:.2g}"
        if key == "offset_power_law":
            text += f", y∞ = {f['limit']:.3g} ± {f['limit_half_width']:.2g} {unit}"
        else:
            text += ", y∞ = 0 (assumed)"
        lines.append(text)
    cov = next((f["coverage"] for f in fit.values() if "coverage" in f), 0.95)
    lines.append(f"(intervals: {100 * cov:g} % from the fit covariance)")
    return "\n".join(lines)


def figure_approximants(doc: dict) -> Figure:
    """τ0 and the corrugation of every cell of the study ``doc`` against atoms (log-log)."""
    cells = [c for c in doc["cells"] if "error" not in c]
    fig = Figure(figsize=(9.0, 4.0), layout="constrained")
    axes = fig.subplots(1, len(PANELS))
    for ax, (key, (title, label)) in zip(axes, PANELS.items(), strict=True):
        n = np.array([c["n_atoms"] for c in cells], float)
        y = np.array([c[key] for c in cells], float)
        resolved = np.array([bool(c.get("resolved", True)) for c in cells], bool)
        drawable = np.isfinite(y) & (y > 0)
        good = drawable & resolved
        ax.loglog(n[good], y[good], "o", color="C0", label="cells")
        if np.any(drawable & ~resolved):
            ax.loglog(
                n[drawable & ~resolved],
                y[drawable & ~resolved],
                "v",
                mfc="none",
                color="C3",
                label="unresolved (< 10× noise floor): upper bound",
            )
        for c, ok in zip(cells, good, strict=True):
            if ok:
                ax.annotate(
                    f"{c['twist_deg']:.2f}°",
                    (c["n_atoms"], c[key]),
                    fontsize=7,
                    xytext=(3, 3),
                    textcoords="offset points",
                )
        fit = doc["scaling"][key]
        if good.sum() >= 2:
            grid = np.geomspace(n[good].min(), n[good].max() * 1.5, 50)
            pl = fit["power_law"]
            if "refused" not in pl:
                ax.loglog(
                    grid,
                    pl["prefactor"] * grid ** -pl["exponent"],
                    "-",
                    color="C1",
                    lw=1,
                    label="c·N^−α",
                )
            op = fit["offset_power_law"]
            if "refused" not in op:
                yy = op["limit"] + op["prefactor"] * grid ** -op["exponent"]
                keep = yy > 0
                ax.loglog(grid[keep], yy[keep], "--", color="C2", lw=1, label="y∞ + c·N^−α")
        bad = [c["label"] for c, ok in zip(cells, drawable, strict=True) if not ok]
        note = _fit_text(fit, label.split("(")[-1].rstrip(")"))
        if bad:
            note += f"\nnot drawn (≤ 0 or NaN): {', '.join(bad)}"
        if fit.get("gated"):
            note += "\nleft out of the fit (gates fired): " + ", ".join(fit["gated"])
        ax.text(0.02, 0.02, note, transform=ax.transAxes, fontsize=6.5, va="bottom")
        ax.set_xlabel("atoms in the cell")
        ax.set_ylabel(label)
        ax.set_title(title, fontsize=9)
        ax.legend(fontsize=7, loc="upper right")
    fig.suptitle(f"Approximant cells ({doc.get('relax_mode', '')}): size scaling", fontsize=10)
    return fig
