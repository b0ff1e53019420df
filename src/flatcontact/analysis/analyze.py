"""The whole ISPES analysis of one grid: constant-pressure maps → paths → τ, σ, G_int → load laws.

:func:`analyze_ispes` takes the grid, the loads and its choices
(:class:`~flatcontact.analysis.options.AnalysisOptions`, validated on construction), checks the
loads and the grid before any work, then for each target load ``P``:

1. the constant-pressure landscape on the grid (:mod:`.constant_pressure`),
   per area, in eV/Å², zeroed at the global minimum of the landscape at the
   lowest requested ``P`` (``energy_zero="lowest-p"``, the default), at each
   load's own minimum (``"each"``), or left absolute (``"none"``);
2. its exact periodic interpolant (:mod:`.periodic`), averaged over the interface's
   shift-space group when the grid stores one (symmetry-equal stackings equal to round-off);
3. the zero-perpendicular-force path from the global minimum along the pulling
   direction (:mod:`.path`) and, on request, the string-method MEP to the
   equivalent minimum that the path reaches; when other inequivalent minima
   lie within the noise of the global one, from each of them, reporting the
   largest τ (:mod:`.starts`, :class:`DegenerateMinimaWarning`);
4. τ, σ_MSS and the shear stiffness (:mod:`.friction`);
5. optionally the symmetry report (:mod:`.symmetry`);
6. the grid's estimate of its own error in τ, σ_MSS and G_int: steps 2–4 on a coarser grid
   taken from the same samples (:mod:`.grid_error`), with a :class:`GridResolutionWarning`
   where it exceeds :data:`~.grid_error.UNRESOLVED_FRACTION` of τ.

Finally the load laws (:mod:`.laws`). Timings per stage are recorded.
"""

from __future__ import annotations

import time
import warnings
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from flatcontact.analysis.constant_pressure import (
    DEFAULT_LOAD_SOURCE,
    LOAD_SOURCES,  # noqa: F401 (re-exported: the analysis's choices in one place)
    ConstantPressureISPES,
    constant_pressure,
)
from flatcontact.analysis.diagnostics import GridResolutionWarning, LoadNoiseWarning
from flatcontact.analysis.friction import FrictionResult
from flatcontact.analysis.grid_error import QUANTITIES, GridEstimate, estimate_grid_error
from flatcontact.analysis.laws import LoadLaws, fit_load_laws
from flatcontact.analysis.noise import NOISE_WARN_FRACTION
from flatcontact.analysis.options import (  # noqa: F401 (re-exported with the analysis)
    AUTO_DIRECTION,
    ENERGY_ZEROS,
    AnalysisOptions,
)
from flatcontact.analysis.path import (
    MinimumEnergyPath,
    SlidingPath,
    minimum_energy_path,
)
from flatcontact.analysis.periodic import PeriodicSurface, lattice_vectors, rectangular_supercell
from flatcontact.analysis.stackings import Stackings, analyze_stackings, lattice_vector_along
from flatcontact.analysis.starts import (
    TAU_START_RULE,
    StartOutcome,
    degeneracy_tolerance_ev_per_a2,
    paths_from_near_degenerate_minima,
    warn_if_tau_depends_on_start,
)
from flatcontact.analysis.symmetry import SymmetryReport, symmetry_report
from flatcontact.foundation import units
from flatcontact.foundation.errors import InputError
from flatcontact.ispes import contract

#: Lateral points per axis: a periodic interpolant needs the first harmonic (k = -1, 0, 1).
MIN_LATERAL_POINTS = 3
#: Attribute of a grid re-indexed onto one shift-lattice period and its index
#: (:func:`flatcontact.ispes.shift_lattice.to_shift_cell`; absent or 1: an ordinary cell).
SHIFT_LATTICE_INDEX_ATTR = "shift_lattice_index"


@dataclass(frozen=True)
class PressureAnalysis:
    """Everything computed at one load (surface and path energies in eV/Å²).

    ``minimum_xy_angstrom``, ``path`` and ``friction`` belong to the reported
    start ``starts[selected_start]``; ``starts`` holds every near-degenerate
    minimum's path and friction (one entry unless the landscape has
    inequivalent minima within the degeneracy tolerance, :mod:`.starts`).
    """

    p_gpa: float
    surface: PeriodicSurface
    minimum_xy_angstrom: np.ndarray
    path: SlidingPath
    friction: FrictionResult
    mep: MinimumEnergyPath | None
    symmetry: SymmetryReport | None
    starts: tuple[StartOutcome, ...] = ()
    selected_start: int = 0
    degeneracy_tolerance_ev_per_a2: float = float("nan")
    stackings: Stackings | None = None

    @property
    def barrier_along_direction_ev_per_a2(self) -> float:
        """Lowest MEP barrier (eV/Å²) to the start's image one lattice period along the pull."""
        if self.stackings is None:
            return float("nan")
        v = lattice_vector_along(self.surface.a1, self.surface.a2, self.path.direction_deg)
        return float("nan") if v is None else self.stackings.barrier_for(v)


@dataclass(frozen=True)
class AnalysisResult:
    """The analysis of one ISPES grid at a series of loads."""

    pressures: tuple[PressureAnalysis, ...]
    constant_pressure: ConstantPressureISPES
    laws: LoadLaws | None
    direction_deg: float
    form: str
    energy_zero: str
    energy_reference_ev_per_a2: float
    supercell: tuple[np.ndarray, np.ndarray] | None
    timings_s: dict[str, float] = field(default_factory=dict)
    load_source: str = DEFAULT_LOAD_SOURCE
    direction_rule: str = "given"
    tau_start_rule: str = TAU_START_RULE
    grid: GridEstimate | None = None  #: the grid's estimate of its own error (:mod:`.grid_error`)

    @property
    def noise(self):
        """Per-load noise estimate (:class:`flatcontact.analysis.noise.LoadNoise`)."""
        return self.constant_pressure.noise

    @property
    def p_gpa(self) -> np.ndarray:
        """The analysed loads (GPa), ascending."""
        return np.array([pa.p_gpa for pa in self.pressures])

    def column(self, name: str) -> np.ndarray:
        """``tau_mpa``, ``sigma_mss_mpa`` or ``shear_stiffness_gpa_per_nm`` per load."""
        return np.array([getattr(pa.friction, name) for pa in self.pressures])


def check_pressures(p_gpa: list[float] | np.ndarray) -> np.ndarray:
    """Finite, distinct loads in GPa, returned ascending; InputError otherwise."""
    p = np.atleast_1d(np.asarray(p_gpa, dtype=float))
    if p.size == 0:
        raise InputError("p_gpa: give at least one target pressure in GPa")
    if not np.all(np.isfinite(p)):
        raise InputError(f"p_gpa: expected finite pressures in GPa, got {p.tolist()}")
    if np.unique(p).size != p.size:
        raise InputError(f"p_gpa: pressures must be distinct, got {p.tolist()}")
    return np.sort(p)


def analyze_ispes(
    ds: xr.Dataset,
    p_gpa: list[float] | np.ndarray,
    options: AnalysisOptions | None = None,
    *,
    source: str = "ISPES grid",
) -> AnalysisResult:
    """Analyse an ISPES grid at the loads ``p_gpa`` (see module docstring).

    Parameters
    ----------
    ds
        Grid following the ``ispes.nc`` contract.
    p_gpa
        Target loads (GPa, positive when pressed).
    options
        How to analyse it (:class:`~flatcontact.analysis.options.AnalysisOptions`: direction,
        energy form, energy zero, load source, fit threshold, optional reports); ``None``: the
        defaults, the paper's analysis. A grid re-indexed onto one period of a twisted or
        coincidence cell's shift lattice (attribute ``shift_lattice_index`` > 1,
        :func:`flatcontact.ispes.shift_lattice.to_shift_cell`) has its stationary points named
        by kind and rank (``min1``, ``saddle1``, ``max1``), not AB/BA/SP/AA.
    source
        Name of the grid in messages.

    Raises
    ------
    InputError
        One line naming the parameter or option field (``p_gpa``, ``form``, ``energy_zero``,
        ...); the CLI and the run translate it to the flag or the settings path.
    """
    opts = AnalysisOptions() if options is None else options
    if not isinstance(opts, AnalysisOptions):
        raise InputError(f"options: expected an AnalysisOptions, got {type(opts).__name__}")
    p = check_pressures(p_gpa)
    _check_lateral_grid(ds, source)
    timings = {"constant_pressure": 0.0, "interpolation": 0.0, "path": 0.0, "friction": 0.0}
    timings.update({"mep": 0.0} if opts.with_mep else {})
    timings.update({"symmetry": 0.0} if opts.with_symmetry else {})
    timings.update({"stackings": 0.0} if opts.with_stackings else {})

    clock = time.perf_counter()
    cp = constant_pressure(
        ds,
        p,
        form=opts.form,
        allow_missing=opts.allow_missing,
        source=source,
        load_source=opts.load_source,
    )
    timings["constant_pressure"] = time.perf_counter() - clock
    group = contract.symmetry_operations(ds) if opts.symmetrise else []
    surfaces, refs = _zeroed_surfaces(cp, group, opts.energy_zero, timings)
    stackings = _stackings(ds, surfaces, opts.with_stackings, timings)
    direction_deg, direction_rule = opts.direction_deg, "given"
    if opts.auto_direction:
        direction_deg, direction_rule = _lowest_barrier_direction(stackings[0], cp.a1, float(p[0]))
    results = _per_load(ds, cp, surfaces, stackings, float(direction_deg), opts, source, timings)

    grid = None
    if opts.with_grid_error:
        clock = time.perf_counter()
        grid = estimate_grid_error(
            [cp.energy_ev_per_a2[i] - refs[i] for i in range(p.size)],
            cp.a1,
            cp.a2,
            group,
            p,
            {q: np.array([getattr(r.friction, q) for r in results]) for q in QUANTITIES},
            float(direction_deg),
            np.array([r.degeneracy_tolerance_ev_per_a2 for r in results]),
            np.asarray(cp.noise.barrier_threshold_ev_per_a2, float),
            opts.max_length_angstrom,
        )
        timings["grid_error"] = time.perf_counter() - clock
        _warn_grid(grid, source)

    laws = None
    if opts.threshold_gpa is not None:
        clock = time.perf_counter()
        tau = np.array([r.friction.tau_mpa for r in results])
        sigma = np.array([r.friction.sigma_mss_mpa for r in results])
        laws = fit_load_laws(p, tau, sigma, opts.threshold_gpa)
        timings["laws"] = time.perf_counter() - clock
    return AnalysisResult(
        pressures=tuple(results),
        constant_pressure=cp,
        laws=laws,
        direction_deg=float(direction_deg),
        form=opts.form,
        energy_zero=opts.energy_zero,
        energy_reference_ev_per_a2=float(refs[0]),
        supercell=rectangular_supercell(cp.a1, cp.a2),
        timings_s=timings,
        load_source=opts.load_source,
        direction_rule=direction_rule,
        grid=grid,
    )


def _check_lateral_grid(ds: xr.Dataset, source: str) -> None:
    """InputError unless the grid has :data:`MIN_LATERAL_POINTS` shifts along each axis."""
    n_lateral = (ds.sizes.get(contract.DIM_A, 0), ds.sizes.get(contract.DIM_B, 0))
    if min(n_lateral) < MIN_LATERAL_POINTS:
        raise InputError(
            f"{source}: lateral grid is {n_lateral[0]}×{n_lateral[1]} (shift_a × shift_b); "
            f"the periodic interpolation and the sliding path need at least "
            f"{MIN_LATERAL_POINTS} points per axis"
        )


def _zeroed_surfaces(
    cp: ConstantPressureISPES, group: list, energy_zero: str, timings: dict[str, float]
) -> tuple[list[PeriodicSurface], list[float]]:
    """Each load's periodic interpolant (symmetrised over ``group``) minus its energy zero
    (eV/Å², :attr:`AnalysisOptions.energy_zero`), and the zeros subtracted."""
    clock = time.perf_counter()

    def surface(values: np.ndarray) -> PeriodicSurface:
        return PeriodicSurface(values, cp.a1, cp.a2).symmetrised(group)

    raw = [surface(values) for values in cp.energy_ev_per_a2]
    minima = [surf.global_minimum()[1] for surf in raw]
    if energy_zero == "lowest-p":
        refs = [minima[0]] * len(raw)
    elif energy_zero == "each":
        refs = list(minima)
    else:
        refs = [0.0] * len(raw)
    surfaces = [surface(s.values - r) for s, r in zip(raw, refs, strict=True)]
    timings["interpolation"] = time.perf_counter() - clock
    return surfaces, refs


def _stackings(
    ds: xr.Dataset, surfaces: list[PeriodicSurface], wanted: bool, timings: dict[str, float]
) -> list[Stackings | None]:
    """Each load's stationary points (:mod:`.stackings`), or ``None`` per load if not wanted;
    named by stacking only on an ordinary cell (not a shift-lattice period)."""
    if not wanted:
        return [None] * len(surfaces)
    clock = time.perf_counter()
    site_names = int(ds.attrs.get(SHIFT_LATTICE_INDEX_ATTR, 1)) <= 1
    found = [analyze_stackings(surf, site_names=site_names) for surf in surfaces]
    timings["stackings"] = time.perf_counter() - clock
    return found


def _per_load(
    ds: xr.Dataset,
    cp: ConstantPressureISPES,
    surfaces: list[PeriodicSurface],
    stackings: list[Stackings | None],
    direction_deg: float,
    opts: AnalysisOptions,
    source: str,
    timings: dict[str, float],
) -> list[PressureAnalysis]:
    """Path, friction and the optional MEP and symmetry report at each load, from the
    near-degenerate minima (:mod:`.starts`); each load's search starts near the previous one's."""
    floor = cp.noise.barrier_threshold_ev_per_a2
    # the grid's measured noise floor (approximant cells), NaN when the grid carries none
    measured_floor = contract.energy_floor_mev_per_a2(ds, source) / units.EV_PER_A2_TO_MEV_PER_A2
    results: list[PressureAnalysis] = []
    previous_xy = None
    for i, pk in enumerate(cp.p_gpa):
        surf = surfaces[i]
        tol = degeneracy_tolerance_ev_per_a2(float(floor[i]), measured_floor)
        starts, k = paths_from_near_degenerate_minima(
            surf,
            direction_deg,
            tol,
            min_barrier_ev_per_a2=float(floor[i]),
            max_length_angstrom=opts.max_length_angstrom,
            timings_s=timings,
            stackings=stackings[i],
            previous_xy=previous_xy,
        )
        r0, path, fr = starts[k].xy_angstrom, starts[k].path, starts[k].friction
        previous_xy = r0
        warn_if_tau_depends_on_start(starts, k, float(pk), tol, source)
        mep = None
        if opts.with_mep:
            clock = time.perf_counter()
            step = (
                path.period_vector
                if path.periodic
                else _shortest_forward_vector(cp.a1, cp.a2, direction_deg)
            )
            mep = minimum_energy_path(surf, r0, r0 + step)
            timings["mep"] += time.perf_counter() - clock
        sym = None
        if opts.with_symmetry:
            clock = time.perf_counter()
            sym = symmetry_report(surf)
            timings["symmetry"] += time.perf_counter() - clock
        results.append(
            PressureAnalysis(float(pk), surf, r0, path, fr, mep, sym, starts, k, tol, stackings[i])
        )
        _warn_noise(cp, i, fr, source)
    return results


def _warn_grid(grid: GridEstimate, source: str) -> None:
    """:class:`GridResolutionWarning` when the grid does not resolve τ (or its estimate failed)."""
    text = grid.message()
    if text is not None:
        warnings.warn(f"{source}: {text}", GridResolutionWarning, stacklevel=3)
    if grid.unavailable is not None:
        warnings.warn(
            f"{source}: grid error estimate incomplete: {grid.unavailable}; at such a load "
            "the other estimator's value is used (analyze.json grid fallback); where none "
            "exists the laws' intervals carry no grid part",
            GridResolutionWarning,
            stacklevel=3,
        )


def _warn_noise(cp: ConstantPressureISPES, i: int, fr: FrictionResult, source: str) -> None:
    """:class:`LoadNoiseWarning` if the load's noise is sizeable against τ or the barriers."""
    nz = cp.noise
    eps, force = nz.energy_noise_mev_per_a2[i], nz.force_noise_mpa[i]
    barrier = max((b.height for b in fr.barriers), default=0.0) * units.EV_PER_A2_TO_MEV_PER_A2
    big_force = np.isfinite(force) and force > NOISE_WARN_FRACTION * abs(fr.tau_mpa)
    big_energy = np.isfinite(eps) and eps > NOISE_WARN_FRACTION * barrier
    if big_force or big_energy:
        warnings.warn(
            f"{source} at P = {nz.p_gpa[i]:g} GPa ({nz.load_source} load, {nz.form} form): "
            f"energy noise {eps:.3g} meV/Å² (largest barrier {barrier:.3g}), force noise "
            f"{force:.3g} MPa (τ = {fr.tau_mpa:.4g} MPa) from δp = {nz.delta_p_gpa:.3g} GPa rms "
            f"and |dp/dz| = {nz.slope_gpa_per_angstrom[i]:.3g} GPa/Å"
            + (
                "; try the energy load source (--load-source energy, analysis.load_source: energy)"
                if nz.load_source == "stress"
                else ""
            ),
            LoadNoiseWarning,
            stacklevel=4,
        )


#: How the ``"auto"`` direction is chosen, as stored with the outputs.
AUTO_DIRECTION_RULE = (
    "lowest-barrier: the shortest lattice translation the slider reaches from the global "
    "minimum over the lowest minimum-energy-path barrier, at the lowest load (P = {p:g} GPa); "
    "equal lengths: the smallest angle from x in [0, 360)"
)


def _lowest_barrier_direction(
    stackings: Stackings | None, a1: np.ndarray, p_gpa: float
) -> tuple[float, str]:
    """``(direction_deg, rule)`` for ``direction_deg="auto"``.

    Falls back on the direction of ``a1`` (stated in the rule) when no saddle
    connects the global minimum to an equivalent one (a landscape without barrier).
    """
    rule = AUTO_DIRECTION_RULE.format(p=p_gpa)
    if stackings is not None and np.isfinite(stackings.barrier_direction_deg):
        return float(stackings.barrier_direction_deg), rule
    angle = float(np.degrees(np.arctan2(a1[1], a1[0])) % 360.0)
    return angle, rule + "; no barrier found: along a1"


def _shortest_forward_vector(a1: np.ndarray, a2: np.ndarray, direction_deg: float) -> np.ndarray:
    th = np.deg2rad(direction_deg)
    d = np.array([np.cos(th), np.sin(th)])
    vecs = lattice_vectors(a1, a2, 4)
    vecs = vecs[vecs @ d > 1e-9]
    return vecs[np.argmin(np.linalg.norm(vecs, axis=1))]
