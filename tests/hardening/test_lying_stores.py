"""Stores that lie: a ``points.db`` whose rows break its contract is repaired (the bad rows
deleted and recomputed, one warning saying so, the grid equal to an uninterrupted scan's),
a garbled one is one line; an ``ispes.nc`` that breaks its contract is one ``error:`` line
naming the file and the defect, before any large allocation and without a warning line.

One toy scan (seconds) is run once per module; each test works on a copy.
"""

from __future__ import annotations

import json
import shutil
import sqlite3

import ase.db
import h5py
import numpy as np
import pytest
import xarray as xr
from ase.calculators.singlepoint import SinglePointCalculator
from tests.hardening.helpers import assert_refused_cleanly, refused, run_cli, tree
from tests.hardening.test_run_directory import _same_content

from flatcontact.ispes.geometry import thickness
from flatcontact.structures.interface_io import write_interface
from flatcontact.structures.toy import toy_interface

TOY = ["--calculator", "flatcontact.ispes.toy:toy_calculator"]


@pytest.fixture(scope="module")
def scanned(tmp_path_factory):
    """(scan argv without --out, the finished scan's folder) of one toy scan."""
    from flatcontact.cli import main

    base = tmp_path_factory.mktemp("scanned")
    reference = toy_interface(layers=3)
    z0 = thickness(reference)
    iface = write_interface(reference, base / "iface.extxyz")
    argv = ["scan", "--interface", str(iface), *TOY, "--grid", "3", "3"]
    argv += ["--thickness-angstrom", f"{z0 - 0.1:.4f},{z0 + 0.1:.4f}", "--workers", "1"]
    with pytest.raises(SystemExit) as info:
        main([*argv, "--out", str(base / "scan")])
    assert info.value.code in (0, None)
    return argv, base / "scan"


@pytest.fixture
def store(scanned, tmp_path):
    """(argv with --out, copied scan folder, its points.db) with ispes.nc removed."""
    argv, folder = scanned
    shutil.copytree(folder, tmp_path / "scan")
    (tmp_path / "scan" / "ispes.nc").unlink()
    return (
        [*argv, "--out", str(tmp_path / "scan")],
        tmp_path / "scan",
        tmp_path / "scan" / "points.db",
    )


def _first_ids(db_path, n=2):
    with ase.db.connect(str(db_path), use_lock_file=False) as db:
        return [row.id for row in db.select(limit=n)]


def _set_key(db_path, row_id, **values):
    db = ase.db.connect(str(db_path), use_lock_file=False)
    db.update(row_id, **values)


def _raw(db_path, sql, *args):
    with sqlite3.connect(str(db_path)) as con:
        con.execute(sql, args)
    con.close()


def _index_value(db_path, row_id, key, value):
    """Set an index key to any value (ASE's update refuses some), in both of ASE's tables."""
    with sqlite3.connect(str(db_path)) as con:
        (kvp,) = con.execute("SELECT key_value_pairs FROM systems WHERE id=?", (row_id,)).fetchone()
        pairs = json.loads(kvp)
        pairs[key] = value
        con.execute("UPDATE systems SET key_value_pairs=? WHERE id=?", (json.dumps(pairs), row_id))
        con.execute(
            "UPDATE number_key_values SET value=? WHERE id=? AND key=?", (value, row_id, key)
        )
    con.close()


def _negative_index(db):
    _index_value(db, _first_ids(db)[0], "i_a", -1)


def _index_out_of_range(db):
    _index_value(db, _first_ids(db)[0], "i_b", 7)


def _no_keys(db):
    row_id = _first_ids(db)[0]
    _raw(db, "UPDATE systems SET key_value_pairs='{}' WHERE id=?", row_id)
    _raw(db, "DELETE FROM number_key_values WHERE id=?", row_id)
    _raw(db, "DELETE FROM keys WHERE id=?", row_id)


def _nan_energy(db):
    _raw(db, "UPDATE systems SET energy=NULL WHERE id=?", _first_ids(db)[0])


def _nan_stress(db):
    _index_value(db, _first_ids(db)[0], "normal_stress_gpa", float("nan"))


def _conflicting_duplicate(db):
    """A second row for an index, its energy 100 eV off (silently used before)."""
    with ase.db.connect(str(db), use_lock_file=False) as handle:
        row = next(iter(handle.select(limit=1)))
        atoms = row.toatoms()
        atoms.calc = SinglePointCalculator(atoms, energy=row.energy + 100.0)
        handle.write(atoms, key_value_pairs=dict(row.key_value_pairs))


def _identical_duplicate(db):
    with ase.db.connect(str(db), use_lock_file=False) as handle:
        row = next(iter(handle.select(limit=1)))
        handle.write(row.toatoms(), key_value_pairs=dict(row.key_value_pairs))


def _wrong_shift(db):
    _index_value(db, _first_ids(db)[0], "i_a", 2)


REPAIRS = {
    "negative index": _negative_index,
    "index out of range": _index_out_of_range,
    "row without keys": _no_keys,
    "NaN energy": _nan_energy,
    "NaN normal stress": _nan_stress,
    "conflicting duplicate": _conflicting_duplicate,
    "index that contradicts the shift": _wrong_shift,
}


@pytest.mark.parametrize("case", sorted(REPAIRS))
def test_bad_rows_are_deleted_recomputed_and_said(store, scanned, capsys, case):
    argv, folder, db = store
    REPAIRS[case](db)
    code, _out, err = run_cli(argv, capsys)
    assert code in (0, None), err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("warning: "), err
    assert str(db) in lines[0] and "recomputed" in lines[0] and "Traceback" not in err
    _same_content(folder / "ispes.nc", scanned[1] / "ispes.nc")
    # the repaired store is clean: the next run has nothing to say or compute
    (folder / "ispes.nc").unlink()
    code, _, err = run_cli(argv, capsys)
    assert code in (0, None) and err == "", err
    _same_content(folder / "ispes.nc", scanned[1] / "ispes.nc")


def test_an_identical_duplicate_row_is_collapsed_without_a_warning(store, scanned, capsys):
    argv, folder, db = store
    _identical_duplicate(db)
    code, _, err = run_cli(argv, capsys)
    assert code in (0, None) and err == "", err
    _same_content(folder / "ispes.nc", scanned[1] / "ispes.nc")


@pytest.mark.parametrize("where", ["header", "pages"])
def test_a_garbled_store_is_one_line_naming_it(store, tmp_path, capsys, where):
    argv, _folder, db = store
    data = bytearray(db.read_bytes())
    page = int.from_bytes(data[16:18], "big")  # the page size in SQLite's file header
    start = 20 if where == "header" else page + 8  # inside the second page
    data[start : start + 2000] = b"\xa5" * 2000
    db.write_bytes(bytes(data))
    before = tree(tmp_path)
    code, _, err = run_cli(argv, capsys)
    refused(code, err, str(db), "remove it")
    after = tree(tmp_path)
    changed = {k for k in before.keys() | after.keys() if before.get(k) != after.get(k)}
    assert all(k == "scan" or k.startswith("scan/") for k in changed), (
        changed
    )  # nothing outside --out
    assert db.read_bytes() == bytes(data)


@pytest.mark.parametrize(
    "defect, expected",
    [
        ({"thickness_angstrom": "many"}, "thickness_angstrom"),
        ({"thickness_angstrom": [float("nan"), 9.0]}, "thickness_angstrom"),
        ({"a1": "3.0"}, "'a1'"),
    ],
)
def test_a_garbled_resolved_grid_is_one_line(store, capsys, defect, expected):
    argv, _folder, db = store
    handle = ase.db.connect(str(db), use_lock_file=False)
    meta = handle.metadata
    meta["resolved"].update(defect)
    handle.metadata = meta
    code, _, err = run_cli(argv, capsys)
    refused(code, err, str(db), "resolved", expected)


# ---- ispes.nc --------------------------------------------------------------------------------


def _nc(scanned, tmp_path, change) -> str:
    with xr.open_dataset(scanned[1] / "ispes.nc", engine="h5netcdf") as ds:
        ds = ds.load()
    path = tmp_path / "bad.nc"
    change(ds, path)
    return path


def _write(ds, path):
    ds.to_netcdf(path, engine="h5netcdf")


def _a1_string(ds, path):
    ds.attrs["a1"] = "2.5 0"
    _write(ds, path)


def _area_nan(ds, path):
    ds.attrs["area"] = float("nan")
    _write(ds, path)


def _no_energy(ds, path):
    _write(ds.drop_vars("energy"), path)


def _energy_text(ds, path):
    ds["energy"] = ds["energy"].astype(str)
    _write(ds, path)


def _huge_sparse_grid(ds, path):
    """A grid that claims 20000 × 20000 × 50 points, chunked and never written (a few kB)."""
    with h5py.File(path, "w") as f:
        for name, n in (("shift_a", 20000), ("shift_b", 20000), ("thickness", 50)):
            f.create_dataset(name, data=np.arange(n, dtype=float) / n)
            f[name].make_scale(name)
        for var in ("energy", "normal_stress"):
            v = f.create_dataset(var, shape=(20000, 20000, 50), dtype=float, chunks=(64, 64, 5))
            for axis, name in enumerate(("shift_a", "shift_b", "thickness")):
                v.dims[axis].attach_scale(f[name])
        for key in ("a1", "a2", "area"):
            f.attrs[key] = np.atleast_1d(ds.attrs[key])


def _plain_hdf5(ds, path):
    with h5py.File(path, "w") as f:
        f.create_dataset("energy", data=np.zeros((3, 3, 2)))
        f.attrs["a1"] = [2.5, 0.0]


def _not_hdf5(ds, path):
    path.write_bytes(b"CDF\x01 not really netCDF at all" * 20)


NC_CASES = {
    "a1 is a string": (_a1_string, "'a1'"),
    "area is NaN": (_area_nan, "'area'"),
    "no energy variable": (_no_energy, "'energy'"),
    "energy holds text": (_energy_text, "'energy'"),
    "a huge sparse grid": (_huge_sparse_grid, "FLATCONTACT_MAX_"),
    "plain HDF5": (_plain_hdf5, "dimension"),
    "not HDF5": (_not_hdf5, "not a readable netCDF"),
}


@pytest.mark.parametrize("case", sorted(NC_CASES))
def test_an_ispes_file_that_lies_is_one_line_naming_it(scanned, tmp_path, capsys, case):
    change, expected = NC_CASES[case]
    path = _nc(scanned, tmp_path, change)
    line = assert_refused_cleanly(
        ["analyze", path, "--p-gpa", "0.5", "--out", tmp_path / "out"],
        capsys,
        tmp_path,
        [str(path), expected],
    )
    assert "warning" not in line.lower()
