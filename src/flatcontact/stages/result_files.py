"""Checked readers of the stages' netCDF results, ``friction.nc`` and ``contact.nc``.

A stage writes these files and records their SHA-256 (:mod:`flatcontact.foundation.rundir`), so a file
changed after the stage is recomputed on the next run. What is read back must still follow
the file's contract, whatever put it there (a bug, a disk fault, an edited record): the
reader checks, before a value is used,

- the file: a regular file (not a link), at most :data:`MAX_BYTES`, readable as netCDF4;
- the sizes, before anything is loaded: the load dimension within the ``loads`` bound
  (:mod:`flatcontact.foundation.limits`), every other dimension within :data:`MAX_SAMPLES`;
- the load coordinate (``p_gpa``, ``p0``): numbers, finite, no load twice and, when the
  caller knows them, exactly the loads the settings asked for (in any order);
- the required variables: present, numbers, along the load dimension, finite (the per-load
  results every consumer reads); no ±inf in any float variable (NaN is the files' "not
  defined here", e.g. a barrier at a load without one);
- the required attributes: present, finite numbers (the cell ``a1``, ``a2``, ``area`` of
  ``friction.nc``; the contact parameters ``param_*`` of ``contact.nc``).

A file that fails is refused in one :class:`~flatcontact.foundation.errors.InputError` line naming it
and the first defect, with the way to recompute it (remove the stage folder and rerun).
"""

from __future__ import annotations

import os
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from flatcontact.foundation import limits
from flatcontact.foundation.errors import InputError
from flatcontact.ispes.contract import finite_attribute, numeric_dtype

#: Largest results file read (bytes): the paper's study writes ~1 MB.
MAX_BYTES = 2_000_000_000
#: Largest size of a dimension other than the loads (path samples, displacements).
MAX_SAMPLES = 1_000_000


@dataclass(frozen=True)
class ResultContract:
    """What one results file must hold (see the module)."""

    name: str
    index: str
    required: tuple[str, ...]
    attrs: tuple[str, ...]


FRICTION = ResultContract(
    name="friction.nc",
    index="p_gpa",
    required=("tau_mpa", "sigma_mss_mpa", "shear_stiffness_gpa_per_nm"),
    attrs=("a1", "a2", "area"),
)
CONTACT = ResultContract(
    name="contact.nc",
    index="p0",
    required=("gross_sliding_stress", "uniform_shear_strength", "initial_lateral_stiffness"),
    attrs=(
        "param_radius_um",
        "param_contact_modulus_gpa",
        "param_shear_modulus_gpa",
        "param_k_mpa_per_gpa",
        "param_tau0_mpa",
        "param_mu_mpa_per_gpa",
        "param_sigma0_mpa",
    ),
)


def _refuse(path: Path, defect: str) -> InputError:
    return InputError(
        f"{path}: {defect}; the file does not follow its contract: remove {path.parent} and "
        "rerun to recompute it"
    )


def open_result(path: str | os.PathLike[str], contract: ResultContract, loads=None):
    """``path`` read into memory and checked against ``contract``; ``loads``: the load
    values the settings asked for (compared to 1e-9 GPa), or None.

    Returns
    -------
    xarray.Dataset

    Raises
    ------
    InputError
        One line naming ``path`` and the first defect (see the module).
    """
    import xarray as xr

    path = Path(path)
    if path.is_symlink() or not path.is_file():
        raise _refuse(path, "missing, or not a regular file")
    size = path.stat().st_size
    if size > MAX_BYTES:
        raise _refuse(path, f"{size} bytes, more than a results file holds ({MAX_BYTES})")
    try:
        with warnings.catch_warnings():  # h5netcdf on plain HDF5, xarray decoding notes
            warnings.simplefilter("ignore")
            with xr.open_dataset(path, engine="h5netcdf") as ds:
                _check_sizes(ds, path, contract)
                ds = ds.load()
    except InputError:
        raise
    except (OSError, ValueError, TypeError, KeyError, AttributeError, RuntimeError) as exc:
        raise _refuse(path, f"not a readable netCDF file ({exc.__class__.__name__})") from None
    _check_index(ds, path, contract, loads)
    _check_variables(ds, path, contract)
    _check_attrs(ds, path, contract)
    return ds


def _check_sizes(ds, path: Path, contract: ResultContract) -> None:
    if contract.index not in ds.dims:
        raise _refuse(path, f"no '{contract.index}' dimension")
    for dim, n in ds.sizes.items():
        if dim == contract.index:
            bound = limits.bound("loads")
        else:
            bound = MAX_SAMPLES
        if n > bound:
            raise _refuse(path, f"dimension '{dim}' claims {n} entries (bound {bound})")


def _check_index(ds, path: Path, contract: ResultContract, loads) -> None:
    if contract.index not in ds.coords or not numeric_dtype(ds[contract.index].values.dtype):
        raise _refuse(path, f"coordinate '{contract.index}' missing or not numbers")
    p = np.asarray(ds[contract.index].values, dtype=float)
    if p.size == 0 or not np.all(np.isfinite(p)):
        raise _refuse(path, f"coordinate '{contract.index}' empty or not finite")
    if np.unique(p).size != p.size:
        raise _refuse(path, f"coordinate '{contract.index}' repeats a load")
    if loads is not None:
        want = np.sort(np.asarray(list(loads), dtype=float))
        if want.shape != p.shape or not np.allclose(want, np.sort(p), rtol=0, atol=1e-9):
            raise _refuse(
                path,
                f"coordinate '{contract.index}' holds {p.tolist()}, the settings ask for "
                f"{want.tolist()}",
            )


def _check_variables(ds, path: Path, contract: ResultContract) -> None:
    for name in contract.required:
        if name not in ds.data_vars:
            raise _refuse(path, f"variable '{name}' missing")
        var = ds[name]
        if var.dims[:1] != (contract.index,) or not numeric_dtype(var.values.dtype):
            raise _refuse(path, f"variable '{name}' must be numbers along '{contract.index}'")
        if not np.all(np.isfinite(np.asarray(var.values, dtype=float))):
            raise _refuse(path, f"variable '{name}' holds NaN or inf")
    for name, var in ds.data_vars.items():
        if np.issubdtype(var.dtype, np.floating) and np.any(np.isinf(var.values)):
            raise _refuse(path, f"variable '{name}' holds inf")


def _check_attrs(ds, path: Path, contract: ResultContract) -> None:
    for name in contract.attrs:
        if name not in ds.attrs:
            raise _refuse(path, f"attribute '{name}' missing")
        try:
            finite_attribute(ds, name, str(path), "finite numbers")
        except InputError as exc:
            raise _refuse(path, str(exc).removeprefix(f"{path}: ")) from None
