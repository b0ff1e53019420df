"""``friction.nc`` is a file contract: the same variables, dimensions, dtypes, attributes and values
as the references in ``tests/analysis/data``, written by the hand-assembled ``friction_dataset`` of
commit 0744133 (before it was built from tables) from the stored Al(111) ISPES of
``docs/measured/examples/al111``. Two analyses cover the dataset's branches: MEP, stackings and the
grid's error estimate, three loads; and no stackings (an empty ``stacking`` dimension), no grid
error, each load's own energy zero, the stress load source.

Only ``flatcontact_version`` may differ (it names the code that wrote the file).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from flatcontact.analysis.analyze import analyze_ispes
from flatcontact.analysis.options import AnalysisOptions
from flatcontact.analysis.outputs import friction_dataset
from flatcontact.ispes.contract import open_ispes

ROOT = Path(__file__).resolve().parents[2]
ISPES = ROOT / "docs" / "measured" / "examples" / "al111" / "02-scan" / "ispes.nc"
DATA = Path(__file__).resolve().parent / "data"

CASES = {
    "al111_mep": ([0.0, 0.5, 1.0], AnalysisOptions(direction_deg=0.0, with_mep=True)),
    "al111_plain": (
        [0.5, 1.5],
        AnalysisOptions(
            with_stackings=False,
            with_grid_error=False,
            energy_zero="each",
            load_source="stress",
        ),
    ),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_friction_dataset_matches_the_stored_reference(case, tmp_path):
    p_gpa, options = CASES[case]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = analyze_ispes(open_ispes(ISPES), p_gpa, options)
    written = tmp_path / "friction.nc"
    friction_dataset(result).to_netcdf(written, engine="h5netcdf")
    with (
        xr.open_dataset(written, engine="h5netcdf") as new,
        xr.open_dataset(DATA / f"friction_{case}.nc", engine="h5netcdf") as ref,
    ):
        assert new.attrs.pop("flatcontact_version") and ref.attrs.pop("flatcontact_version")
        assert list(new.data_vars) == list(ref.data_vars)
        assert list(new.coords) == list(ref.coords)
        assert list(new.attrs) == list(ref.attrs)
        assert dict(new.sizes) == dict(ref.sizes)
        for name in ref.variables:
            assert new[name].dtype == ref[name].dtype, name
            assert new[name].dims == ref[name].dims, name
        xr.testing.assert_identical(new, ref)  # values bit for bit (NaN where NaN), attributes


def test_the_reference_is_not_empty():
    """The comparison means something: the references hold finite τ at every load and paths."""
    with xr.open_dataset(DATA / "friction_al111_mep.nc", engine="h5netcdf") as ref:
        assert ref.sizes["p_gpa"] == 3 and ref.sizes["stacking"] > 0
        assert np.all(np.isfinite(ref["tau_mpa"].values)) and np.all(ref["tau_mpa"].values > 0)
        assert np.isfinite(ref["path_force"].values).sum() > 100
    with xr.open_dataset(DATA / "friction_al111_plain.nc", engine="h5netcdf") as ref:
        assert ref.sizes["stacking"] == 0
        assert np.all(np.isnan(ref["tau_grid_error_mpa"].values))
