"""The scan's worker entry points: what runs on a worker, with that worker's calculator.

Each function takes a picklable :class:`~flatcontact.ispes.relax.ScanContext` (the reference
interface, the calculator factory, the relaxation settings), builds or reuses the worker's
calculator (:func:`~flatcontact.ispes.relax.worker_calculator`, cached per worker thread; with the
root of the reference's Hessian the driver computed: :func:`~flatcontact.ispes.relax.context_calculator`)
and returns plain data to the driver, which alone writes files. The grid's points run through
:func:`flatcontact.ispes.relax.run_task`; the probe's units and checks run here.
"""

from __future__ import annotations

import functools

from flatcontact.ispes.grid import GridSpec, check_rows
from flatcontact.ispes.probe import (
    CompressionSegments,
    compress_chain,
    compress_segment,
    rigid_rows,
    stretch_chain,
)
from flatcontact.ispes.relax import (
    PointTask,
    ScanContext,
    context_calculator,
    relax_point,
    worker_calculator,
)
from flatcontact.ispes.work_of_separation import ideal_work_of_separation


def relax_column_point(reference, calc, relax, a, b, z, start, start_z) -> tuple:
    """One probe point: ``(energy_ev, normal_stress_gpa, force_calls, positions)``; the force
    calls include the reference's Hessian when this point computed it (the probe's cost)."""
    task = PointTask((0, 0, 0), a, b, z, start, (a, b) if start is not None else None, start_z)
    r = relax_point(reference, calc, task, relax)
    return r.energy_ev, r.normal_stress_gpa, r.force_calls + r.hessian_force_calls, r.positions


def _relax_one(context: ScanContext):
    """:func:`relax_column_point` with this worker's cached calculator (holding the driver's
    root of the reference's Hessian, :func:`~flatcontact.ispes.relax.context_calculator`)."""
    calc = context_calculator(context)
    return functools.partial(relax_column_point, context.reference, calc, context.settings)


def probe_chain_task(context: ScanContext, kind: str, shift, p_hi_gpa, stop_at_gpa):
    """Worker entry point: one chain of a probed column with this worker's cached
    calculator: ``kind`` ``"compress"`` (:func:`flatcontact.ispes.probe.compress_chain`) or
    ``"stretch"`` (:func:`flatcontact.ispes.probe.stretch_chain`, without the load at the
    reference thickness: :func:`flatcontact.ispes.probe.join_column` cuts it)."""
    relax_one = _relax_one(context)
    if kind == "compress":
        return compress_chain(relax_one, context.reference, shift, p_hi_gpa)
    return stretch_chain(relax_one, context.reference, shift, None, stop_at_gpa=stop_at_gpa)


def probe_segment_task(context: ScanContext, shift, p_hi_gpa, index: int):
    """Worker entry point: segment ``index`` of a probed column's compression
    (:func:`flatcontact.ispes.probe.compress_segment`) with this worker's cached calculator."""
    segments = CompressionSegments(p_hi_gpa)
    return compress_segment(
        _relax_one(context),
        context.reference,
        shift,
        p_hi_gpa,
        index * segments.n_steps,
        segments.n_steps,
    )


def rigid_rows_task(context: ScanContext, grid: GridSpec, rows: list[int]):
    """Worker entry point: the rigid single points of the lateral rows ``rows``
    (:func:`flatcontact.ispes.probe.rigid_rows`)."""
    calc = worker_calculator(context.factory, context.reference)
    return rigid_rows(context.reference, calc, grid, rows)


def work_of_separation_task(context: ScanContext, shift):
    """Worker entry point: the ideal work of separation at ``shift``
    (:func:`flatcontact.ispes.work_of_separation.ideal_work_of_separation`)."""
    calc = context_calculator(context)
    return ideal_work_of_separation(
        context.reference, context.factory, context.settings, shift, calc=calc
    )


def overlap_check_task(context: ScanContext, grid: GridSpec, items: list[tuple[float, int]]):
    """Worker entry point: :func:`flatcontact.ispes.grid.check_rows` of ``items``."""
    check_rows(context.reference, grid, items, spread_compression=context.settings.mode != "rigid")
