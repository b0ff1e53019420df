"""The run's grid checks on a coincidence cell whose shift-lattice index shares a factor with
``scan.grid``: the scan stage scans ``scan_grid(grid, index)`` (7 × 7 for a 6 × 6 request on
the 156-index diamond(111)/graphite cell), and the checks that the stored landscape and
``scan.json`` are this run's must expect that grid, not ``scan.grid`` itself (they refused
every such run after a complete scan: "a 7x7 landscape, the settings scan a 6x6 grid")."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.result_json import SCAN, ContractError, check_document
from flatcontact.ispes.contract import check_grid
from flatcontact.ispes.shift_lattice import scan_grid, scanned_grid


def _landscape(n: int, index: int | None) -> xr.Dataset:
    ds = xr.Dataset({"energy": (("shift_a", "shift_b", "thickness"), np.zeros((n, n, 2)))})
    if index is not None:
        ds.attrs["shift_lattice_index"] = index
    return ds


@pytest.mark.parametrize("index", [4, 9, 12, 156])
def test_a_coincidence_cell_scanned_on_the_coprime_grid_is_this_runs(index):
    n = scan_grid((6, 6), index)[0]
    assert n != 6 and np.gcd(n, index) == 1  # the scan's own choice differs from scan.grid
    ds = _landscape(n, index)
    assert scanned_grid(ds, [6, 6]) == (n, n)
    check_grid(ds, scanned_grid(ds, [6, 6]))


def test_another_grid_is_still_refused():
    ds = _landscape(6, 156)
    with pytest.raises(InputError, match=r"a 6x6 landscape.*7x7 grid \(scan.grid on a shift "):
        check_grid(ds, scanned_grid(ds, [6, 6]))
    ds = _landscape(7, None)
    with pytest.raises(InputError, match="a 7x7 landscape, the settings scan a 6x6 grid"):
        check_grid(ds, scanned_grid(ds, [6, 6]))
    ds = _landscape(6, 49)  # the (1, 2) twist: 6 is coprime to 49
    check_grid(ds, scanned_grid(ds, [6, 6]))


def _scan_json(grid_requested, grid, nz=3) -> dict:
    return {
        "points_total": grid[0] * grid[1] * nz,
        "force_calls_total": 10,
        "thickness_angstrom": [13.0 + 0.1 * i for i in range(nz)],
        "shift_lattice": {"index": 156, "grid_requested": grid_requested, "grid": grid},
    }


def test_scan_json_counts_the_grid_the_scan_used():
    check_document(_scan_json([6, 6], [7, 7]), SCAN, {"grid": [6, 6]})
    with pytest.raises(ContractError, match="grid_requested"):
        check_document(_scan_json([4, 4], [7, 7]), SCAN, {"grid": [6, 6]})
    lying = _scan_json([6, 6], [7, 7])
    lying["points_total"] = 6 * 6 * 3
    with pytest.raises(ContractError, match="points_total"):
        check_document(lying, SCAN, {"grid": [6, 6]})
