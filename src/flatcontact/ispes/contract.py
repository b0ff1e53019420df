"""The ISPES grid file contract (``ispes.nc``) shared by the scan and the analysis.

Layout (xarray, netCDF4 written with h5netcdf):

dims
    ``shift_a``, ``shift_b``: fractional lateral shift of slab 2 along the
    primitive in-plane lattice vectors ``a1``, ``a2``; values in [0, 1),
    equally spaced, endpoint excluded (the grid is periodic).
    ``thickness``: distance between surfaces 1 and 4 in Å (the paper's z),
    strictly increasing.
variables (all on ``(shift_a, shift_b, thickness)``)
    ``energy``: total potential energy of the cell, eV.
    ``normal_stress``: normal load per area, GPa, positive when the slabs are
    pressed together.
    ``converged``: bool; ``force_calls``: int; ``mapped`` (optional, bool): the point was not
    relaxed but filled from a symmetry-equal registry (a symmetry-reduced scan,
    :mod:`flatcontact.ispes.reduction`).
attrs
    ``a1``, ``a2``: in-plane primitive vectors (Å, 2-vectors in the x-y plane);
    ``area``: |a1 × a2| in Å²; ``potential``: description of the model;
    ``flatcontact_version``; a scan adds ``grid_points``, ``computed_points`` (relaxed) and the
    shift-space group the values obey (optional; absent means the identity only):
    ``symmetry_order`` n, ``symmetry_matrices`` (4n integers: M row by row per operation) and
    ``symmetry_translations`` (2n fractions t), each operation mapping the fractional shift
    ``s`` to ``M s + t`` (mod 1) with E(M s + t) = E(s) (:func:`symmetry_operations`).
    ``energy_floor_mev_per_a2`` (optional, one number): the energy noise floor of the grid
    at fixed thickness, per area (meV/Å²), where it was measured (the approximant study's
    cells: the larger of the round-off and the relaxation floor,
    :mod:`flatcontact.ispes.relax_noise`); absent means not measured
    (:func:`energy_floor_mev_per_a2`).
    ``fold_rerelaxed_points`` and ``fold_rerelaxed_fmax_ev_per_a`` (optional): that many
    points of folding columns were relaxed again at that tighter force tolerance (eV/Å) and
    hold those values (:mod:`flatcontact.ispes.rerelax`).

Points not computed yet are NaN with ``converged = False``.

Reading (:func:`open_ispes`, the one reader of the file) checks, in this order, each failure
one :class:`~flatcontact.foundation.errors.InputError` line naming the file and the defect, never a
warning line: the file opens as netCDF4/HDF5 (anything h5netcdf cannot read, including
plain HDF5 without dimensions, is "not a readable netCDF file" or a missing dimension);
the three dimensions exist and their sizes are within the run bounds of
:mod:`flatcontact.foundation.limits` (``grid_axis`` per lateral axis, ``thicknesses``, ``scan_points``
for the product) before any variable is read into memory; then :func:`validate_ispes`:
the required variables exist on exactly the three dimensions with numeric values;
``a1``, ``a2`` are vectors of at least two finite numbers, ``area`` one finite number equal
to |a1 × a2|; the shift coordinates are the equally spaced fractions; the thicknesses are
finite and distinct; units are known.
"""

from __future__ import annotations

import os
import warnings
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from flatcontact.foundation import limits
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import atomic_path

if TYPE_CHECKING:  # xarray is imported where a dataset is made: scan workers never need it
    import xarray as xr

DIM_A = "shift_a"
DIM_B = "shift_b"
DIM_Z = "thickness"
DIMS = (DIM_A, DIM_B, DIM_Z)

VAR_ENERGY = "energy"
VAR_STRESS = "normal_stress"
VAR_CONVERGED = "converged"
VAR_FORCE_CALLS = "force_calls"
VAR_MAPPED = "mapped"

REQUIRED_VARIABLES = (VAR_ENERGY, VAR_STRESS)
REQUIRED_ATTRS = ("a1", "a2", "area")
UNITS = {VAR_ENERGY: "eV", VAR_STRESS: "GPa", DIM_Z: "angstrom", DIM_A: "1", DIM_B: "1"}

_AREA_RTOL = 1e-6

#: Accepted ``units`` attributes per variable and the factor to the contract's unit.
#: A variable without a ``units`` attribute is taken to be in the contract's unit.
UNIT_FACTORS: dict[str, dict[str, float]] = {
    VAR_ENERGY: {"eV": 1.0, "meV": 1.0e-3},
    VAR_STRESS: {"GPa": 1.0, "MPa": 1.0e-3, "kPa": 1.0e-6, "Pa": 1.0e-9},
    DIM_Z: {"angstrom": 1.0, "Angstrom": 1.0, "Å": 1.0, "A": 1.0, "nm": 10.0},
}


def fractional_shifts(n: int) -> np.ndarray:
    """``n`` equally spaced fractional shifts in [0, 1), endpoint excluded."""
    if n < 1:
        raise InputError(f"grid size must be at least 1 lateral point, got {n}")
    return np.arange(n) / n


def symmetry_attrs(operations: list[dict]) -> dict:
    """The ``symmetry_*`` attributes of a list of ``{"matrix": 2×2, "translation": 2}``."""
    m = np.array([op["matrix"] for op in operations], dtype=np.int64).reshape(-1)
    t = np.array([op["translation"] for op in operations], dtype=float).reshape(-1)
    return {"symmetry_order": len(operations), "symmetry_matrices": m, "symmetry_translations": t}


def symmetry_operations(ds: xr.Dataset) -> list[tuple[np.ndarray, np.ndarray]]:
    """The shift-space operations ``(M, t)`` a grid's values obey (identity only if none stored).

    Raises
    ------
    InputError
        If the ``symmetry_*`` attributes are inconsistent (sizes, non-integer M, |det M| ≠ 1).
    """
    n = int(np.asarray(ds.attrs.get("symmetry_order", 1)).ravel()[0])
    if n <= 1 or "symmetry_matrices" not in ds.attrs:
        return [(np.eye(2, dtype=int), np.zeros(2))]
    m = np.asarray(ds.attrs["symmetry_matrices"], dtype=float).ravel()
    t = np.asarray(ds.attrs.get("symmetry_translations", np.zeros(2 * n)), dtype=float).ravel()
    if m.size != 4 * n or t.size != 2 * n or not np.allclose(m, np.round(m)):
        raise InputError(
            f"symmetry attributes: expected {4 * n} integer matrix entries and {2 * n} "
            f"translations for symmetry_order {n}, got {m.size} and {t.size}"
        )
    ms = np.round(m).astype(int).reshape(n, 2, 2)
    if not np.all(np.abs(np.abs(np.round(np.linalg.det(ms)))) == 1):
        raise InputError("symmetry attributes: every matrix must have determinant ±1")
    return [(ms[k], t[2 * k : 2 * k + 2]) for k in range(n)]


#: Attribute of a grid's measured energy noise floor (meV/Å²; optional, module docstring).
ENERGY_FLOOR_ATTR = "energy_floor_mev_per_a2"


def energy_floor_mev_per_a2(ds: xr.Dataset, source: str = "ISPES grid") -> float:
    """The grid's measured energy noise floor (meV/Å², ``energy_floor_mev_per_a2``), NaN when
    it carries none; InputError unless a stored one is a finite number >= 0."""
    if ENERGY_FLOOR_ATTR not in ds.attrs:
        return float("nan")
    value = finite_attribute(ds, ENERGY_FLOOR_ATTR, source, "one number >= 0 (meV/Å²)")
    if value.size != 1 or value[0] < 0:
        raise InputError(
            f"{source}: attribute '{ENERGY_FLOOR_ATTR}' must be one number >= 0 (meV/Å²)"
        )
    return float(value[0])


def branch_run(p: np.ndarray) -> tuple[int, int]:
    """``(s, e)``: the nodes ``s .. e`` of one column's load ``p`` (ascending ``z``) that carry P = 0.

    The one rule by which the scan chooses thicknesses
    (:func:`flatcontact.ispes.thicknesses.repulsive_branch`) and the analysis reads loads
    (:func:`flatcontact.analysis.constant_pressure.invert_columns`): the nodes up to the
    global tensile maximum ``m`` (``argmin p``) are split where ``p`` rises with ``z``; the
    branch is the first falling run that reaches ``p <= 0`` (the last run if none does).
    ``s > 0`` is a fold on the compressed side: loads above ``p[s]`` are on another branch.
    ``e - s < 1`` leaves no segment to read.
    """
    m = int(np.argmin(p))
    rises = np.flatnonzero(np.diff(p[: m + 1]) >= 0)
    starts = np.concatenate([[0], rises + 1])
    ends = np.concatenate([rises, [m]])
    k = next((i for i, e in enumerate(ends) if p[e] <= 0), len(ends) - 1)
    return int(starts[k]), int(ends[k])


def cell_area(a1: np.ndarray, a2: np.ndarray) -> float:
    """Area |a1 × a2| (Å²) of the in-plane cell spanned by two 2-vectors."""
    a1 = np.asarray(a1, dtype=float)
    a2 = np.asarray(a2, dtype=float)
    return float(abs(a1[0] * a2[1] - a1[1] * a2[0]))


def empty_grid(
    n_a: int,
    n_b: int,
    thickness_angstrom: np.ndarray,
    a1: np.ndarray,
    a2: np.ndarray,
    potential: str,
    **attrs: object,
) -> xr.Dataset:
    """A contract-conforming grid with every point missing (NaN, not converged)."""
    import xarray as xr

    z = np.asarray(thickness_angstrom, dtype=float)
    if z.ndim != 1 or z.size < 1:
        raise InputError("thickness: expected a non-empty list of values in Å")
    shape = (n_a, n_b, z.size)
    coords = {DIM_A: fractional_shifts(n_a), DIM_B: fractional_shifts(n_b), DIM_Z: z}
    ds = xr.Dataset(
        {
            VAR_ENERGY: (DIMS, np.full(shape, np.nan)),
            VAR_STRESS: (DIMS, np.full(shape, np.nan)),
            VAR_CONVERGED: (DIMS, np.zeros(shape, dtype=bool)),
            VAR_FORCE_CALLS: (DIMS, np.zeros(shape, dtype=np.int64)),
        },
        coords=coords,
    )
    # the version here, not at import: reading it (importlib.metadata) cost every scan
    # worker, which imports this module for cell_area, ≈ 0.02 s of CPU at start
    from flatcontact import __version__

    a1 = np.asarray(a1, dtype=float)[:2]
    a2 = np.asarray(a2, dtype=float)[:2]
    ds.attrs.update(
        a1=a1,
        a2=a2,
        area=cell_area(a1, a2),
        potential=potential,
        flatcontact_version=__version__,
        **attrs,
    )
    _set_units(ds)
    return validate_ispes(ds.sortby(DIM_Z), source="new grid")


def _set_units(ds: xr.Dataset) -> None:
    for name, unit in UNITS.items():
        if name in ds.variables:
            ds[name].attrs["units"] = unit


def validate_ispes(ds: xr.Dataset, source: str = "ISPES grid") -> xr.Dataset:
    """Check ``ds`` against the contract and return it with ``thickness`` ascending.

    Raises
    ------
    InputError
        With one line naming ``source`` and the first thing that is wrong.
    """
    for dim in DIMS:
        if dim not in ds.dims:
            raise InputError(f"{source}: missing dimension '{dim}' (expected dims {DIMS})")
    for var in REQUIRED_VARIABLES:
        if var not in ds.data_vars:
            raise InputError(f"{source}: missing variable '{var}'")
        if set(ds[var].dims) != set(DIMS):
            raise InputError(
                f"{source}: variable '{var}' must have dims {DIMS}, has {ds[var].dims}"
            )
        if not numeric_dtype(ds[var].dtype):
            raise InputError(f"{source}: variable '{var}' must hold numbers, holds {ds[var].dtype}")
    for name in (*DIMS, VAR_CONVERGED, VAR_FORCE_CALLS, VAR_MAPPED):
        if name in ds.variables and not numeric_dtype(ds[name].dtype, bool_ok=True):
            raise InputError(f"{source}: '{name}' must hold numbers, holds {ds[name].dtype}")
    for attr in REQUIRED_ATTRS:
        if attr not in ds.attrs:
            raise InputError(f"{source}: missing attribute '{attr}' (Å vectors a1, a2 and area Å²)")
    a1 = finite_attribute(ds, "a1", source, "an in-plane vector of 2 numbers in Å")
    a2 = finite_attribute(ds, "a2", source, "an in-plane vector of 2 numbers in Å")
    stored_area = finite_attribute(ds, "area", source, "one number in Å²")
    if a1.size < 2 or a2.size < 2:
        raise InputError(f"{source}: attributes a1, a2 must be in-plane 2-vectors in Å")
    if stored_area.size != 1:
        raise InputError(f"{source}: attribute 'area' must be one number in Å²")
    area = cell_area(a1, a2)
    if not area > 0:
        raise InputError(f"{source}: a1 and a2 are parallel (zero cell area)")
    if not np.isclose(float(stored_area[0]), area, rtol=_AREA_RTOL):
        raise InputError(
            f"{source}: attribute area={float(stored_area[0]):.6g} Å² differs from |a1 × a2| = {area:.6g} Å²"
        )
    for dim in (DIM_A, DIM_B):
        s = np.asarray(ds[dim].values, dtype=float)
        expected = np.arange(s.size) / s.size
        if not np.allclose(np.sort(s), expected, atol=1e-9):
            raise InputError(
                f"{source}: coordinate '{dim}' must be {s.size} equally spaced fractions in [0, 1) "
                "with the endpoint excluded"
            )
    z = np.asarray(ds[DIM_Z].values, dtype=float)
    if not np.all(np.isfinite(z)) or np.unique(z).size != z.size:
        raise InputError(f"{source}: coordinate 'thickness' must be finite and without repeats")
    try:
        symmetry_operations(ds)  # the analysis needs them; a bad set is refused here, early
    except InputError as exc:
        raise InputError(f"{source}: {exc}") from None
    ds = _to_contract_units(ds, source)
    ds = ds.sortby([DIM_A, DIM_B, DIM_Z])
    if VAR_CONVERGED not in ds:
        ds[VAR_CONVERGED] = np.isfinite(ds[VAR_ENERGY]) & np.isfinite(ds[VAR_STRESS])
    ds = ds.transpose(*DIMS, ...)
    return ds


def numeric_dtype(dtype: Any, bool_ok: bool = False) -> bool:
    """Whether ``dtype`` holds real numbers (booleans only with ``bool_ok``)."""
    if np.issubdtype(dtype, np.bool_):
        return bool_ok
    return np.issubdtype(dtype, np.integer) or np.issubdtype(dtype, np.floating)


def finite_attribute(ds: xr.Dataset, name: str, source: str, expected: str) -> np.ndarray:
    """Attribute ``name`` as a flat float array; InputError unless it is finite numbers."""
    value = ds.attrs[name]
    try:
        if isinstance(value, str | bytes):
            raise ValueError(name)
        array = np.asarray(value, dtype=float).ravel()
    except (TypeError, ValueError):
        kind = "text" if isinstance(value, str | bytes) else type(value).__name__
        raise InputError(f"{source}: attribute '{name}' must be {expected}, is {kind}") from None
    if array.size == 0 or not np.all(np.isfinite(array)):
        raise InputError(f"{source}: attribute '{name}' must be {expected} (finite)")
    return array


def _check_dims(ds: xr.Dataset, source: str) -> None:
    """The three dimensions exist and their sizes are within the run bounds (before loading)."""
    for dim in DIMS:
        if dim not in ds.dims:
            raise InputError(f"{source}: missing dimension '{dim}' (expected dims {DIMS})")
    n_a, n_b, n_z = (int(ds.sizes[d]) for d in DIMS)
    limits.check("grid_axis", n_a, f"{source}: dimension '{DIM_A}'", "grid points")
    limits.check("grid_axis", n_b, f"{source}: dimension '{DIM_B}'", "grid points")
    limits.check("thicknesses", n_z, f"{source}: dimension '{DIM_Z}'", "thicknesses")
    limits.check("scan_points", n_a * n_b * n_z, f"{source}: grid", "points × thicknesses")


def _to_contract_units(ds: xr.Dataset, source: str) -> xr.Dataset:
    """Convert energy, normal stress and thickness to the contract's units (see UNIT_FACTORS).

    A unit that is not in :data:`UNIT_FACTORS` is refused rather than read as the contract's.
    """
    for name, factors in UNIT_FACTORS.items():
        unit = ds[name].attrs.get("units")
        if unit is None:
            continue
        unit = str(unit).strip()
        if unit not in factors:
            raise InputError(
                f"{source}: '{name}' has units '{unit}'; expected one of {sorted(factors)} "
                f"(the contract's is {UNITS[name]})"
            )
        if factors[unit] != 1.0:
            attrs = {**ds[name].attrs, "units": UNITS[name]}
            ds = ds.assign({name: ds[name] * factors[unit]})
            ds[name].attrs.update(attrs)
    return ds


def open_ispes(path: str | os.PathLike[str]) -> xr.Dataset:
    """Read and validate an ``ispes.nc`` file into memory (the checks: see the module docstring).

    Raises
    ------
    InputError
        One line naming ``path`` and the first defect; no warning reaches the user.
    """
    import xarray as xr

    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: no such ISPES file")
    try:
        with warnings.catch_warnings():  # h5netcdf on plain HDF5, xarray decoding notes
            warnings.simplefilter("ignore")
            with xr.open_dataset(path, engine="h5netcdf") as ds:
                _check_dims(ds, str(path))  # sizes first: nothing is read into memory yet
                ds = ds.load()
            return validate_ispes(ds, source=str(path))
    except InputError:
        raise
    except (OSError, ValueError, TypeError, KeyError, AttributeError, RuntimeError) as exc:
        raise InputError(f"{path}: not a readable netCDF file ({exc.__class__.__name__})") from None


def write_ispes(ds: xr.Dataset, path: str | os.PathLike[str]) -> Path:
    """Validate ``ds`` and write it to ``path`` atomically (netCDF4 via h5netcdf)."""
    ds = validate_ispes(ds, source=str(path))
    ds = ds.copy()
    _set_units(ds)
    with atomic_path(path) as tmp:
        ds.to_netcdf(tmp, engine="h5netcdf")
    return Path(path)


def check_grid(ds: xr.Dataset, grid, source: str = "ISPES grid") -> None:
    """Refuse an ISPES whose lateral grid is not ``grid`` (n_a, n_b): a landscape of another
    run or another grid beside a stage record that claims this run's (one line naming it).
    On a coincidence or twist cell ``grid`` is the one the scan uses for ``scan.grid``
    (:func:`flatcontact.ispes.shift_lattice.scanned_grid`: n × n coprime to the index).

    Raises
    ------
    InputError
        ``source``, both grids and how to recompute it.
    """
    index = int(ds.attrs.get("shift_lattice_index", 1))
    have = (int(ds.sizes[DIMS[0]]), int(ds.sizes[DIMS[1]]))
    want = (int(grid[0]), int(grid[1]))
    if have != want:
        on = f" on a shift lattice of index {index}" if index > 1 else ""
        raise InputError(
            f"{source}: a {have[0]}x{have[1]} landscape, the settings scan a {want[0]}x{want[1]} "
            f"grid (scan.grid{on}); the file is not this run's: remove its stage folder and "
            "rerun to recompute it"
        )
