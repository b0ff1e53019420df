"""The scan stage's remedy for folds from relaxation error (:mod:`flatcontact.ispes.rerelax`).

After the grid is stored, every column whose load folds below a load the analysis will read
(``analysis.p_gpa``, read as ``analysis.load_source`` says) has its fold's window relaxed
again at ``scan.fmax_ev_per_angstrom`` / 10, once, into ``02-scan/rerelax.db``; ``ispes.nc``
then holds those points, ``scan.json`` ``fold_rerelaxation`` says what was re-relaxed and
which folds survived, its warnings and the run log state it, and the folds the re-relaxation
removed leave ``load_folds``. A fold that survives is refused by the analysis as before, its
message saying that it survived.
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
        reference, factory, scan.dataset, scan.store_path, store, relax, a.p_gpa, a.load_source
    )
    if not done.found:
        return scan, None, []
    if done.points:
        write_ispes(ds, scan.ispes_path)
    gone = [w.name for w in done.remedied]
    folds = [
        f for f in scan.load_folds if not any(name in str(f.get("column", "")) for name in gone)
    ]
    return dataclasses.replace(scan, dataset=ds, load_folds=folds), done.record(), done.lines()
