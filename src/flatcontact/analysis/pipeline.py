"""The whole ISPES analysis of one grid: constant-pressure maps → paths → τ, σ, G_int → load laws.

:func:`analyze_ispes` validates every argument before any work, then for each
target load ``P``:

1. the constant-pressure landscape on the grid (:mod:`.constant_pressure`),
   per area, in eV/Å², zeroed at the global minimum of the landscape at the
   lowest requested ``P`` (``energy_zero="lowest-p"``, the default), at each
   load's own minimum (``"each"``), or left absolute (``"none"``);
2. its exact periodic interpolant (:mod:`.periodic`);
3. the zero-perpendicular-force path from the global minimum along the pulling
   direction (:mod:`.path`) and, on request, the string-method MEP to the
   equivalent minimum that the path reaches;
4. τ, σ_MSS and the shear stiffness (:mod:`.friction`);
5. optionally the symmetry report (:mod:`.symmetry`).

Finally the load laws (:mod:`.laws`). Timings per stage are recorded.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import xarray as xr

from flatcontact.analysis.constant_pressure import FORMS, ConstantPressureISPES, constant_pressure
from flatcontact.analysis.friction import FrictionResult, friction_along_path
from flatcontact.analysis.laws import LoadLaws, fit_load_laws
from flatcontact.analysis.path import (
    MinimumEnergyPath,
    SlidingPath,
    minimum_energy_path,
    zero_perpendicular_force_path,
)
from flatcontact.analysis.periodic import PeriodicSurface, lattice_vectors, rectangular_supercell
from flatcontact.analysis.symmetry import SymmetryReport, symmetry_report
from flatcontact.errors import InputError

ENERGY_ZEROS = ("lowest-p", "each", "none")


@dataclass(frozen=True)
class PressureAnalysis:
    """Everything computed at one load (surface and path energies in eV/Å²)."""

    p_gpa: float
    surface: PeriodicSurface
    minimum_xy_angstrom: np.ndarray
    path: SlidingPath
    friction: FrictionResult
    mep: MinimumEnergyPath | None
    symmetry: SymmetryReport | None


@dataclass(frozen=True)
class AnalysisResult:
    """The analysis of one ISPES grid at a series of loads."""

    pressures: tuple[PressureAnalysis, ...]
    constant_pressure: ConstantPressureISPES
    laws: LoadLaws
    direction_deg: float
    form: str
    energy_zero: str
    energy_reference_ev_per_a2: float
    supercell: tuple[np.ndarray, np.ndarray] | None
    timings_s: dict[str, float] = field(default_factory=dict)

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
        raise InputError("--p-gpa: give at least one target pressure in GPa")
    if not np.all(np.isfinite(p)):
        raise InputError(f"--p-gpa: expected finite pressures in GPa, got {p.tolist()}")
    if np.unique(p).size != p.size:
        raise InputError(f"--p-gpa: pressures must be distinct, got {p.tolist()}")
    return np.sort(p)


def analyze_ispes(
    ds: xr.Dataset,
    p_gpa: list[float] | np.ndarray,
    direction_deg: float = 90.0,
    form: str = "internal",
    energy_zero: str = "lowest-p",
    allow_missing: bool = False,
    threshold_gpa: float = 3.0,
    with_mep: bool = False,
    with_symmetry: bool = True,
    max_length_angstrom: float | None = None,
    source: str = "ISPES grid",
) -> AnalysisResult:
    """Analyse an ISPES grid at the loads ``p_gpa`` (see module docstring).

    Parameters
    ----------
    ds
        Grid following the ``ispes.nc`` contract.
    p_gpa
        Target loads (GPa, positive when pressed).
    direction_deg
        Pulling direction in degrees from x (90 = y, the paper's).
    form
        ``"internal"`` (paper) or ``"enthalpy"``.
    energy_zero
        ``"lowest-p"``, ``"each"`` or ``"none"``.
    allow_missing
        Interpolate columns with missing thickness points instead of refusing.
    threshold_gpa
        Upper end of the load range of the linear fits.
    with_mep, with_symmetry
        Also compute the string-method MEP / the symmetry report per load.
    max_length_angstrom
        Tracking limit of the path (default: see :func:`.path.default_max_length`).
    source
        Name of the grid in messages.
    """
    p = check_pressures(p_gpa)
    if not np.isfinite(direction_deg):
        raise InputError(f"--direction-deg: expected a finite angle, got {direction_deg}")
    if form not in FORMS:
        raise InputError(f"--energy: expected one of {', '.join(FORMS)}, got {form!r}")
    if energy_zero not in ENERGY_ZEROS:
        raise InputError(
            f"--energy-zero: expected one of {', '.join(ENERGY_ZEROS)}, got {energy_zero!r}"
        )
    if not threshold_gpa > 0:
        raise InputError(f"--threshold-gpa: expected a positive pressure, got {threshold_gpa}")

    timings = {"constant_pressure": 0.0, "interpolation": 0.0, "path": 0.0, "friction": 0.0}
    timings.update({"mep": 0.0} if with_mep else {})
    timings.update({"symmetry": 0.0} if with_symmetry else {})
    clock = time.perf_counter()
    cp = constant_pressure(ds, p, form=form, allow_missing=allow_missing, source=source)
    timings["constant_pressure"] = time.perf_counter() - clock

    a1, a2 = cp.a1, cp.a2
    surfaces, minima = [], []
    clock = time.perf_counter()
    for i in range(p.size):
        surf = PeriodicSurface(cp.energy_ev_per_a2[i], a1, a2)
        surfaces.append(surf)
        minima.append(surf.global_minimum())
    if energy_zero == "lowest-p":
        refs = [minima[0][1]] * p.size
    elif energy_zero == "each":
        refs = [m[1] for m in minima]
    else:
        refs = [0.0] * p.size
    surfaces = [PeriodicSurface(s.values - r, a1, a2) for s, r in zip(surfaces, refs, strict=True)]
    timings["interpolation"] = time.perf_counter() - clock

    results = []
    for i, pk in enumerate(p):
        surf, r0 = surfaces[i], minima[i][0]
        clock = time.perf_counter()
        path = zero_perpendicular_force_path(
            surf, direction_deg, start_xy=r0, max_length_angstrom=max_length_angstrom
        )
        timings["path"] += time.perf_counter() - clock
        clock = time.perf_counter()
        fr = friction_along_path(path)
        timings["friction"] += time.perf_counter() - clock
        mep = None
        if with_mep:
            clock = time.perf_counter()
            end = r0 + (
                path.period_vector
                if path.periodic
                else _shortest_forward_vector(a1, a2, direction_deg)
            )
            mep = minimum_energy_path(surf, r0, end)
            timings["mep"] += time.perf_counter() - clock
        sym = None
        if with_symmetry:
            clock = time.perf_counter()
            sym = symmetry_report(surf)
            timings["symmetry"] += time.perf_counter() - clock
        results.append(PressureAnalysis(float(pk), surf, r0, path, fr, mep, sym))

    clock = time.perf_counter()
    tau = np.array([r.friction.tau_mpa for r in results])
    sigma = np.array([r.friction.sigma_mss_mpa for r in results])
    laws = fit_load_laws(p, tau, sigma, threshold_gpa)
    timings["laws"] = time.perf_counter() - clock
    return AnalysisResult(
        pressures=tuple(results),
        constant_pressure=cp,
        laws=laws,
        direction_deg=float(direction_deg),
        form=form,
        energy_zero=energy_zero,
        energy_reference_ev_per_a2=float(refs[0]),
        supercell=rectangular_supercell(a1, a2),
        timings_s=timings,
    )


def _shortest_forward_vector(a1: np.ndarray, a2: np.ndarray, direction_deg: float) -> np.ndarray:
    th = np.deg2rad(direction_deg)
    d = np.array([np.cos(th), np.sin(th)])
    vecs = lattice_vectors(a1, a2, 4)
    vecs = vecs[vecs @ d > 1e-9]
    return vecs[np.argmin(np.linalg.norm(vecs, axis=1))]
