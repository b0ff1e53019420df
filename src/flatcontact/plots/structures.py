"""Fig. 1 style picture of an interface: side view (x–z) and top view of the inner face of slab 1.

Drawn by the build stage (``01-build/fig1_interface``) and ``flatcontact build``.
"""

from __future__ import annotations

import numpy as np
from ase.data import atomic_numbers, covalent_radii
from matplotlib.figure import Figure
from matplotlib.patches import Circle


def _draw_atoms(
    ax, xy: np.ndarray, symbols, depth: np.ndarray, palette: dict, scale: float
) -> None:
    """Atoms as circles in data units (covalent radius × ``scale``), far ones drawn first."""
    for i in np.argsort(depth):
        r = scale * covalent_radii[atomic_numbers[symbols[i]]]
        ax.add_patch(
            Circle(xy[i], r, facecolor=palette.get(symbols[i], "#999999"), edgecolor="k", lw=0.5)
        )


def figure_interface(atoms):
    """Fig. 1 style: (a) side view of the interface (3 cells along a1, seen along y) with
    surfaces 1–4 marked, (b) top view of slab 1's inner face (surface 2) over 4×4 cells
    with the primitive cell dashed. Si blue, O red (other elements grey)."""
    palette = {"Si": "#3b6ea5", "O": "#d62728"}
    fig = Figure(figsize=(12, 5.5))
    ax, bx = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1, 1.3]})
    cell = atoms.cell.array
    side = atoms.repeat((3, 1, 1))
    pos = side.positions
    _draw_atoms(ax, pos[:, [0, 2]], side.get_chemical_symbols(), -pos[:, 1], palette, 0.55)
    surface = atoms.arrays["surface"]
    z = atoms.positions[:, 2]
    x_lo, x_hi = pos[:, 0].min() - 1.5, pos[:, 0].max() + 1.5
    for tag, color in ((1, "0.6"), (2, "tab:green"), (3, "tab:purple"), (4, "0.6")):
        sel = surface == tag
        if np.any(sel):
            zt = float(z[sel].mean())
            ax.axhline(zt, color=color, lw=0.8, ls="--")
            ax.text(
                x_hi + 0.3,
                zt,
                f"surface {tag}" + (" (fixed)" if tag in (1, 4) else ""),
                va="center",
                fontsize=8,
                color="k",
            )
    ax.set_xlim(x_lo, x_hi + 7)
    ax.set_ylim(z.min() - 2, z.max() + 2)
    ax.set_aspect("equal")
    ax.set_xlabel("x (Å)")
    ax.set_ylabel("z (Å)")
    ax.set_title("(a) side view: slab 1 below, slab 2 above")
    face = atoms[(atoms.arrays["slab"] == 1) & (surface == 2)]
    top = face.repeat((4, 4, 1))
    tp = top.positions
    _draw_atoms(bx, tp[:, :2], top.get_chemical_symbols(), tp[:, 2], palette, 0.55)
    a1, a2 = cell[0][:2], cell[1][:2]
    origin = a1 + a2
    corners = np.array([origin, origin + a1, origin + a1 + a2, origin + a2, origin])
    bx.plot(corners[:, 0], corners[:, 1], "k--", lw=1.2, label="primitive cell")
    bx.set_xlim(tp[:, 0].min() - 1.5, tp[:, 0].max() + 1.5)
    bx.set_ylim(tp[:, 1].min() - 1.5, tp[:, 1].max() + 1.5)
    bx.set_aspect("equal")
    bx.set_xlabel("x (Å)")
    bx.set_ylabel("y (Å)")
    bx.set_title("(b) top view of the inner face of slab 1 (surface 2)")
    for key, col in palette.items():
        if key in atoms.get_chemical_symbols():
            bx.plot([], [], "o", color=col, label=key)
    bx.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    return fig
