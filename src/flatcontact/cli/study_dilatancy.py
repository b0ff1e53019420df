"""``flatcontact study dilatancy``: how z* at fixed load varies with the registry, per stored scan.

Thin: parses ``LABEL=DIR`` pairs, calls :func:`flatcontact.studies.dilatancy.compare_dilatancy`,
writes its JSON and prints the ranges per model (docs/teachers.md, "why two models' τ differ").
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from flatcontact.cli.app import check_out_dir, console, parse_floats
from flatcontact.cli.study import study_app

#: The rows printed per model (all figures are in the JSON).
_PRINTED = ("z_range_angstrom", "gap_range_angstrom", "slabs_range_angstrom", "h_range_mj_per_m2")


def _labelled_folders(items: list[str]) -> dict[str, Path]:
    """``LABEL=DIR`` arguments -> ``{label: Path(dir)}``; one error line per bad item."""
    from flatcontact.foundation.errors import InputError

    folders: dict[str, Path] = {}
    for item in items:
        label, sep, folder = item.partition("=")
        if not sep or not label.strip() or not folder.strip():
            raise InputError(f"SCANS: {item!r}: expected LABEL=DIR (a label, '=', a scan folder)")
        if label in folders:
            raise InputError(f"SCANS: label {label!r} given twice")
        if not Path(folder).is_dir():
            raise InputError(f"SCANS: {label}={folder}: not a directory (a scan folder)")
        folders[label] = Path(folder)
    return folders


@study_app.command("dilatancy")
def dilatancy_command(
    out: Annotated[Path, typer.Argument(help="JSON file to write (the figures per model).")],
    scans: Annotated[
        list[str],
        typer.Argument(
            metavar="SCANS",
            help="LABEL=DIR pairs: a scan folder (ispes.nc, points.db) per model; the first is "
            "the reference of the ratios.",
        ),
    ],
    p_gpa: Annotated[
        list[str] | None,
        typer.Option("--p-gpa", help="Loads in GPa (default 0, 0.5, ..., 3)."),
    ] = None,
) -> None:
    """Dilatancy of stored scans: z* at fixed load split into the interface gap and the slabs."""
    import numpy as np

    from flatcontact.foundation.fileio import write_json_atomic
    from flatcontact.studies.dilatancy import LOADS_GPA, compare_dilatancy

    folders = _labelled_folders(scans)
    loads = np.array(parse_floats(p_gpa, "--p-gpa", "GPa")) if p_gpa else LOADS_GPA
    check_out_dir(out.parent, "OUT")
    doc = compare_dilatancy(folders, loads)
    write_json_atomic(out, doc)
    for label, m in doc["models"].items():
        console.print(label, highlight=False)
        rows = list(_PRINTED)
        if label != doc["reference"]:
            rows += ["z_range_angstrom_over_reference", "h_range_mj_per_m2_over_reference"]
        for q in rows:
            console.print(f"  {q:>34} {np.round(m[q], 3).tolist()}", highlight=False)
    console.print(f"wrote {out}", highlight=False)
