"""Pictures of an interface: side view (x–z) and top view of the inner face of slab 1 (x–y).

Si blue, O red; bonds (Si–O < 2.0 Å) drawn as lines over a 3×3 lateral repetition so the
six-membered rings of the dense surface are visible in the top view.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from ase import Atoms

from flatcontact.fileio import atomic_path
from flatcontact.structures.topology import bonds

COLORS = {"Si": "tab:blue", "O": "tab:red"}
SIZES = {"Si": 60.0, "O": 35.0}


def _draw(ax, atoms: Atoms, mask: np.ndarray, axes: tuple[int, int], reps: tuple[int, int]) -> None:
    cell = atoms.cell.array
    i, j, shifts = bonds(atoms)
    symbols = np.array(atoms.get_chemical_symbols())
    for ra in range(reps[0]):
        for rb in range(reps[1]):
            t = ra * cell[0] + rb * cell[1]
            keep = mask[i] & mask[j] & (i < j)
            start = atoms.positions[i[keep]] + t
            end = atoms.positions[j[keep]] + shifts[keep] @ cell + t
            for p, q in zip(start, end, strict=True):
                ax.plot(
                    [p[axes[0]], q[axes[0]]],
                    [p[axes[1]], q[axes[1]]],
                    color="0.5",
                    lw=0.8,
                    zorder=1,
                )
            for sym in ("O", "Si"):
                sel = mask & (symbols == sym)
                pos = atoms.positions[sel] + t
                ax.scatter(
                    pos[:, axes[0]],
                    pos[:, axes[1]],
                    s=SIZES.get(sym, 40.0),
                    c=COLORS.get(sym, "0.3"),
                    edgecolors="k",
                    linewidths=0.4,
                    zorder=2,
                    label=sym if (ra, rb) == (0, 0) else None,
                )


def plot_interface(atoms: Atoms, path: str | os.PathLike[str], title: str | None = None) -> Path:
    """Write a two-panel PNG/PDF: side view (3×1 cells) and top view of surface 2's face layer (3×3)."""
    import matplotlib.pyplot as plt

    fig, (side, top) = plt.subplots(1, 2, figsize=(10, 5.5), gridspec_kw={"width_ratios": [1, 1.2]})
    everything = np.ones(len(atoms), bool)
    _draw(side, atoms, everything, (0, 2), (3, 1))
    side.set_xlabel("x (Å)")
    side.set_ylabel("z (Å)")
    side.set_title("side view")
    side.set_aspect("equal")
    surface = atoms.arrays.get("surface")
    face = (
        (surface == 2)
        if surface is not None
        else atoms.positions[:, 2] > np.median(atoms.positions[:, 2])
    )
    _draw(top, atoms, face, (0, 1), (3, 3))
    top.set_xlabel("x (Å)")
    top.set_ylabel("y (Å)")
    top.set_title("top view of surface 2 (inner face of slab 1)")
    top.set_aspect("equal")
    top.legend(loc="upper right", fontsize=8)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format=Path(path).suffix.lstrip(".") or "png", dpi=150)
    plt.close(fig)
    return Path(path)
