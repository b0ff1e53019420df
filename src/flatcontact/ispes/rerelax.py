"""Folds from relaxation error, remedied: the fold's window relaxed again at a tighter fmax.

A scan point stops where the largest force on a free atom falls below ``scan.fmax``, which
leaves an energy error above the minimum that grows along a warm-started column (each point
inherits its parent's unrelaxed soft modes). The analysis reads the load from the energy,
p = -(1/A) dU/dz of a spline through the thickness nodes, so an error δU of one node moves
the load of its neighbours by about δU/(A h) (h: the node spacing) and can make a column's
p(z) rise with z on the compressed side: a fold, and the analysis refuses the loads above it
(:mod:`flatcontact.analysis.constant_pressure`). The 12-layer α-quartz slab of the
convergence study folded at 4.29 → 4.54 GPa at 0.005 eV/Å with no plane slipping and did not
fold once its points were relaxed to 0.0005 eV/Å (docs/convergence.md, "Slab layers at high
load"; ``benchmarks/rerelax_window.py``).

:func:`rerelax_folds` applies that remedy before anything refuses: every grid column whose
load (as the analysis reads it, :func:`fold_windows`) folds below a load the analysis will
read has the points of its fold's window (:data:`WINDOW_NODES` thickness nodes on each side
of the rise) relaxed again from their stored positions with the scan's own relaxation
(:func:`flatcontact.ispes.relax.relax_point`) at ``fmax`` × :data:`FMAX_FACTOR`, once
(:data:`MAX_ROUNDS`), for at most :data:`MAX_FOLD_COLUMNS` columns (the lowest folds first):
a bounded cost of at most ``MAX_FOLD_COLUMNS × (2 WINDOW_NODES + 2)`` points. A fold that
survives is not the relaxation's (a plane that slips, a collapse, a fold of the interaction
itself) and is left to the analysis to refuse, with the record saying it survived.

The re-relaxed points are a point store of their own (``rerelax.db`` beside ``points.db``,
:class:`~flatcontact.ispes.store.PointStore`: the same row contract, its settings those of
the scan with the tighter force tolerance, stored as ``relax.fmax_ev_per_a``), so the scan's own store stays what the
scan computed, an interrupted re-relaxation resumes where it stopped, and ``ispes.nc`` is the
scan's grid with those points replaced (attributes ``fold_rerelaxed_points`` and
``fold_rerelaxed_fmax_ev_per_a``). Units: Å, eV, GPa.
"""

from __future__ import annotations

import dataclasses
import logging
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np
from ase import Atoms

from flatcontact.foundation.layout import RERELAX_DB
from flatcontact.ispes import contract
from flatcontact.ispes.grid_bracket import node_loads_gpa
from flatcontact.ispes.relax import PointTask, RelaxSettings, relax_point, worker_calculator
from flatcontact.ispes.store import PointStore

log = logging.getLogger("flatcontact.scan")

#: The tighter force tolerance is the scan's times this (the quartz fold: 0.005 → 0.0005 eV/Å).
FMAX_FACTOR = 0.1
#: Rounds of re-relaxation before a fold is left to be refused.
MAX_ROUNDS = 1
#: Thickness nodes re-relaxed on each side of the rise (the nodes of the rise itself, and
#: this many beyond each): the spline's load at a node depends mostly on its neighbours.
WINDOW_NODES = 2
#: A column of fewer thicknesses has no fold to read (a rise needs three nodes; the
#: analysis reads at least four).
MIN_THICKNESSES = 3
#: At most this many folding columns are re-relaxed (the lowest folds first); more folding
#: columns than this is not a local relaxation error.
MAX_FOLD_COLUMNS = 8
#: The remedies of a fold that survived the re-relaxation (not the relaxation's).
SURVIVING_FOLD_REMEDY = (
    "if a plane slips (scan.json layer_slip), hold the slabs' inner planes laterally "
    "(scan.relax_mode: normal); else add thicknesses around the fold (scan.p_range_gpa.n or "
    "scan.thickness_angstrom) or read loads below it (analysis.p_gpa, scan.p_range_gpa.hi_gpa)"
)


@dataclasses.dataclass(frozen=True)
class FoldWindow:
    """A grid column whose load rises with z on the compressed side below a load the analysis
    reads: the rise from ``p_below_gpa`` at ``z_below_angstrom`` to ``p_gpa`` at
    ``z_angstrom``, and the thickness nodes of its window (positions on the ascending
    ``thickness`` axis of ``ispes.nc``)."""

    column: tuple[int, int]
    shift: tuple[float, float]
    z_below_angstrom: float
    p_below_gpa: float
    z_angstrom: float
    p_gpa: float
    nodes: tuple[int, ...]

    @property
    def name(self) -> str:
        """``"grid column at shift (a, b)"`` (as the scan's ``load_folds`` name it)."""
        return f"grid column at shift ({self.shift[0]:.4g}, {self.shift[1]:.4g})"

    def record(self) -> dict:
        return {
            "column": self.name,
            "z_below_angstrom": self.z_below_angstrom,
            "p_below_gpa": self.p_below_gpa,
            "z_angstrom": self.z_angstrom,
            "p_gpa": self.p_gpa,
        }


def _column_fold(p: np.ndarray, top_gpa: float) -> int | None:
    """The node ``s`` where a column's branch starts past a fold that stops the analysis at
    loads up to ``top_gpa`` (the analysis's rule: no segment left, or a load at or above the
    ceiling ``min(p[:s], p[s + 1])``), else None."""
    s, e = contract.branch_run(p)
    if s == 0:
        return None
    ceiling = min(float(np.min(p[:s])), float(p[s + 1]) if s + 1 < p.size else np.inf)
    if e - s >= 1 and top_gpa < ceiling:
        return None
    return s


def _recorded_fold(p: np.ndarray) -> int | None:
    """The node where a column's load first rises with z before its tensile maximum (the
    scan's grid check, :func:`flatcontact.ispes.grid_bracket.check_grid`, records such a rise
    in ``load_folds`` and the gate ``load_fold`` refuses it), else None."""
    m = int(np.argmin(p))
    rises = np.flatnonzero(np.diff(p[: m + 1]) >= 0)
    return int(rises[0]) + 1 if rises.size else None


def fold_windows(
    ds: Any,
    loads_gpa: Sequence[float],
    load_source: str = "energy",
    window: int = WINDOW_NODES,
    recorded: bool = False,
) -> list[FoldWindow]:
    """The columns of ``ds`` (``ispes.nc``) whose load folds below the largest of
    ``loads_gpa``, lowest fold first.

    The load is the analysis's: ``-(1/A) dU/dz`` at the nodes of the clamped spline
    (:func:`flatcontact.ispes.grid_bracket.node_loads_gpa`, ``load_source="energy"``) or the
    stored ``normal_stress``; the branch rule is
    :func:`flatcontact.ispes.contract.branch_run`. With ``recorded``, also every column whose
    energy-derived or stored load rises before its tensile maximum at any load (what the
    scan's grid check of a pressure-range grid records and the ``load_fold`` gate refuses).
    Columns with a missing point are skipped; a grid of fewer than :data:`MIN_THICKNESSES`
    thicknesses has none.
    """
    z = np.asarray(ds[contract.DIM_Z].values, float)
    if z.size < MIN_THICKNESSES:
        return []
    energy = np.asarray(ds[contract.VAR_ENERGY].values, float)
    stress = np.asarray(ds[contract.VAR_STRESS].values, float)
    sa, sb = ds[contract.DIM_A].values, ds[contract.DIM_B].values
    top = max(float(v) for v in loads_gpa)
    area = float(ds.attrs["area"])
    out = []
    for i in range(energy.shape[0]):
        for j in range(energy.shape[1]):
            e, s = energy[i, j], stress[i, j]
            if not (np.all(np.isfinite(e)) and np.all(np.isfinite(s))):
                continue
            from_energy = node_loads_gpa(z, e[None, :], s[None, :], area)[0]
            p = from_energy if load_source == "energy" else s
            k = _column_fold(p, top)
            if k is None and recorded:
                for p in (from_energy, s):
                    k = _recorded_fold(p)
                    if k is not None:
                        break
            if k is None:
                continue
            lo, hi = max(0, k - 1 - window), min(z.size - 1, k + window)
            out.append(
                FoldWindow(
                    (i, j),
                    (float(sa[i]), float(sb[j])),
                    float(z[k - 1]),
                    float(p[k - 1]),
                    float(z[k]),
                    float(p[k]),
                    tuple(range(lo, hi + 1)),
                )
            )
    return sorted(out, key=lambda w: w.p_gpa)


@dataclasses.dataclass
class FoldRerelaxation:
    """What :func:`rerelax_folds` did: the tighter tolerance (eV/Å), the folds found, those
    that survived, the columns left alone and why, and one record per re-relaxed point."""

    fmax_ev_per_angstrom: float
    found: list[FoldWindow]
    surviving: list[FoldWindow]
    left: list[tuple[str, str]]  #: (column name, why it was not re-relaxed)
    points: list[dict]

    @property
    def remedied(self) -> list[FoldWindow]:
        """The folds that the re-relaxation removed (``surviving``: re-relaxed and still
        folding; ``left``: not re-relaxed)."""
        kept = {w.column for w in self.surviving} | {w.column for w in self.found if self._left(w)}
        return [w for w in self.found if w.column not in kept]

    def _left(self, window: FoldWindow) -> bool:
        return any(name == window.name for name, _ in self.left)

    def record(self) -> dict:
        """``scan.json`` ``fold_rerelaxation``."""
        return {
            "fmax_ev_per_angstrom": self.fmax_ev_per_angstrom,
            "rounds": MAX_ROUNDS,
            "found": [w.record() for w in self.found],
            "remedied": [w.name for w in self.remedied],
            "surviving": [w.record() for w in self.surviving],
            "left": [{"column": name, "why": why} for name, why in self.left],
            "points": list(self.points),
        }

    def lines(self) -> list[str]:
        """The log's and the report's lines: what was re-relaxed and what survived."""
        out = []
        n = len(self.points)
        left = {name for name, _ in self.left}
        for w in self.found:
            if w.name in left:
                continue
            verdict = (
                "the fold survived: not the relaxation's"
                if any(s.column == w.column for s in self.surviving)
                else "the fold is gone: it was the relaxation's"
            )
            out.append(
                f"{w.name}: load folded from {w.p_below_gpa:.4g} GPa at z = "
                f"{w.z_below_angstrom:.4g} Å to {w.p_gpa:.4g} GPa at z = {w.z_angstrom:.4g} Å; "
                f"its window ({len(w.nodes)} thicknesses) re-relaxed at fmax "
                f"{self.fmax_ev_per_angstrom:g} eV/Å: {verdict}"
            )
        if n:
            out.append(
                f"fold re-relaxation: {n} point(s) at fmax {self.fmax_ev_per_angstrom:g} eV/Å"
            )
        return out + [f"{name}: fold not re-relaxed ({why})" for name, why in self.left]


def _window_tasks(main: PointStore, chosen: list[FoldWindow], z: np.ndarray) -> list[tuple]:
    """``(node, stored record, PointTask)`` per point of the ``chosen`` windows, each started
    from its stored positions (the scan's store ``main``; ``z`` the ascending thicknesses)."""
    resolved_z = np.asarray(main.resolved["thickness_angstrom"], float)
    tasks = []
    for w in chosen:
        for k in w.nodes:
            index = (w.column[0], w.column[1], _stored_index(resolved_z, z[k]))
            rec = main.record(index)
            a, b = rec["shift"]
            task = PointTask(
                index,
                a,
                b,
                rec["thickness"],
                start_positions=main.positions(index),
                start_shift=(a, b),
                start_thickness=rec["thickness"],
            )
            tasks.append((k, rec, task))
    return tasks


def _stored_index(resolved_z: np.ndarray, z: float) -> int:
    """The store's thickness index (position in ``resolved`` ``thickness_angstrom``) of ``z``."""
    return int(np.argmin(np.abs(resolved_z - z)))


def rerelax_folds(
    reference: Atoms,
    factory: Any,
    ds: Any,
    store_path: str | Path,
    store_settings: dict,
    relax: RelaxSettings,
    loads_gpa: Sequence[float],
    load_source: str = "energy",
    rerelax_path: str | Path | None = None,
    recorded: bool = False,
) -> tuple[Any, FoldRerelaxation]:
    """Re-relax the windows of the folds of ``ds`` at ``relax.fmax_ev_per_angstrom`` × FMAX_FACTOR.

    Parameters
    ----------
    reference, factory
        The scan's reference interface and calculator factory.
    ds
        The scan's ``ispes.nc`` dataset (its own grid, before any re-indexing).
    store_path, store_settings
        The scan's ``points.db`` and its settings (:func:`flatcontact.ispes.scan.scan_settings`):
        the stored positions are the starts.
    relax
        The scan's relaxation settings (the mode and optimiser are kept).
    loads_gpa, load_source
        The loads the analysis will read and how it reads the load (``"energy"``, ``"stress"``).
    recorded
        Also the folds the scan's grid check records (:func:`fold_windows`).
    rerelax_path
        The store of the re-relaxed points (default ``rerelax.db`` beside ``store_path``).

    Returns
    -------
    dataset, record
        ``ds`` with the re-relaxed points' energy, normal stress, convergence and force calls
        (``ds`` itself when nothing folds), and the :class:`FoldRerelaxation`.
    """
    tight = dataclasses.replace(
        relax, fmax_ev_per_angstrom=relax.fmax_ev_per_angstrom * FMAX_FACTOR
    )
    found = fold_windows(ds, loads_gpa, load_source, recorded=recorded)
    result = FoldRerelaxation(tight.fmax_ev_per_angstrom, found, [], [], [])
    if not found:
        return ds, result
    if relax.mode == "rigid":
        result.left += [(w.name, "a rigid scan relaxes nothing") for w in found]
        return ds, result
    chosen, mapped = [], ds.get(contract.VAR_MAPPED)
    for w in found:
        if len(chosen) >= MAX_FOLD_COLUMNS:
            result.left.append((w.name, f"more than {MAX_FOLD_COLUMNS} folding columns"))
        elif mapped is not None and bool(np.any(mapped.values[w.column[0], w.column[1], :])):
            result.left.append((w.name, "its points are filled by symmetry, not stored"))
        else:
            chosen.append(w)
    if not chosen:
        return ds, result
    z = np.asarray(ds[contract.DIM_Z].values, float)
    with PointStore(store_path, store_settings, reference) as main:
        resolved = main.resolved
        tasks = _window_tasks(main, chosen, z)
    path = (
        Path(rerelax_path) if rerelax_path is not None else Path(store_path).with_name(RERELAX_DB)
    )
    settings = {**store_settings, "relax": tight.as_dict()}
    out = ds.copy(deep=True)
    energy, stress = out[contract.VAR_ENERGY].values, out[contract.VAR_STRESS].values
    converged, calls = out[contract.VAR_CONVERGED].values, out[contract.VAR_FORCE_CALLS].values
    with PointStore(path, settings, reference) as store:
        if store.resolved is None:
            store.set_resolved(resolved)
        calc = None
        for k, rec, task in tasks:
            if task.index not in store:  # a resumed re-relaxation keeps what it finished
                calc = calc or worker_calculator(factory, reference)
                store.write(relax_point(reference, calc, task, tight))
            new = store.record(task.index)
            i, j = task.index[:2]
            energy[i, j, k], stress[i, j, k] = new["energy_ev"], new["normal_stress_gpa"]
            converged[i, j, k] = new["converged"]
            calls[i, j, k] = rec["force_calls"] + new["force_calls"]
            result.points.append(
                {
                    "i_a": int(i),
                    "i_b": int(j),
                    "i_z": int(task.index[2]),
                    "thickness_angstrom": float(rec["thickness"]),
                    "energy_stored_ev": float(rec["energy_ev"]),
                    "energy_ev": float(new["energy_ev"]),
                    "p_stored_gpa": float(rec["normal_stress_gpa"]),
                    "p_gpa": float(new["normal_stress_gpa"]),
                    "force_calls": int(new["force_calls"]),
                    "converged": bool(new["converged"]),
                }
            )
    out.attrs["fold_rerelaxed_points"] = len(result.points)
    out.attrs["fold_rerelaxed_fmax_ev_per_a"] = tight.fmax_ev_per_angstrom
    columns = {w.column for w in chosen}
    again = fold_windows(out, loads_gpa, load_source, recorded=recorded)
    result.surviving += [w for w in again if w.column in columns]
    for line in result.lines():
        log.warning("scan: %s", line)
    return out, result
