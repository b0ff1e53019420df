"""Figure of the scan stage: p(z) and U(z) of every lateral point (``fig_scan_columns``)."""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from flatcontact.foundation import units


def figure_scan_columns(ds, adhesion: dict | None = None):
    """Normal load p(z) and energy U(z) of every lateral point of the ISPES grid.

    Each thin line is one lateral shift; p rises as z falls on the repulsive branch.
    """
    fig = Figure(figsize=(11, 4.2))
    ax, bx = fig.subplots(1, 2)
    z = ds["thickness"].values
    p = ds["normal_stress"].values.reshape(-1, z.size)
    e = ds["energy"].values.reshape(-1, z.size)
    area = float(ds.attrs["area"])
    e_min = np.nanmin(e)
    for k in range(p.shape[0]):
        ax.plot(z, p[k], color="tab:blue", lw=0.6, alpha=0.5)
        bx.plot(
            z,
            (e[k] - e_min) / area * units.EV_PER_A2_TO_MEV_PER_A2,
            color="tab:red",
            lw=0.6,
            alpha=0.5,
        )
    ax.axhline(0, color="grey", lw=0.6)
    ax.set_xlabel("thickness z, surface 1 to 4 (Å)")
    ax.set_ylabel("normal load p (GPa, + = compression)")
    ax.set_title(f"(a) p(z) at all {p.shape[0]} lateral shifts")
    if adhesion and "equilibrium_thickness_angstrom" in adhesion:
        ax.axvline(
            adhesion["equilibrium_thickness_angstrom"],
            color="k",
            ls=":",
            lw=0.8,
            label="p = 0 at the probe stacking",
        )
        ax.legend(fontsize=8)
    bx.set_xlabel("thickness z (Å)")
    bx.set_ylabel("U − min U (meV/Å²)")
    bx.set_title("(b) energy per area U(z)")
    fig.tight_layout()
    return fig
