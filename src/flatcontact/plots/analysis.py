"""Figures of the ISPES analysis: the paper's Fig. 2 (per load) and Fig. 3 (load laws).

Fig. 2: (a) the constant-pressure ISPES (meV/Å²) around the path, with the
path (white; jumps dashed) and the rectangular supercell (red dotted);
(b) the energy profile along the path with each barrier ΔU_i marked by an
arrow; (c) the force profile as a stress (MPa) with the initial slope (shear
stiffness, dashed) and τ (red circle).
Fig. 3: τ and σ against P with their linear fits over the fitted range.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from flatcontact.analysis.analyze import AnalysisResult, PressureAnalysis
from flatcontact.analysis.laws import LoadLaws
from flatcontact.analysis.uncertainty import propagate_box
from flatcontact.foundation import units

MEV = units.EV_PER_A2_TO_MEV_PER_A2


def figure_pressure(pa: PressureAnalysis, result: AnalysisResult) -> Figure:
    """The three panels of Fig. 2 at one load."""
    fig = Figure(figsize=(15, 4.4))
    axes = fig.subplots(1, 3)
    surf, path, fr = pa.surface, pa.path, pa.friction
    xy = path.xy_angstrom
    r0 = pa.minimum_xy_angstrom
    corners = [xy]
    if result.supercell is not None:
        u, v = result.supercell
        rect = np.array([r0, r0 + u, r0 + u + v, r0 + v, r0])
        corners.append(rect)
    pts = np.vstack(corners)
    pad = 0.15 * max(np.linalg.norm(surf.a1), np.linalg.norm(surf.a2))
    lo, hi = pts.min(0) - pad, pts.max(0) + pad
    gx, gy = np.linspace(lo[0], hi[0], 160), np.linspace(lo[1], hi[1], 160)
    mx, my = np.meshgrid(gx, gy)
    z = surf(np.stack([mx, my], -1)) * MEV
    ax = axes[0]
    # the map is an image: one raster inside the vector file (axes, path and text stay vector);
    # 160x160 cells drawn as paths made each SVG 4.9 MB
    im = ax.pcolormesh(mx, my, z, shading="auto", cmap="viridis", rasterized=True)
    fig.colorbar(im, ax=ax, label="energy (meV/Å²)")
    for b in np.unique(path.branch):
        sel = path.branch == b
        ax.plot(xy[sel, 0], xy[sel, 1], color="white", lw=2)
    for j in path.jumps:
        ax.plot([j.xy_before[0], j.xy_after[0]], [j.xy_before[1], j.xy_after[1]], "w--", lw=1)
    if result.supercell is not None:
        ax.plot(rect[:, 0], rect[:, 1], "r:", lw=1.5, label="1×2 rectangular cell")
        ax.legend(loc="upper right", fontsize=8)
    if pa.mep is not None:
        ax.plot(
            pa.mep.xy_angstrom[:, 0], pa.mep.xy_angstrom[:, 1], color="orange", lw=1, label="MEP"
        )
    ax.set_aspect("equal")
    ax.set_xlabel("x (Å)")
    ax.set_ylabel("y (Å)")
    ax.set_title(f"(a) constant-P ISPES, P = {pa.p_gpa:g} GPa ({result.form})")

    t = path.t_angstrom
    ax = axes[1]
    ax.plot(t, path.energy * MEV, "k-")
    for b in fr.barriers:
        ax.annotate(
            "",
            xy=(b.t_max_angstrom, b.energy_max * MEV),
            xytext=(b.t_max_angstrom, b.energy_min * MEV),
            arrowprops={"arrowstyle": "->", "color": "red"},
        )
    ax.set_xlabel(f"displacement along {result.direction_deg:g}° (Å)")
    ax.set_ylabel("energy (meV/Å²)")
    ax.set_title(f"(b) energy profile, σ = {fr.sigma_mss_mpa:.3g} MPa")

    ax = axes[2]
    f = path.force * units.EV_PER_A3_TO_MPA
    ax.plot(t, f, "k-")
    g = fr.shear_stiffness_ev_per_a4 * units.EV_PER_A3_TO_MPA  # MPa per Å
    t_lin = np.linspace(0, min(fr.tau_position_angstrom * 1.5 + 1e-9, t[-1]), 20)
    ax.plot(t_lin, g * t_lin, "b--", label=f"G = {fr.shear_stiffness_gpa_per_nm:.3g} GPa/nm")
    ax.plot(
        [fr.tau_position_angstrom],
        [fr.tau_mpa],
        "o",
        mfc="none",
        mec="red",
        ms=10,
        label=f"τ = {fr.tau_mpa:.3g} MPa",
    )
    ax.axhline(0, color="grey", lw=0.5)
    ax.set_ylim(f.min() * 1.15 - 1e-12, max(f.max(), fr.tau_mpa) * 1.15 + 1e-12)
    ax.set_xlabel(f"displacement along {result.direction_deg:g}° (Å)")
    ax.set_ylabel("force / area (MPa)")
    ax.set_title("(c) force profile")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig


def law_band(
    p_gpa, slope: float, intercept: float, slope_half_width: float, intercept_half_width: float
) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper edge of the law c(P) = slope·P + intercept over the box of its
    coefficients (each ± its half-width), at every P: the extremes are at the box corners
    (:func:`flatcontact.analysis.uncertainty.propagate_box`, exact for a linear law)."""
    p = np.asarray(p_gpa, dtype=float)
    box = propagate_box(
        lambda x: {i: x["s"] * pi + x["c"] for i, pi in enumerate(p)},
        {"s": slope, "c": intercept},
        {"s": slope_half_width, "c": intercept_half_width},
    )
    return np.array([box[i][0] for i in range(p.size)]), np.array(
        [box[i][2] for i in range(p.size)]
    )


def figure_laws(
    p_gpa, tau_mpa, sigma_mss_mpa, laws: LoadLaws, half_widths: dict | None = None
) -> Figure:
    """Fig. 3: τ and σ vs P (one value per load, GPa and MPa) with the linear fits ``laws``;
    with ``half_widths`` (coefficient -> half-width, ``laws.json``) the band of each law over
    its coefficient box (fit, convergence and model spread)."""
    fig = Figure(figsize=(5.5, 4.2))
    ax = fig.subplots()
    p = np.asarray(p_gpa, dtype=float)
    hw = half_widths or {}
    for y, law, style, label, keys in (
        (tau_mpa, laws.tau, "o", "τ", ("k_mpa_per_gpa", "tau0_mpa")),
        (sigma_mss_mpa, laws.sigma, "s", "σ", ("mu_mpa_per_gpa", "sigma0_mpa")),
    ):
        line = ax.plot(p, np.asarray(y, dtype=float), style, label=label)[0]
        if law is not None:
            pf = np.linspace(min(0.0, p.min()), law.p_max_gpa, 50)
            ax.plot(
                pf,
                law(pf),
                "-",
                color=line.get_color(),
                label=f"{label} = {law.slope:.3g}·P + {law.intercept:.3g}",
            )
            hs, hc = (float(hw.get(k) or 0.0) for k in keys)
            if hs > 0 or hc > 0:
                lo, hi = law_band(pf, law.slope, law.intercept, hs, hc)
                ax.fill_between(
                    pf,
                    lo,
                    hi,
                    color=line.get_color(),
                    alpha=0.18,
                    lw=0,
                    label=f"{label} band (±{hs:.2g}·P ± {hc:.2g})",
                )
            if p.max() > law.p_max_gpa:
                pe = np.linspace(law.p_max_gpa, p.max(), 20)
                ax.plot(pe, law(pe), ":", color=line.get_color())
    ax.set_xlabel("P (GPa)")
    ax.set_ylabel("stress (MPa)")
    ax.set_title(f"load laws (fit P ≤ {laws.threshold_gpa:g} GPa)")
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig
