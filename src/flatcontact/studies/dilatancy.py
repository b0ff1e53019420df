"""Dilatancy of stored ISPES scans: how the thickness at fixed load varies with the registry.

Why two models' enthalpy-form τ differ on the same interface: by the envelope theorem the
enthalpy corrugation ``h(x, y)|_P = U(z*)/A + P z*`` carries the load term ``P z*(x, y)``,
so a model whose ``z*`` varies less with the lateral shift has a smaller ``h`` corrugation
and a smaller τ at the same load. This splits ``z*`` into the interface gap and the slabs.

Command (no torch; reads the scans, writes only ``OUT.json``)::

    flatcontact study dilatancy OUT.json LABEL=DIR [LABEL=DIR ...] [--p-gpa 0,0.5,...]

Each ``DIR`` holds a scan's ``ispes.nc`` and ``points.db`` (the relaxed atoms); the first
model is the reference of the ratios. Per load (0, 0.5, …, 3 GPa): the lateral mean of
``z*`` (Å), its slope d<z*>/dP (Å/GPa, the normal compliance of interface plus slabs),
the lateral ranges (max − min over the grid) of ``z*``, of the gap and of the slabs at
``z*`` (Å), of ``U(z*)/A`` and of ``h`` (mJ/m²), and the correlation of the ``z*`` pattern
with the reference's. Gap: lowest atom of slab 2 minus highest atom of slab 1 (the first
and second half of the atoms, the scan's order); slabs: the sum of the two slabs' z
extents; both interpolated linearly in thickness at ``z*``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

LOADS_GPA = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0])
#: The ranges divided by the reference model's in :func:`compare_dilatancy`.
RATIO_QUANTITIES = (
    "z_range_angstrom",
    "gap_range_angstrom",
    "h_range_mj_per_m2",
    "u_range_mj_per_m2",
)
#: 1 eV/Å² in mJ/m².
MJ_PER_M2_PER_EV_PER_A2 = 16021.766


def _lateral_range(x: np.ndarray) -> np.ndarray:
    """max − min over the lateral grid, per load (arrays ``[load, a, b]``). NaN entries (points
    an irreducible-registry scan did not store: images of stored ones by symmetry, with the
    same values) are left out; the means stay NaN then (the images carry the weights)."""
    return np.nanmax(x, axis=(1, 2)) - np.nanmin(x, axis=(1, 2))


def gap_and_slabs(folder: Path, shape: tuple[int, int, int]) -> tuple[np.ndarray, np.ndarray]:
    """Gap and summed slab extents (Å) of every stored point, arrays ``[a, b, thickness]``."""
    from flatcontact.foundation.layout import POINTS_DB
    from flatcontact.ispes.store_schema import stored_rows

    gap, slabs = np.full(shape, np.nan), np.full(shape, np.nan)
    for row in stored_rows(folder / POINTS_DB):
        z = row.toatoms().positions[:, 2]
        half = len(z) // 2
        lower, upper = z[:half], z[half:]
        k = (row.i_a, row.i_b, row.i_z)
        gap[k] = upper.min() - lower.max()
        slabs[k] = (lower.max() - lower.min()) + (upper.max() - upper.min())
    return gap, slabs


def dilatancy(folder: Path, loads_gpa=LOADS_GPA) -> dict:
    """Per-load dilatancy figures of the scan in ``folder`` at ``loads_gpa`` (GPa; default
    :data:`LOADS_GPA`, the quartz comparison's; see the module docstring)."""
    loads_gpa = np.asarray(loads_gpa, dtype=float)
    from flatcontact.analysis.constant_pressure import constant_pressure
    from flatcontact.ispes.contract import open_ispes

    ds = open_ispes(folder / "ispes.nc")
    cp = constant_pressure(ds, loads_gpa, form="enthalpy", source=str(folder / "ispes.nc"))
    z_grid = ds["thickness"].values
    gap, slabs = gap_and_slabs(folder, ds["energy"].shape)
    z_star = cp.thickness_angstrom
    at_z = {"gap": np.empty_like(z_star), "slabs": np.empty_like(z_star)}
    for name, grid in (("gap", gap), ("slabs", slabs)):
        for idx in np.ndindex(z_star.shape):
            at_z[name][idx] = np.interp(z_star[idx], z_grid, grid[idx[1], idx[2]])
    z_mean = z_star.mean(axis=(1, 2))
    return {
        "p_gpa": loads_gpa.tolist(),
        "z_mean_angstrom": z_mean.tolist(),
        "dz_dp_angstrom_per_gpa": np.gradient(z_mean, loads_gpa).tolist(),
        "z_range_angstrom": _lateral_range(z_star).tolist(),
        "gap_range_angstrom": _lateral_range(at_z["gap"]).tolist(),
        "gap_mean_angstrom": at_z["gap"].mean(axis=(1, 2)).tolist(),
        "slabs_range_angstrom": _lateral_range(at_z["slabs"]).tolist(),
        "slabs_mean_angstrom": at_z["slabs"].mean(axis=(1, 2)).tolist(),
        "u_range_mj_per_m2": _lateral_range(
            cp.internal_ev_per_a2 * MJ_PER_M2_PER_EV_PER_A2
        ).tolist(),
        "h_range_mj_per_m2": _lateral_range(cp.energy_ev_per_a2 * MJ_PER_M2_PER_EV_PER_A2).tolist(),
        "_z_star": z_star,
    }


def pattern_correlation(z: np.ndarray, z_ref: np.ndarray) -> list[float]:
    """Per load, the correlation over the grid of two ``z*`` patterns (means removed)."""
    d, d_ref = (
        z - z.mean(axis=(1, 2), keepdims=True),
        z_ref - z_ref.mean(axis=(1, 2), keepdims=True),
    )
    num = (d * d_ref).sum(axis=(1, 2))
    return (num / np.sqrt((d**2).sum(axis=(1, 2)) * (d_ref**2).sum(axis=(1, 2)))).tolist()


def compare_dilatancy(folders: dict[str, Path], loads_gpa=LOADS_GPA) -> dict:
    """The dilatancy of several stored scans, the first the reference of the ratios.

    Parameters
    ----------
    folders
        Label -> scan folder (``ispes.nc`` and ``points.db``), in order; the first entry is the
        reference.
    loads_gpa
        Loads (GPa) at which z* is taken; default :data:`LOADS_GPA`.

    Returns
    -------
    dict
        ``{"reference": label, "models": {label: figures}}``: per model the figures of
        :func:`dilatancy`, the correlation of its z* pattern with the reference's, and the
        ranges of z*, the gap, h and U divided by the reference's (``*_over_reference``).

    Raises
    ------
    InputError
        ``folders``: empty.
    """
    from flatcontact.foundation.errors import InputError

    if not folders:
        raise InputError("folders: give at least one LABEL=DIR scan folder")
    models = {label: dilatancy(Path(folder), loads_gpa) for label, folder in folders.items()}
    ref_label = next(iter(models))
    ref = models[ref_label]
    for m in models.values():
        m["z_pattern_correlation_with_reference"] = pattern_correlation(
            m["_z_star"], ref["_z_star"]
        )
        for q in RATIO_QUANTITIES:
            m[f"{q}_over_reference"] = (np.array(m[q]) / np.array(ref[q])).tolist()
    for m in models.values():
        del m["_z_star"]
    return {"reference": ref_label, "models": models}
