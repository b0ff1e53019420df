"""Run directory: stages are skipped, resumed or rerun exactly when their inputs say so."""

import json
import os

import pytest

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.rundir import RECORD_NAME, RunDirectory, fingerprint


def _counting_work(calls, name, fail=False):
    def work(folder):
        calls.append(name)
        (folder / "partial.txt").open("a").write("x")
        if fail:
            raise KeyboardInterrupt
        (folder / "out.txt").write_text(name)

    return work


def test_fingerprint_is_order_independent_and_sensitive():
    assert fingerprint({"a": 1, "b": [1, 2]}) == fingerprint({"b": [1, 2], "a": 1})
    assert fingerprint({"a": 1}) != fingerprint({"a": 1.5})


def test_skip_rerun_and_dependency_chain(tmp_path):
    run = RunDirectory(tmp_path)
    calls = []
    first = run.run_stage(1, "build", {"layers": 6}, _counting_work(calls, "build"))
    second = run.run_stage(
        2, "scan", {"grid": 4, "up": first.fingerprint}, _counting_work(calls, "scan")
    )
    assert [first.action, second.action] == ["ran", "ran"]

    again1 = run.run_stage(1, "build", {"layers": 6}, _counting_work(calls, "build"))
    again2 = run.run_stage(
        2, "scan", {"grid": 4, "up": again1.fingerprint}, _counting_work(calls, "scan")
    )
    assert [again1.action, again2.action] == ["skipped", "skipped"]
    assert calls == ["build", "scan"]

    # a changed upstream setting reruns the upstream stage and, through its fingerprint, the downstream one
    changed1 = run.run_stage(1, "build", {"layers": 4}, _counting_work(calls, "build"))
    changed2 = run.run_stage(
        2, "scan", {"grid": 4, "up": changed1.fingerprint}, _counting_work(calls, "scan")
    )
    assert [changed1.action, changed2.action] == ["ran", "ran"]
    assert calls == ["build", "scan", "build", "scan"]
    assert (tmp_path / "01-build.previous" / "out.txt").exists()
    assert (changed1.folder / "partial.txt").read_text() == "x"  # rerun from an empty folder


def test_interrupted_stage_is_resumed_with_its_partial_state(tmp_path):
    run = RunDirectory(tmp_path)
    calls = []
    with pytest.raises(KeyboardInterrupt):
        run.run_stage(1, "scan", {"grid": 4}, _counting_work(calls, "scan", fail=True))
    record = json.loads((tmp_path / "01-scan" / RECORD_NAME).read_text())
    assert record["state"] == "running"
    resumed = run.run_stage(1, "scan", {"grid": 4}, _counting_work(calls, "scan"))
    assert resumed.action == "resumed"
    assert (
        resumed.folder / "partial.txt"
    ).read_text() == "xx"  # the earlier attempt's state was kept


def test_corrupt_or_foreign_record_is_refused(tmp_path):
    run = RunDirectory(tmp_path)
    folder = run.folder(1, "scan")
    folder.mkdir()
    (folder / RECORD_NAME).write_text("{not json")
    with pytest.raises(InputError, match="corrupt stage record"):
        run.run_stage(1, "scan", {}, lambda f: None)
    (folder / RECORD_NAME).write_text(json.dumps({"hello": 1}))
    with pytest.raises(InputError, match="not a flatcontact stage record"):
        run.run_stage(1, "scan", {}, lambda f: None)
    (folder / RECORD_NAME).write_text(
        json.dumps({"stage": "build", "fingerprint": "x", "state": "done"})
    )
    with pytest.raises(InputError, match="belongs to stage 'build'"):
        run.run_stage(1, "scan", {}, lambda f: None)


# ---- the lock file: removed by its writer, never another's ------------------------------


def test_the_writer_removes_its_lock_file_however_it_stops(tmp_path):
    """Done, an exception, Ctrl-C: the lock file goes with the lock (the lock is still held
    while it is removed: a writer that opened it meanwhile retries on a fresh file)."""
    from flatcontact.foundation.rundir import LOCK_NAME, RunLock

    lock = RunLock(tmp_path).acquire()
    assert (tmp_path / LOCK_NAME).read_text().split()[0] == str(os.getpid())
    lock.release()
    assert not (tmp_path / LOCK_NAME).exists()
    lock.release()  # idempotent
    for stop in (RuntimeError("the calculator failed"), KeyboardInterrupt()):
        with pytest.raises(type(stop)), RunLock(tmp_path):
            assert (tmp_path / LOCK_NAME).is_file()
            raise stop
        assert os.listdir(tmp_path) == []
    # a writer that follows takes a real lock: a second one is refused while it is held
    with RunLock(tmp_path):
        with pytest.raises(InputError, match=f"pid {os.getpid()}"):
            RunLock(tmp_path).acquire()
    assert os.listdir(tmp_path) == []


def test_tidy_removes_only_an_empty_directory_the_writer_created(tmp_path):
    from flatcontact.foundation.rundir import RunLock

    made, kept = tmp_path / "made", tmp_path / "kept"
    made.mkdir()
    RunLock(made).acquire().release(tidy="created")
    assert not made.exists()
    made.mkdir()
    lock = RunLock(made).acquire()
    (made / "points.db").write_bytes(b"work")
    lock.release(tidy="created")
    assert os.listdir(made) == ["points.db"]
    kept.mkdir()
    RunLock(kept).acquire().release(tidy=True)
    assert kept.is_dir() and os.listdir(kept) == []


def test_release_never_removes_a_lock_file_another_writer_made(tmp_path):
    """The lock file replaced under a writer (a later writer took the lock over as stale):
    the first writer's release leaves the new file, and the new writer's lock holds."""
    from flatcontact.foundation.rundir import LOCK_NAME, RunLock

    first = RunLock(tmp_path).acquire()
    fresh = tmp_path / "fresh"
    fresh.write_text("")
    os.replace(fresh, tmp_path / LOCK_NAME)  # as _take_over_or_refuse does
    second = RunLock(tmp_path).acquire()
    try:
        first.release()
        assert (tmp_path / LOCK_NAME).read_text().split()[0] == str(os.getpid())
        with pytest.raises(InputError, match="another flatcontact process"):
            RunLock(tmp_path).acquire()
    finally:
        second.release()
    assert not (tmp_path / LOCK_NAME).exists()


def test_a_process_forked_from_the_writer_does_not_remove_its_lock_file(tmp_path):
    """A forked copy of the writer (a worker started by fork) that releases its copy of the
    lock leaves the writer's lock file and lock in place."""
    from flatcontact.foundation.rundir import LOCK_NAME, RunLock

    lock = RunLock(tmp_path).acquire()
    try:
        child = os.fork()
        if child == 0:  # pragma: no cover (the child)
            try:
                lock.release(tidy="created")
            finally:
                os._exit(0)
        _, status = os.waitpid(child, 0)
        assert os.waitstatus_to_exitcode(status) == 0
        assert (tmp_path / LOCK_NAME).read_text().split()[0] == str(os.getpid())
        with pytest.raises(InputError, match=f"pid {os.getpid()}"):
            RunLock(tmp_path).acquire()
    finally:
        lock.release()
    assert not (tmp_path / LOCK_NAME).exists()
