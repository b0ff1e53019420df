"""Effective shear strength against contact radius: concurrent and size-limited slip.

From the contact stage's ``summary.json["slip_size"]`` (:mod:`flatcontact.contact.slip_size`),
so the figure can be redrawn from the file alone.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from flatcontact.contact.slip_size import COMMENSURATE, dislocation_strength

#: Contact radii drawn (m): 1 nm to 10 µm.
RADII_M = np.geomspace(1e-9, 1e-5, 300)


def fig_slip_size(doc: dict) -> Figure:
    """Q_peak/πa² of concurrent slip (dashed, the modified Mindlin number of each p0, which
    does not depend on a at fixed p0) and the size-limited strength (solid): for a
    commensurate interface min(τ_c, τ_dis(a)), τ_dis = √(8 G* γ_us/(π a)); for a twisted or
    approximant cell the elastic bound a_el (dotted), beyond which the concurrent number is
    a lower bound. Dots: the contact of each p0 (its radius, the strength reported)."""
    fig = Figure(figsize=(6.4, 4.4), layout="constrained")
    ax = fig.subplots()
    g = doc["shear_modulus_gpa"] * 1e9
    gus = doc.get("unstable_stacking_j_per_m2")
    commensurate = doc["structure"] == COMMENSURATE
    x = RADII_M * 1e9
    for row in doc["results"]:
        tau_c = row["concurrent_strength_mpa"]
        line = ax.plot(x, np.full(x.shape, tau_c), "--", lw=1.0)[0]
        colour = line.get_color()
        label = f"p0 = {row['p0_gpa']:g} GPa"
        if commensurate and gus:
            limited = np.minimum(tau_c, dislocation_strength(RADII_M, g, gus) * 1e-6)
            ax.plot(x, limited, "-", color=colour, label=label)
        else:
            ax.axvline(row["critical_radius_nm"], ls=":", color=colour, label=label)
        ax.plot(row["contact_radius_nm"], row["reported_strength_mpa"], "o", color=colour)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("contact radius a (nm)")
    ax.set_ylabel("effective shear strength Q_peak/πa² (MPa)")
    what = (
        "dislocation-assisted slip above a_c (solid), concurrent slip (dashed)"
        if commensurate
        else f"{doc['structure']} cell: elastic bound a_el (dotted); concurrent (dashed)"
    )
    ax.set_title(what, fontsize=9)
    ax.legend(fontsize=8)
    return fig
