"""Figures of every stage (matplotlib, the file-only Agg backend), one module per stage, and
how they are saved."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # figures are written to files: the non-interactive backend
import matplotlib.pyplot as plt

from flatcontact.fileio import atomic_path

__all__ = ["save_figure"]


def save_figure(
    fig, stem: str | Path, formats: Sequence[str] = ("png", "svg"), dpi: int = 150
) -> list[Path]:
    """Save ``fig`` as ``stem.<format>`` for each format, atomically, then close it.

    Returns the paths written. ``bbox_inches="tight"`` keeps labels inside the image.
    """
    stem = Path(stem)
    written = []
    for ext in formats:
        target = stem.parent / f"{stem.name}.{ext}"
        with atomic_path(target) as tmp:
            fig.savefig(tmp, format=ext, dpi=dpi, bbox_inches="tight")
        written.append(target)
    plt.close(fig)
    return written
