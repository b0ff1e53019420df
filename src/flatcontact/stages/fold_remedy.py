"""The scan stage's remedy for folds from relaxation error (:mod:`flatcontact.ispes.rerelax`).

After the grid is stored, every column whose load, read as ``analysis.load_source`` says,
folds where the analysis would refuse a load of ``analysis.p_gpa``, and on a pressure-range
grid every column the scan's grid check records as folding (``load_folds``, refused by the
gate ``load_fold``), has its fold's window relaxed again at ``scan.fmax_ev_per_angstrom`` / 10, once, into ``02-scan/rerelax.db``; ``ispes.nc``
then holds those points, ``scan.json`` ``fold_rerelaxation`` says what was re-relaxed and
which folds survived, its warnings and the run log state it, and the folds the re-relaxation
removed leave ``load_folds``. A fold that survives is refused by the analysis as before, its
message saying that it survived. Only folds that would stop the run are re-relaxed, so a run
that passes keeps its numbers. The lowest and highest load of ``analysis.p_gpa`` are part of
a pressure-range scan's fingerprint (:func:`flatcontact.stages.fingerprints.scan`); with given thicknesses
(``scan.thickness_angstrom``) they are not, and a load added later above a fold is refused
by the analysis without this remedy (rerun the scan, e.g. with a new ``--out``).
"""

from __future__ import annotations

import dataclasses
from typing import Any

from flatcontact.ispes.contract import write_ispes
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.reduction import SymmetrySettings
from flatcontact.ispes.relax import RelaxSettings
from flatcontact.ispes.rerelax import rerelax_folds
from flatcontact.ispes.scan import scan_settings


def remedy_folds(
    settings,
    reference,
    factory,
    scan: Any,
    grid: GridSpec,
    relax: RelaxSettings,
    symmetry: SymmetrySettings,
) -> tuple[Any, dict | None, list[str]]:
    """``(scan, record, lines)``: the scan result with the re-relaxed ``dataset`` (written to
    ``ispes.nc``) and the ``load_folds`` that remain, the ``scan.json``
    ``fold_rerelaxation`` record (None when nothing folds) and the lines to state."""
    a = settings.analysis
    store = scan_settings(reference, factory, grid, relax, symmetry)
    ds, done = rerelax_folds(
        reference,
        factory,
        scan.dataset,
        scan.store_path,
        store,
        relax,
        a.p_gpa,  # only a fold that would be refused: a run that passes keeps its numbers
        a.load_source,
        recorded=settings.scan.p_range_gpa is not None,  # the grid check records folds
    )
    if not done.found:
        return scan, None, []
    if done.points:
        write_ispes(ds, scan.ispes_path)
    gone = [w.name for w in done.remedied]
    folds = [
        f for f in scan.load_folds if not any(name in str(f.get("column", "")) for name in gone)
    ]
    # the grid check's notes on the folds that are gone would say they are still there
    notes = [n for n in scan.notes if not any(f"{name} (" in n for name in gone)]
    if gone:
        grid_folds = sum("grid column" in str(f.get("column", "")) for f in folds)
        notes = [n for n in notes if "grid columns fold (" not in n] + [
            f"p-range-gpa: {len(gone)} grid column fold(s) re-relaxed away; {grid_folds} "
            "remain (scan.json load_folds, fold_rerelaxation)"
        ]
    scan = dataclasses.replace(scan, dataset=ds, load_folds=folds, notes=notes)
    return scan, done.record(), done.lines()
