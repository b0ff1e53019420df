"""Files of the analysis stage, all written atomically.

- ``friction.csv``: one row per load: ``p_gpa``, ``tau_mpa``,
  ``sigma_mss_mpa``, ``shear_stiffness_gpa_per_nm`` and path diagnostics;
  ``n_degenerate_minima`` (inequivalent minima within the degeneracy
  tolerance of the global one, :mod:`.starts`) and ``tau_by_start_mpa`` (τ
  from each of them, ``;``-separated, in the order of ``friction.nc``'s
  ``start`` dimension);
- ``friction.nc``: the same per load plus the paths (dims ``p_gpa``,
  ``sample``; NaN-padded), the constant-pressure maps (meV/Å², dims
  ``p_gpa``, ``shift_a``, ``shift_b``), ``z*`` (Å) and, on dims ``p_gpa``,
  ``start`` (NaN-padded), each near-degenerate start's position, energy above
  the lowest minimum, τ, σ_MSS and shear stiffness, with ``selected_start``;

The analyze stage (:mod:`flatcontact.stages.analyze`) writes them; ``laws.json`` is the laws
stage's (:mod:`flatcontact.stages.laws`).
"""

from __future__ import annotations

import csv
import io
import math

import numpy as np
import xarray as xr

from flatcontact import __version__
from flatcontact.analysis.analyze import AnalysisResult
from flatcontact.analysis.friction import EV_PER_A4_TO_GPA_PER_NM
from flatcontact.analysis.grid_error import ERROR_COLUMNS
from flatcontact.analysis.noise import BARRIER_NOISE_FACTOR
from flatcontact.foundation import units

CSV_COLUMNS = (
    "p_gpa",
    "tau_mpa",
    "sigma_mss_mpa",
    "shear_stiffness_gpa_per_nm",
    "tau_position_angstrom",
    "tau_limited_by",
    "tau_period_mpa",
    "n_barriers",
    "n_jumps",
    "period_angstrom",
    "periodic",
    "mep_barrier_mev_per_a2",
    "energy_noise_mev_per_a2",
    "force_noise_mpa",
    "n_degenerate_minima",
    "tau_by_start_mpa",
    "direction_deg",
    "start_stacking",
    "zero_shift_stacking",
    "lowest_barrier_mev_per_a2",
    "lowest_barrier_direction_deg",
    "barrier_along_direction_mev_per_a2",
    "stacking_energies_mev_per_a2",
    *ERROR_COLUMNS.values(),
)
#: Separator of the per-start values in one ``friction.csv`` cell.
LIST_SEPARATOR = ";"
_MEV = units.EV_PER_A2_TO_MEV_PER_A2


def _clean(v: object) -> object:
    if isinstance(v, list):
        return [_clean(x) for x in v]
    if isinstance(v, float | np.floating):
        return None if not math.isfinite(float(v)) else float(v)
    if isinstance(v, dict):
        return {k: _clean(x) for k, x in v.items()}
    return v


def per_pressure_rows(result: AnalysisResult) -> list[dict]:
    """One dict per load with the CSV columns (floats; NaN as None)."""
    rows = []
    nz = result.noise
    for i, pa in enumerate(result.pressures):
        fr, path = pa.friction, pa.path
        rows.append(
            {
                "p_gpa": pa.p_gpa,
                "tau_mpa": fr.tau_mpa,
                "sigma_mss_mpa": fr.sigma_mss_mpa,
                "shear_stiffness_gpa_per_nm": fr.shear_stiffness_gpa_per_nm,
                "tau_position_angstrom": fr.tau_position_angstrom,
                "tau_limited_by": fr.tau_limited_by,
                "tau_period_mpa": fr.tau_period_mpa,
                "n_barriers": len(fr.barriers),
                "n_jumps": len(path.jumps),
                "period_angstrom": path.length_angstrom if path.periodic else float("nan"),
                "periodic": bool(path.periodic),
                "mep_barrier_mev_per_a2": (
                    pa.mep.barrier * units.EV_PER_A2_TO_MEV_PER_A2 if pa.mep else float("nan")
                ),
                "energy_noise_mev_per_a2": float(nz.energy_noise_mev_per_a2[i]),
                "force_noise_mpa": float(nz.force_noise_mpa[i]),
                "n_degenerate_minima": max(1, len(pa.starts)),
                "tau_by_start_mpa": [o.tau_mpa for o in pa.starts] or [fr.tau_mpa],
                "direction_deg": float(path.direction_deg),
                **_stacking_columns(pa),
                **_grid_columns(result, i),
            }
        )
    return [{k: _clean(v) for k, v in row.items()} for row in rows]


def _grid_columns(result: AnalysisResult, i: int) -> dict:
    """The grid's signed error estimates of τ, σ_MSS and G_int at load ``i`` (NaN without)."""
    grid = result.grid
    return {
        col: float(grid.error[q][i]) if grid is not None else float("nan")
        for q, col in ERROR_COLUMNS.items()
    }


def _stacking_columns(pa) -> dict:
    """Per-load stacking outputs (:mod:`.stackings`); NaN/empty without the stackings analysis."""
    mev = units.EV_PER_A2_TO_MEV_PER_A2
    st = pa.stackings
    if st is None:
        return {
            "start_stacking": "",
            "zero_shift_stacking": "",
            "lowest_barrier_mev_per_a2": float("nan"),
            "lowest_barrier_direction_deg": float("nan"),
            "barrier_along_direction_mev_per_a2": float("nan"),
            "stacking_energies_mev_per_a2": {},
        }
    return {
        "start_stacking": start_stacking_name(pa),
        "zero_shift_stacking": st.name_at((0.0, 0.0)),
        "lowest_barrier_mev_per_a2": st.barrier * mev,
        "lowest_barrier_direction_deg": st.barrier_direction_deg,
        "barrier_along_direction_mev_per_a2": pa.barrier_along_direction_ev_per_a2 * mev,
        "stacking_energies_mev_per_a2": {k: v * mev for k, v in st.energies().items()},
    }


def start_stacking_name(pa) -> str:
    """Name of the stationary point the reported path starts from ('' if not matched)."""
    st = pa.stackings
    if st is None:
        return ""
    surf = pa.surface
    scale = float(np.min(np.linalg.norm(surf.lattice, axis=0)))
    for p in st.points:
        ds = surf.fractional(p.xy_angstrom - pa.minimum_xy_angstrom)
        ds -= np.round(ds)
        if p.kind == "minimum" and np.linalg.norm(surf.cartesian(ds)) < 1e-4 * scale:
            return p.name
    return ""


def stackings_json(pa) -> dict:
    """``{name: {kind, energy_mev_per_a2, x_angstrom, y_angstrom, multiplicity}}`` of one load."""
    if pa.stackings is None:
        return {}
    out = pa.stackings.to_json(units.EV_PER_A2_TO_MEV_PER_A2)
    for v in out.values():
        v["energy_mev_per_a2"] = _clean(v.pop("energy"))
    return out


def summary_json(result: AnalysisResult) -> dict:
    """What ``flatcontact analyze --json`` prints."""
    out = {
        "direction_deg": result.direction_deg,
        "direction_rule": result.direction_rule,
        "tau_start_rule": result.tau_start_rule,
        "energy_form": result.form,
        "load_source": result.load_source,
        "noise": result.noise.to_json(),
        "pressures": [
            {
                k: row[k]
                for k in (
                    "p_gpa",
                    "tau_mpa",
                    "sigma_mss_mpa",
                    "shear_stiffness_gpa_per_nm",
                    "tau_limited_by",
                    "tau_period_mpa",
                    "n_jumps",
                    "periodic",
                    "energy_noise_mev_per_a2",
                    "force_noise_mpa",
                    "n_degenerate_minima",
                    "tau_by_start_mpa",
                    "start_stacking",
                    "zero_shift_stacking",
                    "lowest_barrier_mev_per_a2",
                    "lowest_barrier_direction_deg",
                    "barrier_along_direction_mev_per_a2",
                    *ERROR_COLUMNS.values(),
                )
            }
            | {"stackings": stackings_json(pa)}
            for row, pa in zip(per_pressure_rows(result), result.pressures, strict=True)
        ],
        "laws": result.laws.to_json() if result.laws is not None else None,
        "grid": result.grid.to_json() if result.grid is not None else None,
    }
    sym = [pa.symmetry for pa in result.pressures if pa.symmetry is not None]
    if sym:
        out["symmetry_kept"] = {
            str(pa.p_gpa): pa.symmetry.kept for pa in result.pressures if pa.symmetry
        }
    return out


def _cell(v: object) -> object:
    """A CSV cell: empty for undefined, ``;``-joined for a per-start list."""
    if v is None:
        return ""
    if isinstance(v, list):
        return LIST_SEPARATOR.join("" if x is None else repr(float(x)) for x in v)
    if isinstance(v, dict):
        return LIST_SEPARATOR.join(
            f"{k}={'' if x is None else repr(float(x))}" for k, x in v.items()
        )
    return v


def friction_csv_text(result: AnalysisResult) -> str:
    """``friction.csv`` content (empty cells for undefined values)."""
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=CSV_COLUMNS, lineterminator="\n")
    writer.writeheader()
    for row in per_pressure_rows(result):
        writer.writerow({k: _cell(row[k]) for k in CSV_COLUMNS})
    return buf.getvalue()


#: Per-load columns of the ``friction.csv`` rows carried into ``friction.nc``: name -> attributes.
FRICTION_COLUMNS = {
    "tau_mpa": {"units": "MPa"},
    "tau_period_mpa": {"units": "MPa"},
    "sigma_mss_mpa": {"units": "MPa"},
    "shear_stiffness_gpa_per_nm": {"units": "GPa/nm"},
    **{c: {"units": "MPa" if c.endswith("_mpa") else "GPa/nm"} for c in ERROR_COLUMNS.values()},
}
#: The sliding path per load, NaN-padded on ``sample``: name -> (value of the path, attributes).
PATH_SAMPLES = {
    "path_t": (lambda path: path.t_angstrom, {"units": "angstrom"}),
    "path_x": (lambda path: path.xy_angstrom[:, 0], {"units": "angstrom"}),
    "path_y": (lambda path: path.xy_angstrom[:, 1], {"units": "angstrom"}),
    "path_energy": (lambda path: path.energy * _MEV, {"units": "meV/angstrom^2"}),
    "path_force": (lambda path: path.force * units.EV_PER_A3_TO_MPA, {"units": "MPa"}),
    "path_stiffness": (
        lambda path: path.curvature * EV_PER_A4_TO_GPA_PER_NM,
        {"units": "GPa/nm"},
    ),
}
#: The load's noise (:mod:`.noise`), columns of the rows: name -> attributes.
NOISE_COLUMNS = {
    "energy_noise_mev_per_a2": {
        "units": "meV/angstrom^2",
        "long_name": "energy noise from the load's error",
    },
    "force_noise_mpa": {"units": "MPa", "long_name": "energy noise / lateral grid spacing"},
}
#: Each near-degenerate start (:mod:`.starts`), NaN-padded on ``start``:
#: name -> (value of the start, attributes).
START_VALUES = {
    "tau_by_start_mpa": (
        lambda o: o.tau_mpa,
        {"units": "MPa", "long_name": "tau from each near-degenerate minimum"},
    ),
    "sigma_mss_by_start_mpa": (lambda o: o.friction.sigma_mss_mpa, {"units": "MPa"}),
    "shear_stiffness_by_start_gpa_per_nm": (
        lambda o: o.friction.shear_stiffness_gpa_per_nm,
        {"units": "GPa/nm"},
    ),
    "start_x": (lambda o: o.xy_angstrom[0], {"units": "angstrom"}),
    "start_y": (lambda o: o.xy_angstrom[1], {"units": "angstrom"}),
    "start_energy_above_lowest_mev_per_a2": (
        lambda o: o.above_lowest_mev_per_a2,
        {"units": "meV/angstrom^2"},
    ),
}
#: The lowest barrier of each load's landscape (:mod:`.stackings`), columns of the rows.
BARRIER_COLUMNS = {
    "lowest_barrier_mev_per_a2": {
        "units": "meV/angstrom^2",
        "long_name": "lowest minimum-energy-path barrier from the global minimum "
        "to an equivalent one",
    },
    "lowest_barrier_direction_deg": {
        "units": "degree",
        "long_name": "shortest translation over that barrier",
    },
    "barrier_along_direction_mev_per_a2": {
        "units": "meV/angstrom^2",
        "long_name": "lowest MEP barrier to the start's image one lattice period "
        "along the pulling direction",
    },
}
#: Each named stationary point, NaN where a load lacks it: name -> (value of the point, attributes).
STACKING_VALUES = {
    "stacking_energy_mev_per_a2": (
        lambda pt: pt.energy * _MEV,
        {"units": "meV/angstrom^2", "long_name": "energy of each named stationary point"},
    ),
    "stacking_x": (lambda pt: pt.xy_angstrom[0], {"units": "angstrom"}),
    "stacking_y": (lambda pt: pt.xy_angstrom[1], {"units": "angstrom"}),
}
FORCE_SIGN = "path_force = de/dt, the resisting lateral stress (positive while climbing)"


def friction_dataset(result: AnalysisResult) -> xr.Dataset:
    """``friction.nc`` as an xarray Dataset (units in attributes): per load (dim ``p_gpa``) the
    friction, the path (``sample``), the noise and the starts (``start``), the stationary points
    (``stacking``) and the constant-pressure maps (``shift_a``, ``shift_b``), built from the
    tables above, one function per group."""
    rows = per_pressure_rows(result)
    names, kinds = _stacking_names(result)
    cp = result.constant_pressure
    return xr.Dataset(
        {
            **_friction_variables(result, rows),
            **_path_variables(result),
            **_start_variables(result, rows),
            **_stacking_variables(result, rows, names, kinds),
            **_map_variables(result),
        },
        coords={
            "p_gpa": ("p_gpa", result.p_gpa, {"units": "GPa"}),
            "shift_a": cp.shift_a,
            "shift_b": cp.shift_b,
            "stacking": ("stacking", np.array(names, dtype=str)),
        },
        attrs={
            "a1": cp.a1,
            "a2": cp.a2,
            "area": cp.area_angstrom2,
            "direction_deg": result.direction_deg,
            "energy_form": result.form,
            "energy_zero": result.energy_zero,
            "load_source": result.load_source,
            "load_noise_delta_p_gpa": _attr(result.noise.delta_p_gpa),
            "stress_energy_mismatch_rms_gpa": _attr(result.noise.stress_energy_mismatch_rms_gpa),
            "lateral_grid_spacing_angstrom": result.noise.grid_spacing_angstrom,
            "barrier_noise_factor": BARRIER_NOISE_FACTOR,
            "tau_start_rule": result.tau_start_rule,
            "direction_rule": result.direction_rule,
            "force_sign": FORCE_SIGN,
            "flatcontact_version": __version__,
        },
    )


def _column(rows: list[dict], name: str) -> np.ndarray:
    """One per-load column of the rows as floats (NaN for an undefined cell)."""
    return np.array([np.nan if r[name] is None else r[name] for r in rows], dtype=float)


def _friction_variables(result: AnalysisResult, rows: list[dict]) -> dict:
    """τ, τ over a period, σ_MSS, G_int, the grid's error estimates and the path's jumps."""
    out = {name: ("p_gpa", _column(rows, name), attrs) for name, attrs in FRICTION_COLUMNS.items()}
    out["n_jumps"] = ("p_gpa", np.array([len(pa.path.jumps) for pa in result.pressures]))
    return out


def _path_variables(result: AnalysisResult) -> dict:
    """:data:`PATH_SAMPLES` on ``(p_gpa, sample)``, each path NaN-padded to the longest."""
    n = max(len(pa.path.t_angstrom) for pa in result.pressures)
    out = {}
    for name, (get, attrs) in PATH_SAMPLES.items():
        values = np.full((len(result.pressures), n), np.nan)
        for i, pa in enumerate(result.pressures):
            v = get(pa.path)
            values[i, : len(v)] = v
        out[name] = (("p_gpa", "sample"), values, attrs)
    return out


def _start_variables(result: AnalysisResult, rows: list[dict]) -> dict:
    """The load's noise, the near-degenerate starts and :data:`START_VALUES` on
    ``(p_gpa, start)``, NaN-padded to the most starts."""
    pressures = result.pressures
    out = {name: ("p_gpa", _column(rows, name), attrs) for name, attrs in NOISE_COLUMNS.items()}
    out["n_degenerate_minima"] = ("p_gpa", _column(rows, "n_degenerate_minima").astype(int))
    out["selected_start"] = (
        "p_gpa",
        np.array([pa.selected_start for pa in pressures]),
        {"long_name": "index along start of the reported path and tau"},
    )
    out["degeneracy_tolerance_mev_per_a2"] = (
        "p_gpa",
        np.array([pa.degeneracy_tolerance_ev_per_a2 for pa in pressures]) * _MEV,
        {"units": "meV/angstrom^2", "long_name": "minima this close to the lowest are starts"},
    )
    n_start = max(max(len(pa.starts), 1) for pa in pressures)
    for name, (get, attrs) in START_VALUES.items():
        values = np.full((len(pressures), n_start), np.nan)
        for i, pa in enumerate(pressures):
            for j, o in enumerate(pa.starts):
                values[i, j] = get(o)
        out[name] = (("p_gpa", "start"), values, attrs)
    return out


def _stacking_names(result: AnalysisResult) -> tuple[list[str], dict[str, str]]:
    """The stationary points named at any load, in order of first appearance, and the kind of
    each (as first named)."""
    named = [pa.stackings for pa in result.pressures if pa.stackings]
    names = list(dict.fromkeys(name for st in named for name in st.energies()))
    kinds: dict[str, str] = {}
    for st in named:
        kinds.update({k: v for k, v in st.kinds().items() if k not in kinds})
    return names, kinds


def _stacking_variables(
    result: AnalysisResult, rows: list[dict], names: list[str], kinds: dict[str, str]
) -> dict:
    """The barriers of :data:`BARRIER_COLUMNS`, the start's stacking and :data:`STACKING_VALUES`
    on ``(p_gpa, stacking)`` (the first point of each name; NaN where a load lacks it)."""
    out = {name: ("p_gpa", _column(rows, name), attrs) for name, attrs in BARRIER_COLUMNS.items()}
    out["start_stacking"] = ("p_gpa", np.array([r["start_stacking"] for r in rows], dtype=str))
    first_points = [
        {} if pa.stackings is None else _first_of_each_name(pa.stackings.points)
        for pa in result.pressures
    ]
    for name, (get, attrs) in STACKING_VALUES.items():
        values = np.full((len(result.pressures), len(names)), np.nan)
        for i, first in enumerate(first_points):
            for j, stacking in enumerate(names):
                if stacking in first:
                    values[i, j] = get(first[stacking])
        out[name] = (("p_gpa", "stacking"), values, attrs)
    out["stacking_kind"] = ("stacking", np.array([kinds[n] for n in names], dtype=str))
    return out


def _first_of_each_name(points) -> dict:
    first: dict = {}
    for pt in points:
        first.setdefault(pt.name, pt)
    return first


def _map_variables(result: AnalysisResult) -> dict:
    """The constant-pressure maps (meV/Å², zeroed as the analysis says) and z* (Å)."""
    cp = result.constant_pressure
    maps = np.stack([pa.surface.values for pa in result.pressures]) * _MEV
    dims = ("p_gpa", "shift_a", "shift_b")
    return {
        "energy_map": (dims, maps, {"units": "meV/angstrom^2"}),
        "thickness_at_p": (dims, cp.thickness_angstrom, {"units": "angstrom"}),
    }


def _attr(v: float) -> float:
    """netCDF attributes cannot be None: NaN stands for 'not estimated'."""
    return float(v)
