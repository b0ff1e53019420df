"""A closed point store is one file: no ``points.db-wal`` / ``-shm`` (nor the driver's lock)
beside it after the store is closed (a normal end, a refused reopen, Ctrl-C), after a reader
is done with it (:func:`flatcontact.ispes.store_schema.stored_rows`, the slip table, the
dilatancy study), and after a reopen folds in the log a ``kill -9`` left, with every point
the log held now in ``points.db`` alone (users copy and keep run directories: a copy of the
file without its log must hold the points).

The garbage collector is off in these tests: a connection left open waits for it (a sqlite3
connection is a reference cycle) and would keep the side files only until it happens to run.
"""

import gc
import shutil

import numpy as np
import pytest
from tests.ispes.test_store_crash import write_and_kill
from tests.ispes.test_store_rows import _result

from flatcontact.foundation.errors import InputError
from flatcontact.ispes.slip import store_points
from flatcontact.ispes.store import SIDE_SUFFIXES, PointStore
from flatcontact.ispes.store_schema import stored_rows
from flatcontact.structures.toy import toy_interface

SETTINGS = {"test": "side files"}


@pytest.fixture(autouse=True)
def no_garbage_collector():
    gc.collect()
    gc.disable()
    try:
        yield
    finally:
        gc.enable()


def _beside(db) -> list[str]:
    """The side files of ``db`` present (SQLite's log and index, journal, driver lock)."""
    return [s for s in SIDE_SUFFIXES if db.with_name(db.name + s).exists()]


def _store(tmp_path, n: int = 3):
    db, ref = tmp_path / "points.db", toy_interface(layers=3)
    with PointStore(db, SETTINGS, ref) as store:
        for k in range(n):
            store.write(_result(ref, k))
    return db, ref


def test_closing_and_reopening_a_store_leaves_the_file_alone(tmp_path):
    db, ref = _store(tmp_path)
    assert _beside(db) == []
    with PointStore(db, SETTINGS, ref) as store:  # resumed: rows read and checked
        assert len(store) == 3
        assert _beside(db) == ["-wal", "-shm", ".driver"]  # open: the log is in use
        store.write(_result(ref, 3))
    assert _beside(db) == []
    with pytest.raises(InputError, match="different settings"):
        PointStore(db, {"test": "other"}, ref)
    assert _beside(db) == []
    with pytest.raises(KeyboardInterrupt), PointStore(db, SETTINGS, ref) as store:
        store.write(_result(ref, 4))
        raise KeyboardInterrupt
    assert _beside(db) == []
    with PointStore(db, SETTINGS, ref) as store:  # Ctrl-C committed the point written
        assert len(store) == 5


def test_the_readers_close_what_they_open(tmp_path):
    db, _ = _store(tmp_path)
    rows = list(stored_rows(db))
    assert [(r.i_a, r.energy) for r in rows] == [(k, -1.0 - k / 7) for k in range(3)]
    assert _beside(db) == []
    points = list(store_points(db))
    assert [p[0] for p in points] == [(k, 0, 0) for k in range(3)]
    assert _beside(db) == []
    given_up = stored_rows(db)
    next(given_up)
    assert _beside(db) == ["-wal", "-shm"]  # the reader's connection is open
    given_up.close()
    assert _beside(db) == []


def test_the_dilatancy_reader_closes_the_store(tmp_path):
    from flatcontact.studies.dilatancy import gap_and_slabs

    db, _ = _store(tmp_path)
    gap, _ = gap_and_slabs(tmp_path, (3, 1, 1))
    assert np.isfinite(gap).all()
    assert _beside(db) == []


def test_a_reopen_folds_the_log_a_kill_9_left_into_the_file(tmp_path):
    """The killed driver's committed points live in its -wal; a reopen and close moves them
    into points.db: the file copied alone then holds all 25."""
    db = tmp_path / "points.db"
    write_and_kill(db)
    assert "-wal" in _beside(db)
    PointStore(db, {"test": "crash"}, toy_interface(layers=3)).close()
    assert _beside(db) == []
    alone = tmp_path / "copy" / "points.db"
    alone.parent.mkdir()
    shutil.copyfile(db, alone)
    assert len(list(stored_rows(alone))) == 25
    assert _beside(alone) == []
