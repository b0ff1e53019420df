"""Figures of every stage, one module per stage, and how they are saved.

Every figure is a bare :class:`matplotlib.figure.Figure` (no pyplot state): saving renders it
with the file format's own canvas, so importing flatcontact never changes the user's
matplotlib backend (a notebook keeps its inline or interactive backend) and no figure stays
registered with pyplot after it is written."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from flatcontact.foundation.fileio import atomic_path

__all__ = ["save_figure"]

#: Resolution of the PNG files and of the rasterised maps inside the SVGs (dots per inch):
#: matplotlib's own default. At 150 the default run's PNGs, which report.html embeds, took
#: 1.5× the bytes (2.5 against 1.7 MB; a 15-inch Fig. 2 is 1,500 pixels wide at 100).
DPI = 100


def save_figure(
    fig, stem: str | Path, formats: Sequence[str] = ("png", "svg"), dpi: int = DPI
) -> list[Path]:
    """Save ``fig`` as ``stem.<format>`` for each format, atomically.

    Returns the paths written. ``bbox_inches="tight"`` keeps labels inside the image; ``dpi``
    is the PNG's resolution and that of the rasterised maps inside the vector files.
    """
    stem = Path(stem)
    written = []
    for ext in formats:
        target = stem.parent / f"{stem.name}.{ext}"
        with atomic_path(target) as tmp:
            fig.savefig(tmp, format=ext, dpi=dpi, bbox_inches="tight")
        written.append(target)
    return written
