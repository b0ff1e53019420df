"""Figures of the oscillation cycle: hysteresis loops, lock-in stiffness next to the paper's
d⟨Q⟩/d⟨u⟩ (Fig. 5b-style), and the multi-load fit overlay (Fig. 6-style).

Every function takes results (:mod:`flatcontact.contact.cycle`, :mod:`.fit`) and returns a
matplotlib Figure; saving is the caller's business. Stresses are amplitudes Q_amp/(π a²)
unless the axis says rms.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure

from flatcontact.contact import cycle, fit
from flatcontact.contact.measured import LoadCurve
from flatcontact.contact.parameters import ContactParameters
from flatcontact.foundation import units

_MPA = units.MPA_TO_PA


def fig_loops(
    params: ContactParameters,
    p0_gpa: Sequence[float] = (1.0, 1.77),
    fractions: Sequence[float] = (0.3, 0.6, 0.9, 0.99),
    model: str = "modified",
    n_points: int = 301,
) -> Figure:
    """Steady loops u(Q) at several amplitudes (fractions of gross sliding), one panel per p0,
    with the loading branch from rest dashed."""
    fig = Figure(figsize=(5.2 * len(p0_gpa), 4.2), layout="constrained")
    axes = np.atleast_1d(fig.subplots(1, len(p0_gpa)))
    for ax, p0 in zip(axes, p0_gpa, strict=True):
        p0_pa = p0 * units.GPA_TO_PA
        (cyc,) = cycle.cycles([p0], params, model, amplitude_fractions=fractions)
        lps = cycle.loops(cyc.force_amplitude_n, p0_pa, params, model, n_points)
        for lp, w in zip(lps, cyc.dissipated_energy_j, strict=True):
            ax.plot(
                lp.displacement_m / units.NM_TO_M,
                lp.force_n * units.N_TO_UN,
                lw=1.2,
                label=f"Q_amp = {lp.force_amplitude_n * units.N_TO_UN:.3g} µN, "
                f"W = {w * units.J_TO_FJ:.3g} fJ",
            )
        # the loading branch from rest: the first quarter cycle
        q = np.linspace(0.0, cyc.force_amplitude_n[-1], 200)
        u = cycle.CycleModel(model, p0_pa, params).amplitude_displacement(q)
        ax.plot(np.asarray(u) / units.NM_TO_M, q * units.N_TO_UN, "k--", lw=0.8, label="loading")
        ax.axhline(0, color="0.7", lw=0.5)
        ax.axvline(0, color="0.7", lw=0.5)
        ax.set_title(
            f"p0 = {p0:g} GPa, {model} model (gross sliding "
            f"{cyc.gross_sliding_force_n * units.N_TO_UN:.3g} µN)",
            fontsize=9,
        )
        ax.set_xlabel("lateral displacement u (nm)")
        ax.set_ylabel("lateral force Q (µN)")
        ax.legend(fontsize=7, loc="upper left")
    return fig


def fig_lockin_overlay(
    params: ContactParameters,
    p0_gpa: Sequence[float] = (0.5, 1.0, 1.77, 2.0, 3.0),
    model: str = "modified",
) -> Figure:
    """Fig. 5b/6 overlay: the lock-in stiffness k′ = Q_amp/u′₁ (solid) and the paper's
    d⟨Q⟩/d⟨u⟩ (dashed) against the amplitude stress, and the loss tangent u″₁/u′₁."""
    fig = Figure(figsize=(11, 4.2), layout="constrained")
    ax, bx = fig.subplots(1, 2)
    for i, p0 in enumerate(p0_gpa):
        c = cycle.lockin_curve(p0 * units.GPA_TO_PA, params, model)
        area = np.pi * c.contact_radius_m**2
        stress = np.append(c.force_amplitude_n / area / _MPA, c.gross_sliding_force_n / area / _MPA)
        color = f"C{i}"
        k_lock = np.append(c.lockin_stiffness_n_per_m, 0.0)
        k_paper = np.append(c.paper_stiffness_n_per_m, 0.0)
        ax.plot(stress, k_lock, color=color, label=f"{p0:g} GPa, lock-in Q_amp/u'₁")
        ax.plot(stress, k_paper, color=color, ls="--", lw=0.9, label=f"{p0:g} GPa, d⟨Q⟩/d⟨u⟩")
        bx.plot(stress[:-1], c.loss_tangent, color=color, label=f"{p0:g} GPa")
    ax.set_xlabel("shear stress amplitude Q_amp/πa² (MPa)")
    ax.set_ylabel("lateral stiffness (N/m)")
    ax.set_title(f"{model} model: lock-in (solid) vs the paper's construction (dashed)", fontsize=9)
    ax.legend(fontsize=6, ncol=2)
    bx.set_xlabel("shear stress amplitude Q_amp/πa² (MPa)")
    bx.set_ylabel("loss tangent u''₁/u'₁")
    bx.legend(fontsize=7)
    return fig


def fig_fit(comparison: fit.ModelComparison) -> Figure:
    """Measured curves with the fitted modified and classical models (left) and the
    residuals (right); the legend states the fitted values with their standard errors."""
    fig = Figure(figsize=(11, 4.4), layout="constrained")
    ax, bx = fig.subplots(1, 2)
    mod, cla = comparison.modified, comparison.classical
    for i, c in enumerate(mod.curves):
        color = f"C{i}"
        ax.plot(
            c.stress_pa / _MPA,
            c.stiffness_n_per_m,
            "o",
            ms=3,
            color=color,
            label=f"{c.source}, p0 = {c.p0_gpa:g} GPa",
        )
        hi = max(float(c.stress_pa.max()), 1e-9) * 1.05
        dense = LoadCurve(c.p0_gpa, np.linspace(0.0, hi, 300), np.zeros(300), c.source)
        for res, ls in ((mod, "-"), (cla, ":")):
            k = fit.model_stiffness(
                dense, res.params, model=res.model, stiffness=res.stiffness, measure=res.measure
            )
            ax.plot(dense.stress_pa / _MPA, k, ls, color=color, lw=1)
        bx.plot(c.stress_pa / _MPA, mod.residuals_n_per_m[i], "o", ms=3, color=color)
        bx.plot(c.stress_pa / _MPA, cla.residuals_n_per_m[i], "x", ms=3, color=color)

    def text(res):
        vals = res.params.as_dict()
        return ", ".join(f"{k} = {vals[k]:.4g} ± {res.standard_errors[k]:.2g}" for k in res.free)

    fig.suptitle(
        f"modified (—): {text(mod)}; AICc {mod.aicc:.1f}\nclassical (⋯): {text(cla)}; "
        f"AICc {cla.aicc:.1f}",
        fontsize=8,
    )
    ax.set_xlabel(f"mean shear stress, {mod.measure} (MPa)")
    ax.set_ylabel(f"lateral stiffness, {mod.stiffness} (N/m)")
    ax.legend(fontsize=7)
    bx.axhline(0, color="0.6", lw=0.6)
    bx.set_xlabel(f"mean shear stress, {mod.measure} (MPa)")
    bx.set_ylabel("residual model − data (N/m); o modified, x classical")
    return fig
