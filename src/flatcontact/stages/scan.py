"""Stage 2, scan: the ISPES grid of the interface (resumable, parallel).

Files: ``points.db`` (the resumable point store), ``probe.json`` (the probe's finished
units, :mod:`flatcontact.ispes.probe_units`), ``ispes.nc`` (the ISPES contract),
``scan.json`` (:meth:`ScanStageResult.to_json`) and ``fig_scan_columns.png`` (+ ``.svg``).

Coincidence and twist cells (issue 23): the energy repeats on the shift lattice Λ_1 + Λ_2,
``index`` times finer than the interface cell (N² for an N-cell twist,
:mod:`flatcontact.ispes.shift_lattice`). The stage finds it on the atoms before the scan,
scans the grid :func:`~flatcontact.ispes.shift_lattice.scan_grid` (n × n over the
supercell, n coprime to the index: the points of an n × n grid over ONE period) and writes
``ispes.nc`` re-indexed onto that period
(:func:`~flatcontact.ispes.shift_lattice.to_shift_cell`), so the analysis, the laws and the
contact stage read the real period; a grid over the supercell read as one period would be
aliased (τ0 of the (1, 2) twisted bilayer 7× too small). ``scan.json`` ``shift_lattice``
states the cell the analysis reads; index 1 (a 1×1 cell) changes nothing.
"""

from __future__ import annotations

import dataclasses
import json
import logging
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import write_json_atomic
from flatcontact.foundation.layout import SCAN_FIGURE, SCAN_JSON
from flatcontact.ispes import scan as ispes_scan
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.reduction import SymmetrySettings
from flatcontact.ispes.relax import RelaxSettings
from flatcontact.stages import _calculator
from flatcontact.stages._common import save
from flatcontact.stages.fold_remedy import remedy_folds

log = logging.getLogger("flatcontact.run")


@dataclass(frozen=True)
class ScanInputs:
    """The interface to scan (``interface.extxyz`` of the build stage or ``flatcontact build``)."""

    interface: Path


@dataclass
class ScanStageResult:
    """What the scan stage did: the scan driver's result and the stage's warnings."""

    scan: Any  # flatcontact.ispes.scan.ScanResult
    warnings: list[str] = field(default_factory=list)
    files: list[Path] = field(default_factory=list)
    layer_slip: dict | None = None  # flatcontact.ispes.slip.SlipTable.to_json()
    shift_lattice: dict | None = None  # the cell ispes.nc is stated on (module docstring)
    fold_rerelaxation: dict | None = None  # folds re-relaxed at fmax/10 (stages.fold_remedy)

    @property
    def dataset(self):
        """The ``ispes.nc`` content (xarray Dataset)."""
        return self.scan.dataset

    def to_json(self) -> dict:
        """``scan.json``: counts, force calls, thicknesses, adhesion, notes, warnings,
        ``load_folds`` (columns whose load folds and the loads refused, docs/file-contracts.md)
        and the lateral slip of the planes inside each slab (``layer_slip``, :mod:`flatcontact.ispes.slip`)."""
        r, ds = self.scan, self.scan.dataset
        calls = r.force_calls_computed
        return {
            "points_total": r.points_total,
            "points_done": r.points_done,
            "points_computed": r.points_computed,
            "grid_points": r.points_total,
            "computed_points": r.points_stored,
            "symmetry": r.symmetry
            or {"order": 1, "operations": [], "note": "every grid point relaxed"},
            "converged": int(ds["converged"].sum()),
            "force_calls_total": int(np.nansum(ds["force_calls"].values)),
            "hessian_force_calls": int(r.hessian_force_calls),
            "median_force_calls_per_point": float(np.median(calls)) if calls else None,
            "thickness_angstrom": [float(z) for z in ds["thickness"].values],
            "area_angstrom2": float(ds.attrs["area"]),
            "potential": str(ds.attrs.get("potential", "")),
            "adhesion": r.adhesion,
            "notes": list(r.notes),
            "warnings": list(self.warnings),
            "load_folds": list(getattr(r, "load_folds", [])),
            "layer_slip": self.layer_slip,
            "shift_lattice": self.shift_lattice,
            "fold_rerelaxation": self.fold_rerelaxation,
        }


def grid_spec(scan, lateral: tuple[int, int] | None = None) -> GridSpec:
    """The scan grid of the ``scan`` settings (:class:`flatcontact.ispes.grid.GridSpec`);
    ``lateral`` replaces ``scan.grid`` (the grid chosen for a shift lattice, :func:`scan_stage`)."""
    r = scan.p_range_gpa
    n_a, n_b = lateral if lateral is not None else scan.grid
    return GridSpec(
        n_a,
        n_b,
        thickness_angstrom=tuple(scan.thickness_angstrom) if scan.thickness_angstrom else None,
        p_range_gpa=(r.lo_gpa, r.hi_gpa, r.n) if r else None,
        bracket_all_stackings=scan.bracket_all_stackings,
    )


def symmetry_settings(scan) -> SymmetrySettings:
    """The irreducible-registry settings of the ``scan`` settings (:mod:`flatcontact.ispes.reduction`)."""
    y = scan.symmetry
    enabled = scan.relax_mode != "full" if y.enabled == "auto" else bool(y.enabled)
    return SymmetrySettings(
        enabled,
        y.verify_points,
        y.tolerance_angstrom,
        y.energy_tolerance_mev_per_a2,
        y.stress_tolerance_gpa,
        y.energy_tolerance_fraction,
    )


def relax_settings(scan) -> RelaxSettings:
    """The per-point relaxation of the ``scan`` settings (:class:`flatcontact.ispes.relax.RelaxSettings`)."""
    return RelaxSettings(
        scan.fmax_ev_per_angstrom,
        scan.optimizer,
        scan.max_steps,
        mode=scan.relax_mode,
        precondition=scan.precondition,
    )


def built_with_other_model(reference, settings) -> str | None:
    """The model an interface's recipe names when it is not the run's, else ``None``.

    The recipe (``info["recipe"]``, written by :mod:`flatcontact.structures.build`) holds the
    whole ``InteractionModel`` (``potential_spec``; older files only its label ``potential``, of
    which the intra-slab part is compared). A recipe naming no potential gives ``None``.
    """
    from flatcontact.potentials.model import InteractionModel
    from flatcontact.potentials.names import normalize_potential_name

    try:
        recipe = json.loads(reference.info.get("recipe", "{}") or "{}")
    except (TypeError, ValueError):
        return None
    if not isinstance(recipe, dict):
        return None
    if isinstance(recipe.get("potential_spec"), dict):
        try:
            built = InteractionModel(**recipe["potential_spec"])
        except (InputError, TypeError):
            return str(recipe["potential_spec"].get("intra", "an unknown model"))
        return None if _calculator.same_model(settings, built) else built.label
    label = recipe.get("potential")
    if not isinstance(label, str) or not label:
        return None
    intra = label.split("+LJ(")[0]
    try:
        intra = normalize_potential_name(intra)
    except InputError:
        pass
    return None if _calculator.same_intra(settings, intra) else label


def _no_repulsive_branch(ds) -> str | None:
    """A warning when no scanned thickness is under compression (p > 0 nowhere).

    Such a grid holds only the separated (tensile) branch; the constant-pressure analysis at
    P >= 0 needs thicknesses where the slabs push back (p = normal_stress > 0, compressive).
    """
    p = np.asarray(ds.normal_stress.values, dtype=float)
    if p.size and not np.any(p[np.isfinite(p)] > 0):
        z = [float(v) for v in ds.thickness.values]
        return (
            f"no scanned thickness reached p > 0 (max {np.nanmax(p):.3g} GPa at z = "
            f"{min(z):g}..{max(z):g} Å): the interface is separated everywhere and "
            "'flatcontact analyze' has no repulsive branch; scan smaller thicknesses"
        )
    return None


def scan_stage(
    settings,
    inputs: ScanInputs,
    folder: Path,
    progress: Callable[[int, int], None] | None = None,
) -> ScanStageResult:
    """Scan ``inputs.interface`` with the run's model on ``settings.scan``'s grid into ``folder``.

    Checks before any relaxation: the interface contract, the model's elements, the grid and
    the store's settings (:func:`flatcontact.ispes.scan.run_scan`). A different model than the
    one the interface was relaxed with is a warning (its reference stacking and thickness are
    not the scan model's), in ``scan.json`` and on the console. Ctrl-C raises
    :class:`flatcontact.ispes.scan.ScanInterrupted` after the store is consistent.
    """
    from flatcontact.plots.scan import figure_scan_columns
    from flatcontact.structures.interface_io import read_interface

    s = settings.scan
    reference = read_interface(inputs.interface)
    _calculator.check_atoms(settings, reference)
    factory = _calculator.factory(settings)
    warnings = []
    built_with = built_with_other_model(reference, settings)
    if built_with is not None:
        warnings.append(
            f"{inputs.interface} was built with {built_with}, this scan uses "
            f"{_calculator.label(settings)}: its reference stacking and thickness are not the "
            "relaxed ones of the scan's model"
        )
        log.warning("scan: %s", warnings[-1])
    lattice, lateral, record = _shift_lattice_grid(s, reference)
    if lateral != tuple(s.grid):
        warnings.append(
            f"scan.grid {list(s.grid)}: the landscape repeats on a shift lattice of index "
            f"{lattice.index}; scanned {lateral[0]} x {lateral[1]} over the interface cell "
            "(coprime to the index), re-indexed onto one period"
        )
        log.warning("scan: %s", warnings[-1])
    grid, relax, symmetry = grid_spec(s, lateral), relax_settings(s), symmetry_settings(s)
    # a user's calculator that fails at a point: one line naming the stage and the point
    with _calculator.failing_at("scan"):
        scan = ispes_scan.run_scan(
            reference,
            factory,
            grid,
            folder,
            relax,
            order=s.order,
            executor_options=s.executor_options(),
            progress=progress,
            symmetry=symmetry,
            bracket_loads_gpa=list(settings.analysis.p_gpa),
        )
        scan, folds, lines = remedy_folds(settings, reference, factory, scan, grid, relax, symmetry)
    warnings += lines
    if lattice.index > 1:
        from flatcontact.ispes.contract import write_ispes
        from flatcontact.ispes.shift_lattice import to_shift_cell

        scan = dataclasses.replace(scan, dataset=to_shift_cell(scan.dataset, lattice))
        write_ispes(scan.dataset, scan.ispes_path)
        record.update(
            a1_angstrom=np.asarray(scan.dataset.attrs["a1"], float).tolist(),
            a2_angstrom=np.asarray(scan.dataset.attrs["a2"], float).tolist(),
            area_angstrom2=float(scan.dataset.attrs["area"]),
        )
    separated = _no_repulsive_branch(scan.dataset)
    if separated is not None:
        warnings.append(separated)
    for note in scan.notes:
        log.warning("scan: %s", note)
    result = ScanStageResult(scan, warnings, [scan.store_path, scan.ispes_path])
    result.shift_lattice = record
    result.fold_rerelaxation = folds
    if "layer" in reference.arrays and "slab" in reference.arrays:
        from flatcontact.ispes.slip import slip_table, store_points

        result.layer_slip = slip_table(reference, store_points(scan.store_path)).to_json()
    result.files.append(write_json_atomic(folder / SCAN_JSON, result.to_json()))
    result.files += save(
        figure_scan_columns(scan.dataset, scan.adhesion), folder, SCAN_FIGURE, settings.report.svg
    )
    return result


#: Displacement (Å) within which a relaxed cell still repeats on a finer shift lattice: a build
#: relaxation of a coincidence cell modulates the sheets by 0.05–0.1 Å (H-diamond(111) on
#: graphene, measured), far below the 1.4 Å between unlike positions of a honeycomb.
NEAR_PERIOD_TOLERANCE_ANGSTROM = 0.25


def _shift_lattice_grid(scan, reference) -> tuple[Any, tuple[int, int], dict]:
    """The interface's shift lattice, the lateral grid to scan and the ``scan.json``
    ``shift_lattice`` record (module docstring), checked before any point is relaxed.

    Raises
    ------
    InputError
        One line naming ``scan.grid`` and the index when the grid cannot be re-indexed onto
        one period (:func:`flatcontact.ispes.shift_lattice.reindex`): never an aliased grid.
    """
    from flatcontact.ispes.shift_lattice import reindex, scan_grid, shift_lattice_of
    from flatcontact.ispes.shift_symmetry import self_translations
    from flatcontact.structures.interface_contract import in_plane_vectors

    lattice = shift_lattice_of(reference, scan.symmetry.tolerance_angstrom)
    tol = scan.symmetry.tolerance_angstrom
    for slab in (1, 2):
        exact = len(self_translations(reference, slab, tol))
        near = len(self_translations(reference, slab, NEAR_PERIOD_TOLERANCE_ANGSTROM))
        if near > exact:
            raise InputError(
                f"structure: slab {slab} of the built cell repeats {near} times in the "
                f"supercell to within {NEAR_PERIOD_TOLERANCE_ANGSTROM} Å but {exact} times to "
                f"scan.symmetry.tolerance_angstrom = {tol} Å (shift lattice index "
                f"{lattice.index}), as after a build relaxation of a twist or coincidence cell; "
                "a grid over the supercell would alias that landscape: build the cell unrelaxed "
                "(a large structure.fmax_ev_per_angstrom, as "
                "examples/passivated-tip-h-diamond-graphene-approximants.yaml does)"
            )
    lateral = scan_grid(scan.grid, lattice.index)
    if lattice.index > 1:
        reindex(lattice, *lateral)
    a1, a2 = in_plane_vectors(reference)
    area = float(abs(a1[0] * a2[1] - a1[1] * a2[0]))
    record = {
        "index": int(lattice.index),
        "cell": "shift_lattice" if lattice.index > 1 else "interface",
        "grid_requested": [int(v) for v in scan.grid],
        "grid": list(lateral),
        "a1_angstrom": np.asarray(a1, float).tolist(),
        "a2_angstrom": np.asarray(a2, float).tolist(),
        "area_angstrom2": area,
        "interface_area_angstrom2": area,
    }
    return lattice, lateral, record
