"""Figures of a study (:mod:`flatcontact.studies`): each quantity against the refined setting.

One figure per quantity (τ, σ_MSS per load, W); one panel per refined setting (convergence:
x = the setting's value, base included) or one panel over the models (models study: x = the
model). Lines are loads. The variants are the ``study.json`` records.
"""

from __future__ import annotations

import math

from matplotlib.figure import Figure

#: quantity -> axis label
QUANTITY_LABELS = {
    "tau_mpa": "τ (MPa)",
    "sigma_mss_mpa": "σ_MSS (MPa)",
    "work_of_separation_j_per_m2": "W (J/m²)",
}


def _value(variant: dict, quantity: str, p_gpa: float | None) -> float:
    if p_gpa is None:
        return float(variant[quantity])
    for row in variant["loads"]:
        if abs(row["p_gpa"] - p_gpa) < 1e-9:
            return float(row[quantity])
    return math.nan


def figure_study(doc: dict, quantity: str) -> Figure:
    """``quantity`` of every variant of the study ``doc`` against its setting (module docstring)."""
    variants = doc["variants"]
    per_load = quantity != "work_of_separation_j_per_m2"
    loads = [row["p_gpa"] for row in variants[0]["loads"]] if per_load else [None]
    if doc["study"] == "convergence":
        panels = list(doc["settings"]) or ["base"]
    else:
        panels = ["model"]
    fig = Figure(figsize=(3.6 * len(panels), 3.2), layout="constrained")
    axes = fig.subplots(1, len(panels), squeeze=False)[0]
    for ax, setting in zip(axes, panels, strict=True):
        if setting == "model":
            members = variants
            xs = list(range(len(members)))
            ax.set_xticks(xs, [v["label"] for v in members], rotation=30, fontsize=7)
            ax.set_xlabel("model")
        else:
            members = [v for v in variants if v["setting"] in ("base", setting)]
            members.sort(key=lambda v: v["level"])
            xs = [v["values"].get(setting, math.nan) for v in members]
            state = doc["settings"].get(setting, {}).get("state", "")
            ax.set_xlabel(f"{setting} ({state})")
            if setting == "fmax":
                ax.set_xscale("log")
        for p in loads:
            ys = [_value(v, quantity, p) for v in members]
            ax.plot(xs, ys, "o-", ms=3, label=f"{p:g} GPa" if p is not None else None)
        ax.set_ylabel(QUANTITY_LABELS[quantity])
    if per_load:
        axes[-1].legend(fontsize=6, title="load", title_fontsize=6)
    return fig
