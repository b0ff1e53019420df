"""Figures of the asperity stage: Q(u) atoms vs model, c/a vs Q/Q_peak, traction profiles
with the laws, the slip map. Inputs: asperity.json's ``loads`` and the asperity.nc dataset."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure


def fig_force_displacement(loads: list[dict]) -> Figure:
    """Q(u) of the atoms and of the pointwise model (Hertz, measured pressure), per load."""
    fig = Figure(figsize=(6.0, 4.2))
    ax = fig.add_subplot()
    for i, load in enumerate(loads):
        c = f"C{i}"
        atoms = load["atoms"]
        u = np.asarray(atoms["displacement_angstrom"])
        ax.plot(
            u,
            np.asarray(atoms["lateral_force_n"]) * 1e9,
            "o-",
            ms=3,
            color=c,
            label=f"atoms, p0 {load['target_p0_gpa']:g} GPa",
        )
        ax.plot(
            u,
            np.asarray(load["model_hertz"]["lateral_force_n"]) * 1e9,
            "--",
            color=c,
            label="model, Hertz p",
        )
        ax.plot(
            u,
            np.asarray(load["model_measured_pressure"]["lateral_force_n"]) * 1e9,
            ":",
            color=c,
            label="model, measured p",
        )
    ax.set_xlabel("tip displacement u (Å)")
    ax.set_ylabel("lateral force Q (nN)")
    ax.legend(fontsize=7)
    return fig


def fig_stick_ratio(loads: list[dict]) -> Figure:
    """c/a against Q/Q_peak: atoms (markers) and the pointwise model (lines)."""
    fig = Figure(figsize=(5.0, 4.0))
    ax = fig.add_subplot()
    for i, load in enumerate(loads):
        c = f"C{i}"
        atoms = load["atoms"]
        x = np.asarray(atoms["q_over_q_peak"])
        # the atoms on their rising branch (the model is compared there only)
        n_rise = sum(m is not None for m in load["model_hertz"]["stick_ratio_at_atoms_q"])
        ax.plot(
            x[:n_rise],
            atoms["stick_ratio"][:n_rise],
            "o",
            ms=3,
            color=c,
            label=f"atoms, p0 {load['target_p0_gpa']:g} GPa",
        )
        for key, style, label in (
            ("stick_ratio_at_atoms_q", "--", "pointwise, Hertz p"),
            ("elastic_stick_ratio_at_atoms_q", "-.", "elastic stick zone (Cattaneo-type)"),
        ):
            model = load["model_hertz"].get(key)
            if model is None:
                continue
            pts = sorted((xi, m) for xi, m in zip(x, model, strict=True) if m is not None)
            if pts:
                ax.plot(*zip(*pts, strict=True), style, color=c, label=label)
    ax.set_xlabel("Q / Q_peak")
    ax.set_ylabel("c / a")
    ax.set_ylim(-0.05, 1.1)
    ax.legend(fontsize=7)
    return fig


def fig_tractions(load: dict) -> Figure:
    """q(x) at a few steps of one load with τ(p) and σ(p) of the laws (left, MPa), and the
    pressure p(x) (right, GPa)."""
    fig = Figure(figsize=(6.5, 4.2))
    ax = fig.add_subplot()
    ax_p = ax.twinx()
    for j, row in enumerate(load["local_traction"]):
        c = f"C{j}"
        x = np.asarray(row["bin_centre_angstrom"])
        ax_p.plot(x, row["pressure_gpa"], "-", color=c, alpha=0.35)
        ax.plot(
            x,
            np.asarray(row["shear_gpa"]) * 1e3,
            "o-",
            ms=3,
            color=c,
            label=f"q, u = {row['displacement_angstrom']:.2f} Å",
        )
    last = load["local_traction"][-1]
    x = np.asarray(last["bin_centre_angstrom"])
    ax.plot(x, np.asarray(last["tau_gpa"]) * 1e3, "k--", label="τ(p) of the laws")
    ax.plot(x, np.asarray(last["sigma_gpa"]) * 1e3, "k:", label="σ(p) of the laws")
    ax.set_xlabel("contact coordinate (Å)")
    ax.set_ylabel("shear q, τ(p), σ(p) (MPa)")
    ax_p.set_ylabel("pressure p (GPa, faint lines)")
    ax.legend(fontsize=7)
    return fig


def fig_slip_map(ds, load: int = 0) -> Figure:
    """Slip (Å) of the facing atoms against the contact coordinate and the step."""
    fig = Figure(figsize=(6.0, 4.0))
    ax = fig.add_subplot()
    slip = np.asarray(ds["slip_angstrom"].isel(load=load))
    x = np.asarray(ds["bin_centre_angstrom"])
    u = np.asarray(ds["displacement_angstrom"].isel(load=load))
    mesh = ax.pcolormesh(x, u, slip, shading="nearest", cmap="viridis", rasterized=True)
    a = np.asarray(ds["contact_half_width_angstrom"].isel(load=load))
    c = np.asarray(ds["stick_half_width_angstrom"].isel(load=load))
    for sign in (1, -1) if x.min() < 0 else (1,):
        ax.plot(sign * a, u, "w-", lw=1)
        ax.plot(sign * c, u, "r--", lw=1)
    fig.colorbar(mesh, ax=ax, label="slip (Å)")
    ax.set_xlabel("contact coordinate (Å)  [white: a, red: stick edge c]")
    ax.set_ylabel("tip displacement u (Å)")
    return fig


def fig_lockin_ramp(ramps: list[dict], p0_gpa) -> Figure:
    """The lock-in stiffness k′ against the force amplitude (the paper's Fig. 6 reading):
    atoms (markers) and the model on Hertz and on the measured pressure (lines), per load."""
    fig = Figure(figsize=(5.6, 4.0))
    ax = fig.add_subplot()
    for i, (ramp, p0) in enumerate(zip(ramps, p0_gpa, strict=True)):
        c = f"C{i}"
        rows = ramp["amplitudes"]
        qa = np.array([r["force_amplitude_n"] for r in rows]) * 1e9
        ax.plot(
            qa,
            [r["atoms_lockin_n_per_m"] for r in rows],
            "o-",
            color=c,
            label=f"atoms, p0 {p0:g} GPa",
        )
        curve = ramp.get("model_curve")
        for name, style in (("hertz", "--"), ("measured_pressure", ":")):
            key = f"model_{name}_lockin_n_per_m"
            k = [np.nan if r.get(key) is None else r[key] for r in rows]
            label = "model, " + ("Hertz p" if name == "hertz" else "measured p")
            if not np.all(np.isnan(k)):
                ax.plot(qa, k, "x", color=c)
            if curve is not None and key in curve:
                ax.plot(
                    np.asarray(curve["force_amplitude_n"]) * 1e9,
                    curve[key],
                    style,
                    color=c,
                    label=label + " (at the atoms' Q_amp/Q_peak)",
                )
    ax.set_xlabel("force amplitude Q_amp (nN)")
    ax.set_ylabel("lock-in stiffness k′ = Q_amp/u′₁ (N/m)")
    ax.legend(fontsize=7)
    return fig
