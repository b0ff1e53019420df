"""Where the sliding path starts when the landscape has (nearly) degenerate inequivalent minima.

The paper's shear strength τ is the largest resisting force on the way out of
the *initial* minimum, the global minimum of the constant-pressure landscape.
A landscape may have two or more inequivalent minima per cell (not related by
a lattice vector) of equal or nearly equal depth: e.g. the two hollow sites of
a hexagonal interface, which any inversion-symmetric landscape
(``e(r) = e(-r)``) makes exactly degenerate. Which of them is "the global
minimum" is then decided by round-off or by noise far below what the data
resolve, while τ from each of them differs (pulling along ``+d`` from one
hollow is pulling along ``-d`` from the other): τ flipped between 60.5 and
180.4 MPa with the thickness grid on such a landscape.

Rule (deterministic, independent of round-off, the same at every load):

1. all inequivalent local minima in the cell are found on the exact periodic
   interpolant (:meth:`.PeriodicSurface.local_minima`; robust to a constant
   added to the landscape, so the global minimum is always among them);
2. minima within the **degeneracy tolerance** ``δ = max(2 ε(P),``
   ``DEGENERACY_FLOOR_MEV_PER_A2, F)`` of the lowest are *near-degenerate*
   (``ε(P)`` the energy noise of the load, :mod:`.noise`; the same ``2 ε``
   below which a dip is not a minimum in σ_MSS; ``F`` the grid's measured
   energy noise floor where it carries one, the ISPES attribute
   ``energy_floor_mev_per_a2``: the approximant study writes the larger of the
   round-off and the relaxation floor of each cell, 2.7e-4 to 4.7e-4 meV/Å² on
   the rigid-layers H-diamond(111)/graphene cells at fmax 0.005 eV/Å, above the
   fixed window; a plain run measures no floor and uses ``max(2 ε, floor)``).
   The data cannot tell which of them is the ground state. With the landscape's symmetry classes
   (:mod:`.stackings`), every minimum **symmetry-equivalent** to a
   near-degenerate one (mapped onto it by an operation the landscape keeps
   within 2 %, and within 2 % of the landscape's range in energy) is a start
   too, whatever its energy difference: a splitting of equivalent stackings
   (AB/BA made unequal by pinning or round-off) then cannot add or remove a
   start from one load to the next;
3. the path and τ, σ_MSS and the shear stiffness are computed from each
   start (``tau_by_start_mpa`` etc. in the outputs), the starts ordered by
   their fractional position ``(s_a, s_b)`` in the cell;
4. the reported τ is the **largest τ over the starts**: the pull that sets
   the slider sliding out of its rest position whichever of the
   indistinguishable minima it sits in. Equal τ (within ``1e-9`` relative,
   or ``TAU_SPREAD_RTOL`` between symmetry-equivalent starts) go to the
   start nearest the previous load's reported one (modulo the lattice), so
   the representative is followed continuously through the loads; at the
   first load, or at equal distance, to the lower minimum, then to the first
   in cell order. The reported path, barriers, σ_MSS and shear stiffness are
   those of that start. With a single start nothing changes: the path starts
   from the global minimum as in the paper. Minima equivalent by an operation
   that keeps the pulling direction (``R d = d``, e.g. a lattice translation
   or a mirror along d; or AB/BA of a six-fold landscape pulled along a
   lattice vector, via inversion and the mirror normal to d) give the same τ
   by construction; equivalent by one that does not (AB/BA of a hexagonal
   landscape pulled along y), τ from one is τ from the other along ``R⁻¹ d``,
   and the largest is reported;
5. a :class:`DegenerateMinimaWarning` gives every start's energy and τ when
   the τ differ by more than ``TAU_SPREAD_RTOL`` of the largest.

σ_MSS is a whole-period quantity: when the path out of one start passes
through the others, one period from any start climbs the same barriers over
the same distance, and σ is the same from every start (checked by the tests
and reported per start). Only the order of the climbs differs, and τ (the
first climb) with it; ``τ_period`` (the largest force over a period) is then
the same from every start and equals the reported τ.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass

import numpy as np

from flatcontact.analysis.diagnostics import DegenerateMinimaWarning
from flatcontact.analysis.friction import FrictionResult, friction_along_path
from flatcontact.analysis.path import SlidingPath, zero_perpendicular_force_path
from flatcontact.analysis.periodic import PeriodicSurface
from flatcontact.analysis.stackings import SYMMETRY_TOLERANCE, Stackings
from flatcontact.foundation import units

#: Smallest degeneracy tolerance (meV/Å²), used where the energy noise is unknown or smaller.
DEGENERACY_FLOOR_MEV_PER_A2 = 1.0e-4
#: Warn when the τ of near-degenerate starts differ by more than this fraction of the largest.
TAU_SPREAD_RTOL = 1.0e-3
#: The rule, as stored with the outputs.
TAU_START_RULE = (
    "tau from the global minimum; if other inequivalent minima lie within the degeneracy "
    "tolerance max(2 eps, floor, the grid's measured noise floor) of it, or minima are symmetry-equivalent to it (landscape "
    "symmetry within 2%), the largest tau over those starts (equal tau: the start nearest the "
    "previous load's, then the lower minimum)"
)
#: τ within this relative difference count as equal when choosing the start.
TAU_TIE_RTOL = 1.0e-9


@dataclass(frozen=True)
class StartOutcome:
    """The path and friction from one near-degenerate minimum (surface energies in eV/Å²)."""

    xy_angstrom: np.ndarray  #: the minimum, Cartesian, reduced into the cell
    energy_ev_per_a2: float  #: the landscape's value there
    above_lowest_ev_per_a2: float  #: energy above the lowest minimum (>= 0)
    path: SlidingPath
    friction: FrictionResult

    @property
    def tau_mpa(self) -> float:
        """τ from this start (MPa)."""
        return self.friction.tau_mpa

    @property
    def above_lowest_mev_per_a2(self) -> float:
        """Energy above the lowest minimum (meV/Å²)."""
        return self.above_lowest_ev_per_a2 * units.EV_PER_A2_TO_MEV_PER_A2


def degeneracy_tolerance_ev_per_a2(
    barrier_threshold_ev_per_a2: float, measured_floor_ev_per_a2: float = float("nan")
) -> float:
    """δ = max(2 ε(P), floor, F) in eV/Å² (module rule, step 2).

    ``barrier_threshold_ev_per_a2`` is 2 ε (0 or NaN if unknown); ``measured_floor_ev_per_a2``
    the grid's measured energy noise floor F (NaN if none was measured: then δ = max(2 ε,
    floor)). Minima closer than F are not distinguishable, whatever the fixed window says.
    """
    floor = DEGENERACY_FLOOR_MEV_PER_A2 / units.EV_PER_A2_TO_MEV_PER_A2
    thr = float(barrier_threshold_ev_per_a2)
    measured = float(measured_floor_ev_per_a2)
    values = [floor] + [v for v in (thr, measured) if np.isfinite(v)]
    return max(values)


def near_degenerate_minima(
    minima: list[tuple[np.ndarray, float]], tolerance_ev_per_a2: float
) -> list[tuple[np.ndarray, float]]:
    """The minima (sorted lowest first, as from ``local_minima``) within the tolerance of the lowest."""
    if not minima:
        return []
    lowest = minima[0][1]
    return [m for m in minima if m[1] - lowest <= tolerance_ev_per_a2]


def _cell_order(surface: PeriodicSurface, xy: np.ndarray) -> tuple[float, float]:
    """Sort key of a start: its fractional position in the cell, rounded (round-off proof)."""
    s = np.round(surface.fractional(xy), 6) % 1.0
    return float(s[0]), float(s[1])


def choose_start(
    taus: np.ndarray,
    energies: np.ndarray,
    distances: np.ndarray | None = None,
    classes: np.ndarray | None = None,
) -> int:
    """Index of the reported start: largest τ; equal τ → nearest the previous start → lower energy.

    τ within ``TAU_TIE_RTOL`` of the largest are equal; with ``classes`` (symmetry
    class per start, :mod:`.stackings`) so are the starts of the largest τ's class
    within ``TAU_SPREAD_RTOL`` (equivalent minima, whose τ differ only by round-off
    or a symmetry breaking below the symmetry tolerance). ``distances`` (Å, to the
    previous load's reported start modulo the lattice) makes the choice among equal
    τ continuous in the load; without it, or at equal distance (1e-6 Å), the lower
    minimum, then the first.
    """
    taus = np.asarray(taus, float)
    energies = np.asarray(energies, float)
    top = float(np.max(taus))
    tied = taus >= top - TAU_TIE_RTOL * max(abs(top), 1e-300)
    if classes is not None:
        classes = np.asarray(classes)
        best = classes[int(np.argmax(taus))]
        tied |= (classes == best) & (taus >= top - TAU_SPREAD_RTOL * max(abs(top), 1e-300))
    idx = np.flatnonzero(tied)
    if distances is not None:
        d = np.round(np.asarray(distances, float)[idx], 6)
        idx = idx[d == d.min()]
    return int(idx[np.argmin(energies[idx])])


def paths_from_near_degenerate_minima(
    surface: PeriodicSurface,
    direction_deg: float,
    tolerance_ev_per_a2: float,
    min_barrier_ev_per_a2: float = 0.0,
    max_length_angstrom: float | None = None,
    timings_s: dict[str, float] | None = None,
    stackings: Stackings | None = None,
    previous_xy: np.ndarray | None = None,
) -> tuple[tuple[StartOutcome, ...], int]:
    """Path and friction from every near-degenerate minimum, and the index of the reported one.

    Warnings raised while tracking a path (e.g. :class:`PathNotPeriodicWarning`)
    are passed on for the reported start only.

    Parameters
    ----------
    surface
        Constant-pressure landscape in eV/Å².
    direction_deg
        Pulling direction (degrees from x).
    tolerance_ev_per_a2
        Degeneracy tolerance δ (:func:`degeneracy_tolerance_ev_per_a2`).
    min_barrier_ev_per_a2
        Noise floor of :func:`.friction_along_path`.
    max_length_angstrom
        Tracking limit of the path.
    timings_s
        If given, seconds spent are added to its ``"path"`` (minima search and
        tracking) and ``"friction"`` entries.
    stackings
        The landscape's stationary points and symmetry classes (:mod:`.stackings`): the
        minima symmetry-equivalent to a near-degenerate one are starts too, whatever
        their energy difference (module rule, step 2).
    previous_xy
        The previous load's reported start (Å): among equal τ the nearest one is
        reported (:func:`choose_start`).
    """
    clock = time.perf_counter()
    minima = near_degenerate_minima(surface.local_minima(), tolerance_ev_per_a2)
    if not minima:  # no isolated minimum found: fall back on the refined lowest sample
        minima = [surface.global_minimum()]
    classes = [-1] * len(minima)
    if stackings is not None:
        minima, classes = _with_equivalent_minima(surface, minima, stackings)
    order = sorted(range(len(minima)), key=lambda i: _cell_order(surface, minima[i][0]))
    minima, classes = [minima[i] for i in order], [classes[i] for i in order]
    lowest = min(m[1] for m in minima)
    outcomes, caught_by_start = [], []
    spent = {"path": 0.0, "friction": 0.0}
    for xy, value in minima:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            path = zero_perpendicular_force_path(
                surface, direction_deg, start_xy=xy, max_length_angstrom=max_length_angstrom
            )
            spent["path"] += time.perf_counter() - clock
            clock = time.perf_counter()
            fr = friction_along_path(path, min_barrier_ev_per_a2=min_barrier_ev_per_a2)
            spent["friction"] += time.perf_counter() - clock
            clock = time.perf_counter()
        caught_by_start.append(caught)
        outcomes.append(StartOutcome(np.asarray(xy, float), float(value), value - lowest, path, fr))
    distances = None
    if previous_xy is not None:
        distances = np.array(
            [_lattice_distance(surface, o.xy_angstrom, previous_xy) for o in outcomes]
        )
    k = choose_start(
        np.array([o.friction.tau_ev_per_a3 for o in outcomes]),
        np.array([o.energy_ev_per_a2 for o in outcomes]),
        distances,
        np.array(classes) if stackings is not None else None,
    )
    for w in caught_by_start[k]:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    if timings_s is not None:
        for key, value in spent.items():
            timings_s[key] = timings_s.get(key, 0.0) + value
    return tuple(outcomes), k


def _lattice_distance(surface: PeriodicSurface, xy: np.ndarray, other: np.ndarray) -> float:
    """Distance (Å) between two points modulo the lattice (minimum image)."""
    ds = surface.fractional(np.asarray(xy, float) - np.asarray(other, float))
    ds -= np.round(ds)
    return float(np.linalg.norm(surface.cartesian(ds)))


def _with_equivalent_minima(
    surface: PeriodicSurface, minima: list[tuple[np.ndarray, float]], stackings: Stackings
) -> tuple[list[tuple[np.ndarray, float]], list[int]]:
    """The near-degenerate minima plus every minimum symmetry-equivalent to one of them.

    Returns the minima and their symmetry class (-1: not matched to a stationary point).
    """
    scale = float(np.min(np.linalg.norm(surface.lattice, axis=0)))
    tol = 1e-4 * scale
    pts = [p for p in stackings.points if p.kind == "minimum"]

    def match(xy: np.ndarray) -> int:
        for p in pts:
            if _lattice_distance(surface, xy, p.xy_angstrom) < tol:
                return p.symmetry_class
        return -1

    classes = [match(xy) for xy, _ in minima]
    out = list(minima)
    spread = float(np.ptp(surface.values))
    reach = max(m[1] for m in minima) + SYMMETRY_TOLERANCE * spread
    for p in pts:
        if (
            p.symmetry_class in classes
            and p.energy <= reach
            and all(_lattice_distance(surface, p.xy_angstrom, xy) >= tol for xy, _ in out)
        ):
            out.append((np.asarray(p.xy_angstrom, float), float(surface(p.xy_angstrom))))
            classes.append(p.symmetry_class)
    return out, classes


def warn_if_tau_depends_on_start(
    outcomes: tuple[StartOutcome, ...],
    selected: int,
    p_gpa: float,
    tolerance_ev_per_a2: float,
    source: str,
) -> None:
    """:class:`DegenerateMinimaWarning` naming every start's τ if they differ noticeably.

    The message states how far apart the starts' energies are (the largest energy above the
    lowest, meV/Å²) next to the degeneracy tolerance: a start symmetry-equivalent to a
    near-degenerate one is a start whatever its energy (module rule, step 2), so the two
    numbers differ when pinning or round-off splits equivalent stackings.
    """
    if len(outcomes) < 2:
        return
    taus = np.array([o.tau_mpa for o in outcomes])
    if np.ptp(taus) <= TAU_SPREAD_RTOL * np.max(np.abs(taus)):
        return
    mev = units.EV_PER_A2_TO_MEV_PER_A2
    surface = outcomes[0].path.frame.surface
    parts = []
    for o in outcomes:
        s = surface.fractional(o.xy_angstrom)
        parts.append(
            f"τ = {o.tau_mpa:.4g} MPa from the minimum at s = ({s[0]:.3f}, {s[1]:.3f}) "
            f"({o.above_lowest_mev_per_a2:.2g} meV/Å² above the lowest; σ_MSS = "
            f"{o.friction.sigma_mss_mpa:.4g} MPa)"
        )
    spread = max(o.above_lowest_mev_per_a2 for o in outcomes)
    warnings.warn(
        f"{source} at P = {p_gpa:g} GPa: {len(outcomes)} minima, up to {spread:.2g} meV/Å² "
        f"apart, are near-degenerate (within {tolerance_ev_per_a2 * mev:.2g} meV/Å² of the "
        "lowest) or symmetry-equivalent to one that is, so the slider's τ depends on "
        f"which one it sits in: " + "; ".join(parts) + f". Reported τ = "
        f"{outcomes[selected].tau_mpa:.4g} MPa, the largest (the pull that starts sliding from "
        "either)",
        DegenerateMinimaWarning,
        stacklevel=4,
    )
