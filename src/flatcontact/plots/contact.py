"""Figures of the contact model (paper Figs. 4, 5 and 6-style overlays).

Every function takes result objects and returns a matplotlib Figure; saving is
the caller's business. Axis labels name the stress measure.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from matplotlib.figure import Figure

from flatcontact.contact import fit, mindlin
from flatcontact.contact.experiment import model_stiffness_at_stress
from flatcontact.contact.measured import LoadCurve, MeasuredStiffness
from flatcontact.contact.parameters import ContactParameters
from flatcontact.contact.summary import ContactAnalysis
from flatcontact.foundation import units

#: Fig. 4's default displacement as a fraction of the displacement at the peak force.
FIG4_FRACTION_OF_PEAK = 0.6


def fig4_traction(
    params: ContactParameters, p0_gpa: float = 1.0, displacement_nm: float | None = None
) -> Figure:
    """Fig. 4(a,b): τ(r), σ(r) and the full-stick q(r) at u; the stick zone (the disc r < c, or
    the annulus c_in < r < c once the centre slips, k < 0) and the slip zone.

    ``displacement_nm`` None: u = :data:`FIG4_FRACTION_OF_PEAK` × the displacement at the
    peak force, so that both zones are visible whatever the laws (a fixed u can leave the
    slip annulus invisible, or the contact fully slipping).
    """
    p0 = p0_gpa * units.GPA_TO_PA
    a = float(mindlin.contact_radius(p0, params))
    if displacement_nm is None:
        u_peak = float(mindlin.peak_force(p0, params).displacement_m)
        displacement_nm = round(FIG4_FRACTION_OF_PEAK * u_peak / units.NM_TO_M, 3)
    u = displacement_nm * units.NM_TO_M
    resp = mindlin.lateral_force(u, p0, params)
    c = float(resp.stick_radius_m)
    c_in = float(resp.stick_inner_radius_m)
    r = np.linspace(0.0, a, 600, endpoint=False)
    p = p0 * np.sqrt(1.0 - (r / a) ** 2)
    tau = mindlin.shear_strength(p, params)
    sig = mindlin.slip_friction(p, params)
    q = mindlin.full_stick_traction(r, u, a, params)
    fig = Figure(figsize=(10, 4.2), layout="constrained")
    ax, ax2 = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.6, 1]})
    rn = r / units.NM_TO_M
    mpa = units.MPA_TO_PA
    ax.plot(rn, tau / mpa, label=r"shear strength $\tau(r)=k\,p(r)+\tau_0$")
    ax.plot(rn, sig / mpa, label=r"slip friction $\sigma(r)=\mu\,p(r)+\sigma_0$")
    ax.plot(rn, q / mpa, label=rf"full-stick $q(r)$, $u$ = {displacement_nm:g} nm")
    actual = np.where((r < c) & (r > c_in), q, sig)
    ax.plot(rn, actual / mpa, "k--", lw=1, label="traction of the model")
    ax.axvspan(
        c_in / units.NM_TO_M,
        c / units.NM_TO_M,
        color="tab:red",
        alpha=0.08,
        label=f"stick, c = {c / units.NM_TO_M:.1f} nm"
        + (f", c_in = {c_in / units.NM_TO_M:.1f} nm" if c_in > 0 else ""),
    )
    ax.axvspan(c / units.NM_TO_M, a / units.NM_TO_M, color="tab:blue", alpha=0.08, label="slip")
    if c_in > 0:
        ax.axvspan(0, c_in / units.NM_TO_M, color="tab:blue", alpha=0.08)
    ymax = 1.6 * float(np.max(tau)) / mpa
    ax.set_ylim(0, ymax)
    ax.set_xlim(0, a / units.NM_TO_M)
    ax.set_xlabel("r (nm)")
    ax.set_ylabel("stress (MPa)")
    ax.set_title(f"p0 = {p0_gpa:g} GPa, a = {a / units.NM_TO_M:.1f} nm")
    ax.legend(fontsize=8, loc="upper left")
    th = np.linspace(0, 2 * np.pi, 200)
    ax2.fill(
        a * np.cos(th) / units.NM_TO_M,
        a * np.sin(th) / units.NM_TO_M,
        color="tab:blue",
        alpha=0.5,
        label="slip zone",
    )
    ax2.fill(
        c * np.cos(th) / units.NM_TO_M,
        c * np.sin(th) / units.NM_TO_M,
        color="tab:red",
        alpha=0.7,
        label="stick zone",
    )
    if c_in > 0:  # the centre slips: the stick zone is an annulus
        ring = (c_in * np.cos(th) / units.NM_TO_M, c_in * np.sin(th) / units.NM_TO_M)
        ax2.fill(*ring, color="white")
        ax2.fill(*ring, color="tab:blue", alpha=0.5)
    ax2.set_aspect("equal")
    ax2.set_xlabel("x (nm)")
    ax2.set_ylabel("y (nm)")
    ax2.legend(fontsize=8, loc="upper right")
    return fig


def fig5_force_and_stiffness(
    analysis: ContactAnalysis,
    measure: str = "amplitude",
    lockin: Sequence[Any] | None = None,
    bands: Sequence[ContactAnalysis] | None = None,
) -> Figure:
    """Fig. 5: (a) Q(u) for each p0; (b) oscillatory stiffness vs mean shear stress (``measure``).

    ``lockin``: one :class:`~flatcontact.contact.cycle.SteadyCycle` per p0
    (:func:`~flatcontact.contact.cycle.lockin_curve`); panel (b) then also shows the lock-in
    stiffness k′ = Q_amp/u′₁ (dash-dot, what a lock-in amplifier measures) next to the
    paper's d⟨Q⟩/d⟨u⟩ (solid), against the same stress measure (amplitude Q_amp/πa², rms
    Q_amp/(√2 πa²)), falling to 0 at gross sliding.

    ``bands``: the analyses at the lower and upper corner of the load laws' uncertainty box
    (same p0); Q(u) and the stiffness curve of each p0 are shaded between them.
    """
    fig = Figure(figsize=(11, 4.2), layout="constrained")
    ax, bx = fig.subplots(1, 2)
    for i, p0 in enumerate(analysis.p0_gpa):
        line = ax.plot(
            analysis.displacement_m[i] / units.NM_TO_M,
            analysis.response.lateral_force_n[i] * units.N_TO_UN,
            label=f"p0 = {p0:g} GPa",
        )[0]
        pk = analysis.peaks
        ax.plot(
            pk.displacement_m[i] / units.NM_TO_M,
            pk.force_n[i] * units.N_TO_UN,
            "o",
            color=line.get_color(),
        )
        cv = analysis.curves[i]
        if bands is not None:
            lo, hi = (b.curves[i] for b in bands)
            x_hi = hi.stress_pa(measure) / units.MPA_TO_PA
            k_lo = np.interp(
                x_hi, lo.stress_pa(measure) / units.MPA_TO_PA, lo.stiffness_n_per_m, right=0.0
            )
            bx.fill_between(
                x_hi, k_lo, hi.stiffness_n_per_m, color=line.get_color(), alpha=0.15, lw=0
            )
            ax.fill_between(
                bands[1].displacement_m[i] / units.NM_TO_M,
                np.interp(
                    bands[1].displacement_m[i],
                    bands[0].displacement_m[i],
                    bands[0].response.lateral_force_n[i],
                )
                * units.N_TO_UN,
                bands[1].response.lateral_force_n[i] * units.N_TO_UN,
                color=line.get_color(),
                alpha=0.15,
                lw=0,
            )
        bx.plot(
            cv.stress_pa(measure) / units.MPA_TO_PA,
            cv.stiffness_n_per_m,
            color=line.get_color(),
            label=f"p0 = {p0:g} GPa",
        )
        bx.plot(
            cv.knee_stress_pa(measure) / units.MPA_TO_PA,
            cv.knee_fraction * cv.initial_stiffness_n_per_m,
            "x",
            color=line.get_color(),
        )
        if lockin is not None:
            c = lockin[i]
            scale = np.pi * c.contact_radius_m**2 * (1.0 if measure == "amplitude" else np.sqrt(2))
            q = np.append(c.force_amplitude_n, c.gross_sliding_force_n)
            bx.plot(
                q / scale / units.MPA_TO_PA,
                np.append(c.lockin_stiffness_n_per_m, 0.0),
                "-.",
                color=line.get_color(),
                lw=1.0,
                label=f"lock-in Q_amp/u'₁ ({c.model}), {p0:g} GPa",
            )
    ax.set_xlabel("lateral displacement u (nm)")
    ax.set_ylabel("lateral force Q (µN)")
    ax.set_yscale("log")
    ax.set_title("(a) Q(u); dots: peak (gross sliding under load control)")
    ax.legend(fontsize=8)
    label = r"$Q_{max}/\pi a^2$" if measure == "amplitude" else r"$\langle Q\rangle/\pi a^2$"
    bx.set_xlabel(f"mean shear stress, {measure} {label} (MPa)")
    bx.set_ylabel(r"lateral stiffness $d\langle Q\rangle/d\langle u\rangle$ (N/m)")
    if bands is not None:
        ax.set_title("(a) Q(u); dots: peak; shaded: the laws' uncertainty box", fontsize=10)
    bx.set_title(
        "(b) oscillatory stiffness d⟨Q⟩/d⟨u⟩; x: knee"
        + ("; shaded: laws' uncertainty" if bands is not None else "")
        + ("\ndash-dot: lock-in Q_amp/u'₁, what a lock-in amplifier measures" if lockin else ""),
        fontsize=10 if lockin else None,
    )
    bx.legend(fontsize=8)
    return fig


def fig6_overlay(
    measured: MeasuredStiffness,
    p0_gpa: float,
    model_params: dict[str, ContactParameters],
    *,
    measure: str = "amplitude",
    measured_collapse_mpa: float | None = None,
    lockin_model: str | None = None,
) -> Figure:
    """Fig. 6 style: measured stiffness vs stress with model curves (one per labelled
    parameter set, e.g. the default τ0 and the fitted τ0); left absolute, right each
    normalised by its own low-stress value.

    The model curves are the paper's d⟨Q⟩/d⟨u⟩ (dashed). With ``lockin_model``
    ('modified' or 'classical') each parameter set also gets the lock-in stiffness
    k′ = Q_amp/u′₁ of the steady cycle (solid): the curve a lock-in measurement corresponds to.
    """
    p0 = p0_gpa * units.GPA_TO_PA
    fig = Figure(figsize=(11, 4.2), layout="constrained")
    ax, bx = fig.subplots(1, 2)
    xs = measured.stress_pa / units.MPA_TO_PA
    plateau = float(np.median(measured.stiffness_n_per_m[:3]))
    ax.plot(xs, measured.stiffness_n_per_m, "o", color="0.3", label=f"measured ({measured.source})")
    bx.plot(xs, measured.stiffness_n_per_m / plateau, "o", color="0.3", label="measured")
    top = max(float(np.max(measured.stress_pa)), 1.0)
    for name, prm in model_params.items():
        pk = float(mindlin.peak_force(p0, prm).force_n)
        a = float(mindlin.contact_radius(p0, prm))
        smax = pk / (np.pi * a**2) * (1.0 if measure == "amplitude" else 1.0 / np.sqrt(2.0))
        grid = np.concatenate(
            [
                np.linspace(0.0, smax, 300, endpoint=False),
                smax * (1 - np.logspace(-2, -8, 30)),
                [smax, max(smax, top) * 1.05],
            ]
        )
        k = model_stiffness_at_stress(grid, p0, prm, measure)
        line = ax.plot(grid / units.MPA_TO_PA, k, "--", label=f"model d⟨Q⟩/d⟨u⟩, {name}")[0]
        bx.plot(grid / units.MPA_TO_PA, k / k[0], "--", label=f"model d⟨Q⟩/d⟨u⟩, {name}")
        if lockin_model is not None:
            curve = LoadCurve(p0_gpa, grid, np.zeros_like(grid), name)
            k2 = fit.model_stiffness(curve, prm, model=lockin_model, measure=measure)
            kw = {"color": line.get_color(), "lw": 1.2}
            ax.plot(grid / units.MPA_TO_PA, k2, "-", label=f"lock-in Q_amp/u'₁, {name}", **kw)
            bx.plot(grid / units.MPA_TO_PA, k2 / k2[0], "-", label=f"lock-in, {name}", **kw)
    if measured_collapse_mpa is not None:
        for x in (ax, bx):
            x.axvline(measured_collapse_mpa, color="0.5", lw=0.8, ls=":", label="measured collapse")
    for x in (ax, bx):
        x.set_xlabel(f"mean shear stress, {measure} (MPa)")
        x.legend(fontsize=8)
    ax.set_ylabel("lateral stiffness (N/m)")
    bx.set_ylabel("stiffness / low-stress stiffness")
    ax.set_title(
        f"p0 = {p0_gpa:g} GPa"
        + ("; a lock-in measures Q_amp/u'₁ (solid)" if lockin_model is not None else "")
    )
    return fig
