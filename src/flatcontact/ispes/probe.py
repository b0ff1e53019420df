"""Probe relaxations: the rigid energy and load of every stacking, and relaxed columns along z.

A pressure-range grid chooses its thicknesses from a few columns of the grid relaxed
along z. :func:`rigid_stackings` evaluates every lateral shift once, unrelaxed, at the
reference thickness; :func:`probed_stackings` picks the extreme columns from it (the
lowest and highest energy, the most and least repulsive); :func:`probe_column` relaxes
one column from compression up to separation (a :class:`ColumnProbe`: energies in eV,
loads in GPa, > 0 pressed, thicknesses in Å ascending). The thicknesses are chosen from
the probes in :mod:`flatcontact.ispes.thicknesses`, the work of separation in
:mod:`flatcontact.ispes.separation`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np
from ase import Atoms

from flatcontact.foundation.errors import InputError
from flatcontact.ispes.contract import cell_area
from flatcontact.ispes.geometry import in_plane_vectors, place_slab2, thickness
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.relax import normal_stress_gpa, start_afresh
from flatcontact.potentials.guarded import CalculatorFailure, failing_at


@dataclasses.dataclass(frozen=True)
class ColumnProbe:
    """Relaxed energies and loads along z at one lateral stacking (ascending z)."""

    shift: tuple[float, float]
    thickness_angstrom: np.ndarray
    energy_ev: np.ndarray
    normal_stress_gpa: np.ndarray
    force_calls: int
    area_angstrom2: float

    def as_dict(self) -> dict:
        return {
            "shift": list(self.shift),
            "thickness_angstrom": self.thickness_angstrom.tolist(),
            "energy_ev": self.energy_ev.tolist(),
            "normal_stress_gpa": self.normal_stress_gpa.tolist(),
            "force_calls": self.force_calls,
            "area_angstrom2": self.area_angstrom2,
        }

    @classmethod
    def from_dict(cls, d: dict) -> ColumnProbe:
        return cls(
            shift=tuple(d["shift"]),
            thickness_angstrom=np.asarray(d["thickness_angstrom"], dtype=float),
            energy_ev=np.asarray(d["energy_ev"], dtype=float),
            normal_stress_gpa=np.asarray(d["normal_stress_gpa"], dtype=float),
            force_calls=int(d["force_calls"]),
            area_angstrom2=float(d["area_angstrom2"]),
        )


@dataclasses.dataclass(frozen=True)
class RigidStackings:
    """Rigid (unrelaxed) energy (eV) and normal load (GPa, > 0 pressed) of every lateral
    grid shift at the reference thickness, shape ``(n_a, n_b)``; NaN where the slabs overlap."""

    energy_ev: np.ndarray
    normal_stress_gpa: np.ndarray


def rigid_stackings(reference: Atoms, calc, grid: GridSpec) -> RigidStackings:
    """One single-point evaluation per lateral grid shift at the reference thickness.

    The load is the net z-force on slab 2 per area
    (:func:`flatcontact.ispes.relax.normal_stress_gpa`, the scan's own definition).
    """
    energy, load = rigid_rows(reference, calc, grid, range(grid.n_a))
    return RigidStackings(energy, load)


def rigid_rows(reference: Atoms, calc, grid: GridSpec, rows) -> tuple[np.ndarray, np.ndarray]:
    """The rigid energies (eV) and loads (GPa) of :func:`rigid_stackings` for the shifts
    ``shift_a`` of the indices ``rows`` only: arrays of shape ``(len(rows), n_b)`` (the
    scan with many workers evaluates the rows on its workers)."""
    z_ref = thickness(reference)
    sa, sb = grid.shifts()
    rows = list(rows)
    energy = np.full((len(rows), grid.n_b), np.nan)
    load = np.full((len(rows), grid.n_b), np.nan)
    for i, row in enumerate(rows):
        a = sa[row]
        for j, b in enumerate(sb):
            try:
                atoms = place_slab2(reference, float(a), float(b), z_ref)
            except InputError:
                continue
            start_afresh(calc)  # a function of the stacking alone, whatever ran before
            atoms.calc = calc
            where = f"rigid single point at shift ({a:.4g}, {b:.4g}), thickness {z_ref:.4g} Å"
            with failing_at(where):
                energy[i, j] = atoms.get_potential_energy()
                load[i, j] = normal_stress_gpa(atoms, atoms.get_forces(apply_constraint=False))
            atoms.calc = None
    return energy, load


def _first_extreme(values: np.ndarray, grid: GridSpec, highest: bool) -> tuple[float, float]:
    """Shift of the smallest (largest) finite value; ties (1e-12) go to the first in grid order."""
    v = np.asarray(values, dtype=float)
    if not np.any(np.isfinite(v)):
        raise InputError(
            "probe column: the slabs overlap at every lateral shift of the reference thickness"
        )
    flat = v.ravel()
    if highest:
        k = int(np.flatnonzero(flat >= np.nanmax(flat) - 1e-12)[0])
    else:
        k = int(np.flatnonzero(flat <= np.nanmin(flat) + 1e-12)[0])
    sa, sb = grid.shifts()
    i, j = np.unravel_index(k, v.shape)
    return float(sa[i]), float(sb[j])


def extreme_stackings(
    energies: np.ndarray, grid: GridSpec
) -> tuple[tuple[float, float], tuple[float, float]]:
    """The lateral shifts of the lowest and of the highest rigid energy (NaN = overlap, skipped).

    Ties go to the first shift in (shift_a, shift_b) order within 1e-12 eV. Returns
    ``(lowest, highest)``; they coincide for a landscape without corrugation.
    """
    return _first_extreme(energies, grid, False), _first_extreme(energies, grid, True)


def probed_stackings(
    rigid: RigidStackings, grid: GridSpec
) -> list[tuple[str, tuple[float, float]]]:
    """The columns a pressure-range grid probes, as ``(role, shift)``, duplicates removed.

    ``"lowest energy"`` first (the paper's probe, which also gives the adhesion), then
    ``"highest energy"``, ``"most repulsive"`` and ``"least repulsive"`` (the largest and
    the smallest rigid load at the reference thickness): the columns whose loads at a
    given z are the extremes of the grid, so thicknesses that bracket the requested
    loads at them bracket them at the other stackings too.
    """
    wanted = [
        ("lowest energy", _first_extreme(rigid.energy_ev, grid, False)),
        ("highest energy", _first_extreme(rigid.energy_ev, grid, True)),
        ("most repulsive", _first_extreme(rigid.normal_stress_gpa, grid, True)),
        ("least repulsive", _first_extreme(rigid.normal_stress_gpa, grid, False)),
    ]
    out: list[tuple[str, tuple[float, float]]] = []
    for role, shift in wanted:
        if all(shift != s for _, s in out):
            out.append((role, shift))
    return out


#: default z offsets (Å, relative to the reference thickness) for probing tension and separation
_UP_OFFSETS = np.concatenate(
    [np.arange(1, 11) * 0.1, 1.0 + np.arange(1, 13) * 0.25, 4.0 + np.arange(1, 17) * 1.0]
)


@dataclasses.dataclass(frozen=True)
class ColumnChain:
    """One chain of a probed column: relaxed points in the order relaxed, each warm-started
    from the one before (the first cold). Thicknesses in Å, energies in eV, loads in GPa."""

    thickness_angstrom: tuple[float, ...]
    energy_ev: tuple[float, ...]
    normal_stress_gpa: tuple[float, ...]
    force_calls: tuple[int, ...]
    #: a compression segment (:func:`compress_segment`) that ended where the slabs overlap:
    #: the message; None otherwise
    overlap: str | None = None


def compress_chain(
    relax: Callable[[float, float, float, np.ndarray | None, float | None], tuple],
    reference: Atoms,
    shift: tuple[float, float],
    p_hi_gpa: float,
    dz_down_angstrom: float = 0.1,
    max_down_steps: int = 80,
) -> ColumnChain:
    """The compression of a column: the reference thickness (cold start), then steps of
    ``dz_down_angstrom`` down, each warm-started from the last, until the load reaches
    ``p_hi_gpa`` (GPa). The first point is the column's load at the reference thickness."""
    z_ref = thickness(reference)
    a, b = shift
    e, p, n, pos = relax(a, b, z_ref, None, None)
    out = [(z_ref, e, p, n)]
    start, start_z = pos, z_ref
    k = 0
    while p < p_hi_gpa:
        k += 1
        if k > max_down_steps:
            raise InputError(_too_far_message(p_hi_gpa, max_down_steps, dz_down_angstrom, p))
        z = z_ref - k * dz_down_angstrom
        try:
            e, p, n, pos = relax(a, b, z, start, start_z)
        except CalculatorFailure:
            raise  # the user's calculator failed: not an overlap
        except InputError as exc:
            raise InputError(_overlap_message(p_hi_gpa, exc)) from None
        out.append((z, e, p, n))
        start, start_z = pos, z
    return ColumnChain(*(tuple(v) for v in zip(*out, strict=True)))


#: Thickness steps of one segment when a column's compression runs as several chains
#: (:func:`compress_segment`, :class:`CompressionSegments`: the scan does it with many
#: workers). Each segment starts cold at its first thickness, which costs more than a warm
#: step (quartz, paper preset: 65-90 force calls cold against ~30 warm per 0.1 Å step), so
#: shorter segments shorten the longest chain but add work.
COMPRESS_SEGMENT_STEPS = 3


def _overlap_message(p_hi_gpa: float, exc: Exception) -> str:
    return f"p-range-gpa: the slabs overlap before the load reaches {p_hi_gpa} GPa ({exc})"


def _too_far_message(p_hi_gpa: float, max_down_steps: int, dz: float, p: float) -> str:
    return (
        f"p-range-gpa: the load did not reach {p_hi_gpa} GPa within {max_down_steps * dz:.3g} Å "
        f"of compression (reached {p:.3g} GPa)"
    )


def compress_segment(
    relax: Callable[[float, float, float, np.ndarray | None, float | None], tuple],
    reference: Atoms,
    shift: tuple[float, float],
    p_hi_gpa: float,
    first_step: int,
    n_steps: int = COMPRESS_SEGMENT_STEPS,
    dz_down_angstrom: float = 0.1,
    max_down_steps: int = 80,
) -> ColumnChain:
    """Steps ``first_step`` … ``first_step + n_steps - 1`` of a column's compression
    (z = z_ref − k·``dz_down_angstrom``, at most ``max_down_steps``), the first started
    cold, each next warm-started from the last, ending after the first whose load reaches
    ``p_hi_gpa`` (GPa). Slabs that overlap end the segment with the message in ``overlap``
    (raised by :meth:`CompressionSegments.join` only if the column needs that thickness),
    except at the reference thickness (step 0), which raises as :func:`compress_chain` does.

    Segment 0 with ``n_steps`` > ``max_down_steps`` is :func:`compress_chain` itself; a
    later segment differs from the sequential column only through its cold start (a
    relaxation from another start, equal within the force tolerance).
    """
    z_ref = thickness(reference)
    a, b = shift
    out = []
    start, start_z = None, None
    overlap = None
    for k in range(first_step, min(first_step + n_steps, max_down_steps + 1)):
        z = z_ref - k * dz_down_angstrom
        try:
            e, p, n, pos = relax(a, b, z, start, start_z)
        except CalculatorFailure:
            raise  # the user's calculator failed: not an overlap
        except InputError as exc:
            if k == 0:
                raise
            overlap = _overlap_message(p_hi_gpa, exc)
            break
        out.append((z, e, p, n))
        start, start_z = pos, z
        if p >= p_hi_gpa:
            break
    fields = tuple(tuple(v) for v in zip(*out, strict=True)) if out else ((), (), (), ())
    return ColumnChain(*fields, overlap=overlap)


class CompressionSegments:
    """A column's compression run as segments of ``n_steps`` thickness steps
    (:func:`compress_segment`), each a chain of its own, and joined in order.

    The schedule a driver follows (the scan with many workers, and
    ``benchmarks/schedule_model.py``, which replays it): :meth:`launch` names the next
    segment to start, as long as no finished segment has reached ``p_hi_gpa`` (or the slabs'
    overlap) and the steps are not exhausted; :meth:`add` takes a finished segment;
    :meth:`join` is the compression once every segment up to the first that reaches the
    load is in. Which segments were started beyond it depends on timing; the result does not.
    """

    def __init__(
        self,
        p_hi_gpa: float,
        n_steps: int = COMPRESS_SEGMENT_STEPS,
        dz_down_angstrom: float = 0.1,
        max_down_steps: int = 80,
    ):
        if n_steps < 1:
            raise InputError(f"n_steps: expected at least one step per segment, got {n_steps}")
        self.p_hi_gpa = float(p_hi_gpa)
        self.n_steps = int(n_steps)
        self.dz = float(dz_down_angstrom)
        self.max_down_steps = int(max_down_steps)
        self.segments: dict[int, ColumnChain] = {}
        self.launched = 0

    def _ends(self, chain: ColumnChain) -> bool:
        return chain.overlap is not None or any(p >= self.p_hi_gpa for p in chain.normal_stress_gpa)

    def wants_more(self) -> bool:
        """Whether a further segment may be needed: none finished has ended the column and
        the next one starts within ``max_down_steps``."""
        if any(self._ends(c) for c in self.segments.values()):
            return False
        return self.launched * self.n_steps <= self.max_down_steps

    def launch(self) -> int:
        """The index of the next segment to start (steps ``index * n_steps`` on)."""
        self.launched += 1
        return self.launched - 1

    def add(self, index: int, chain: ColumnChain) -> None:
        self.segments[index] = chain

    def join(self) -> ColumnChain | None:
        """The compression (as :func:`compress_chain` returns it), or None while a segment
        it needs is missing. Raises the sequential chain's InputError when the slabs overlap
        before the load is reached or the load is not reached within ``max_down_steps``."""
        out: list[tuple] = []
        j = 0
        while j * self.n_steps <= self.max_down_steps:
            chain = self.segments.get(j)
            if chain is None:
                return None
            for point in zip(
                chain.thickness_angstrom,
                chain.energy_ev,
                chain.normal_stress_gpa,
                chain.force_calls,
                strict=True,
            ):
                out.append(point)
                if point[2] >= self.p_hi_gpa:
                    return ColumnChain(*(tuple(v) for v in zip(*out, strict=True)))
            if chain.overlap is not None:
                raise InputError(chain.overlap)
            j += 1
        raise InputError(
            _too_far_message(self.p_hi_gpa, self.max_down_steps, self.dz, float(out[-1][2]))
        )


def next_segments(plans: list[CompressionSegments], slots: int) -> list[tuple[int, int]]:
    """The compression segments to start in ``slots`` free worker slots, as ``(column,
    segment)``: each to the column that wants more (:meth:`CompressionSegments.wants_more`)
    and has started the fewest, ties to the first column. The scan calls it with the free
    workers when the probe starts and with one slot whenever a probe chain finishes."""
    out = []
    for _ in range(slots):
        wanting = [c for c, plan in enumerate(plans) if plan.wants_more()]
        if not wanting:
            break
        c = min(wanting, key=lambda c: (plans[c].launched, c))
        out.append((c, plans[c].launch()))
    return out


def _stretch_stop(
    p_min: float, p: float, stop_at_gpa: float | None, separated_gpa: float
) -> tuple[bool, float]:
    """The stretching's stop rule after a point of load ``p``: ``(stop, new p_min)``.

    Past the tensile maximum (p above the smallest load so far, ``p_min``) a column with a
    ``stop_at_gpa`` stops, as one at or below it does; a column without stops once the
    slabs are separated (|p| < ``separated_gpa`` after a tension). Stopping is monotonic in
    ``p_min``: a smaller ``p_min`` stops at the same point or earlier.
    """
    past_min = p > p_min
    p_min = min(p_min, p)
    if stop_at_gpa is not None and (p <= stop_at_gpa or past_min):
        return True, p_min
    return past_min and p_min < 0 and abs(p) < separated_gpa, p_min


def stretch_chain(
    relax: Callable[[float, float, float, np.ndarray | None, float | None], tuple],
    reference: Atoms,
    shift: tuple[float, float],
    p_ref_gpa: float | None,
    separated_gpa: float = 1e-4,
    stop_at_gpa: float | None = None,
) -> ColumnChain:
    """The stretching of a column: the default offsets above the reference thickness, the
    first cold, each next warm-started from the last, until :func:`_stretch_stop`.

    ``p_ref_gpa`` is the load at the reference thickness (the compression's first point).
    Without it (``None``: the two chains run at the same time) the rule starts from
    ``p_min = +inf``, which stops at the same point or later
    (:func:`_stretch_stop` is monotonic); :func:`join_column` cuts the chain where the rule
    with the load at the reference stops, so the column equals the sequential one exactly.
    """
    z_ref = thickness(reference)
    a, b = shift
    out = []
    start, start_z = None, None
    p_min = np.inf if p_ref_gpa is None else p_ref_gpa
    for dz in _UP_OFFSETS:
        z = z_ref + float(dz)
        e, p, n, pos = relax(a, b, z, start, start_z)
        out.append((z, e, p, n))
        start, start_z = pos, z
        stop, p_min = _stretch_stop(p_min, p, stop_at_gpa, separated_gpa)
        if stop:
            break
    return ColumnChain(*(tuple(v) for v in zip(*out, strict=True)))


def join_column(
    reference: Atoms,
    shift: tuple[float, float],
    compressed: ColumnChain,
    stretched: ColumnChain,
    separated_gpa: float = 1e-4,
    stop_at_gpa: float | None = None,
) -> ColumnProbe:
    """The :class:`ColumnProbe` of a column from its two chains (ascending z).

    The stretching is cut after the first point where :func:`_stretch_stop`, started from
    the compression's load at the reference thickness, stops: the points a chain run
    without that load relaxed beyond it are dropped (their warm starts came from the same
    points, so the kept ones equal the sequential column's).
    """
    p_min = compressed.normal_stress_gpa[0]
    keep = len(stretched.thickness_angstrom)
    for k, p in enumerate(stretched.normal_stress_gpa):
        stop, p_min = _stretch_stop(p_min, p, stop_at_gpa, separated_gpa)
        if stop:
            keep = k + 1
            break
    z = np.concatenate([compressed.thickness_angstrom, stretched.thickness_angstrom[:keep]])
    e = np.concatenate([compressed.energy_ev, stretched.energy_ev[:keep]])
    p = np.concatenate([compressed.normal_stress_gpa, stretched.normal_stress_gpa[:keep]])
    calls = sum(compressed.force_calls) + sum(stretched.force_calls[:keep])
    order = np.argsort(z, kind="stable")
    a1, a2 = in_plane_vectors(reference)
    return ColumnProbe(
        shift=(float(shift[0]), float(shift[1])),
        thickness_angstrom=z[order],
        energy_ev=e[order],
        normal_stress_gpa=p[order],
        force_calls=int(calls),
        area_angstrom2=cell_area(a1, a2),
    )


def probe_column(
    relax: Callable[[float, float, float, np.ndarray | None, float | None], tuple],
    reference: Atoms,
    shift: tuple[float, float],
    p_hi_gpa: float,
    dz_down_angstrom: float = 0.1,
    max_down_steps: int = 80,
    separated_gpa: float = 1e-4,
    stop_at_gpa: float | None = None,
) -> ColumnProbe:
    """Relax a column at ``shift`` from compression up to separation.

    Two chains of warm starts (:func:`compress_chain`, then :func:`stretch_chain`, which
    starts cold above the reference thickness), one after the other; the scan driver runs
    them on two workers at once and joins them with :func:`join_column` (the same column).

    Parameters
    ----------
    relax
        ``relax(shift_a, shift_b, z, start_positions, start_z) -> (energy_ev,
        normal_stress_gpa, force_calls, positions)``; consecutive probe points are
        warm-started from the previous one.
    reference
        The reference interface (its thickness is the starting z).
    shift
        Lateral stacking of the column.
    p_hi_gpa
        Compress in steps of ``dz_down_angstrom`` until the load reaches this value.
    separated_gpa
        Beyond the tensile maximum, stop once |p| is below this (GPa) — the slabs are
        separated — or at the last default offset (reference + 20 Å).
    stop_at_gpa
        Stop stretching once the load is at most this (GPa) or past the tensile maximum.
    """
    down = compress_chain(relax, reference, shift, p_hi_gpa, dz_down_angstrom, max_down_steps)
    up = stretch_chain(
        relax, reference, shift, down.normal_stress_gpa[0], separated_gpa, stop_at_gpa
    )
    return join_column(reference, shift, down, up, separated_gpa, stop_at_gpa)
