"""The driver lock ``points.db.driver``: one driver per store, its file removed when the
driver closes the store (done, refused, Ctrl-C), never a file another driver holds, never
from a forked copy; ``kill -9`` leaves it and the next driver takes it over and resumes."""

import os
import signal
import subprocess
import sys
import textwrap

import pytest
from tests.ispes.test_store_rows import _result

from flatcontact.foundation.errors import InputError
from flatcontact.ispes import store as store_module
from flatcontact.ispes.store import PointStore
from flatcontact.structures.toy import toy_interface

SETTINGS = {"test": "lock"}


def _lock(db):
    return db.with_name(db.name + ".driver")


def _held(db) -> bool:
    """Whether another open of the store is refused as a second driver."""
    try:
        PointStore(db, SETTINGS, toy_interface(layers=3)).close()
    except InputError as exc:
        assert "another flatcontact scan is writing" in str(exc)
        return True
    return False


def test_a_closed_store_leaves_no_lock_file_and_resumes(tmp_path):
    db, ref = tmp_path / "points.db", toy_interface(layers=3)
    with PointStore(db, SETTINGS, ref) as store:
        assert _lock(db).is_file() and _held(db)
        assert _lock(db).is_file()  # the refused second driver removed nothing
        store.write(_result(ref, 0))
    assert not _lock(db).exists()
    with PointStore(db, SETTINGS, ref) as store:  # resumed: the point is there
        assert set(store.done()) == {_result(ref, 0).index}
    assert not _lock(db).exists()


def test_a_store_refused_or_interrupted_leaves_no_lock_file(tmp_path):
    db, ref = tmp_path / "points.db", toy_interface(layers=3)
    PointStore(db, SETTINGS, ref).close()
    with pytest.raises(InputError, match="different settings"):
        PointStore(db, {"test": "other"}, ref)
    assert not _lock(db).exists()
    with pytest.raises(KeyboardInterrupt), PointStore(db, SETTINGS, ref):
        raise KeyboardInterrupt
    assert not _lock(db).exists()


def test_never_removes_a_lock_file_it_does_not_hold(tmp_path):
    """A driver whose path now names another file (a takeover, a removal and a new driver)
    lets its own lock go and leaves that file alone."""
    db, ref = tmp_path / "points.db", toy_interface(layers=3)
    store = PointStore(db, SETTINGS, ref)
    _lock(db).unlink()
    _lock(db).write_text("someone else's")
    store.close()
    assert _lock(db).read_text() == "someone else's"


def test_a_forked_copy_never_removes_the_lock_nor_lets_it_go(tmp_path):
    db, ref = tmp_path / "points.db", toy_interface(layers=3)
    with PointStore(db, SETTINGS, ref) as store:
        pid = os.fork()
        if pid == 0:  # the child: its copy of the lock given up, then gone at once
            store._driver_lock.release()
            os._exit(0)
        assert os.waitpid(pid, 0)[1] == 0
        assert _lock(db).is_file() and _held(db)
    assert not _lock(db).exists()


def test_a_driver_that_locked_a_removed_file_opens_the_path_again(tmp_path, monkeypatch):
    """Driver B opens the lock file; driver A stops (removes it, lets go) before B's flock:
    B's lock is on a removed file, so B opens the path again. One driver: a third is refused."""
    db = tmp_path / "points.db"
    first = store_module._DriverLock(db)
    flock, calls = store_module.fcntl.flock, []

    def first_stops_in_between(handle, op):
        if not calls:
            first.release()
        calls.append(op)
        return flock(handle, op)

    monkeypatch.setattr(store_module.fcntl, "flock", first_stops_in_between)
    second = store_module._DriverLock(db)
    assert len(calls) == 2  # the removed file's lock, then the path's new file
    assert store_module._names(_lock(db), second._handle)
    with pytest.raises(InputError, match="another flatcontact scan is writing"):
        store_module._DriverLock(db)
    second.release()
    assert not _lock(db).exists()


KILLED = textwrap.dedent(
    """
    import sys, time
    from flatcontact.ispes.store import PointStore
    from flatcontact.structures.toy import toy_interface
    from tests.ispes.test_store_rows import _result

    ref = toy_interface(layers=3)
    store = PointStore(sys.argv[1], {"test": "lock"}, ref)
    store.write(_result(ref, 0))
    store.flush()
    print("open", flush=True)
    time.sleep(600)
    """
)


def test_kill_9_leaves_the_lock_file_and_the_next_driver_takes_it_over(tmp_path):
    db = tmp_path / "points.db"
    root = str(__import__("pathlib").Path(__file__).parents[2])
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([root, os.environ.get("PYTHONPATH", "")])}
    proc = subprocess.Popen(
        [sys.executable, "-c", KILLED, str(db)], stdout=subprocess.PIPE, text=True, env=env
    )
    try:
        assert proc.stdout.readline().split() == ["open"]
        assert _held(db)
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait(timeout=60)
    assert _lock(db).is_file()
    ref = toy_interface(layers=3)
    with PointStore(db, SETTINGS, ref) as store:
        assert set(store.done()) == {_result(ref, 0).index}
    assert not _lock(db).exists()
