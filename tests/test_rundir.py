"""Run directory: stages are skipped, resumed or rerun exactly when their inputs say so."""

import json

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
