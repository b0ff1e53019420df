"""A finished toy run directory, damaged, moved, locked, read-only or out of disk.

One toy study (seconds) is run once per module; each test works on a copy. What must
hold: a missing or garbled output of a done stage reruns that stage only (and gives the
same numbers), a garbled record or marker is one line naming the file and what to remove,
moving the run directory and its configuration folder reruns nothing, a second writer is
refused in one line while the lock is held and takes over when it is not, a read-only
finished run reports its results, and a full disk is one line after which the rerun
resumes.
"""

from __future__ import annotations

import errno
import json
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from tests.hardening.helpers import refused, run_cli, tree

STAGE_FOLDERS = ("01-build", "02-scan", "03-analyze", "04-laws", "06-contact", "07-report")


@pytest.fixture(scope="module")
def finished(finished_toy):
    """(config folder, run directory) of one finished toy study (built once per process)."""
    return finished_toy


@pytest.fixture
def copy(finished, tmp_path):
    conf, run = finished
    shutil.copytree(conf, tmp_path / "conf")
    shutil.copytree(run, tmp_path / "run")
    return tmp_path / "conf" / "run.yaml", tmp_path / "run"


def _actions(out: str) -> list[str]:
    """The action printed under each stage heading ("unchanged, skipped", "resumed ...")."""
    actions = []
    for line in (ln.strip() for ln in out.splitlines()):
        if line.startswith(("unchanged", "resumed", "done", "off")):
            actions.append(line)
    return actions


def _numbers(value, prefix=""):
    """Numeric leaves of JSON data (timings left out: they differ between runs)."""
    if isinstance(value, dict):
        out = {}
        for k, v in value.items():
            if "second" not in k and "time" not in k:
                out.update(_numbers(v, f"{prefix}.{k}"))
        return out
    if isinstance(value, list):
        out = {}
        for i, v in enumerate(value):
            out.update(_numbers(v, f"{prefix}[{i}]"))
        return out
    if isinstance(value, int | float) and not isinstance(value, bool):
        return {prefix: float(value)}
    return {}


def _same_content(a: Path, b: Path) -> None:
    if a.suffix == ".json":
        na, nb = _numbers(json.loads(a.read_text())), _numbers(json.loads(b.read_text()))

        # counts of this invocation's work (points computed, force calls) differ after a
        # resume; the results do not
        def result(key: str) -> bool:
            return "force_calls" not in key and "points_computed" not in key

        assert {k for k in na.keys() ^ nb.keys() if result(k)} == set()
        na = {k: v for k, v in na.items() if k in nb and result(k)}
        np.testing.assert_allclose([na[k] for k in na], [nb[k] for k in na], rtol=1e-9, atol=1e-12)
    elif a.suffix == ".nc":
        with (
            xr.open_dataset(a, engine="h5netcdf") as da,
            xr.open_dataset(b, engine="h5netcdf") as db,
        ):
            for name in da.data_vars:
                if np.issubdtype(da[name].dtype, np.number):
                    np.testing.assert_allclose(da[name].values, db[name].values, rtol=1e-9)
    else:
        assert a.read_bytes() == b.read_bytes()


DAMAGE = {
    "02-scan/ispes.nc": "02-scan",
    "02-scan/scan.json": "02-scan",
    "03-analyze/friction.csv": "03-analyze",
    "03-analyze/friction.nc": "03-analyze",
    "04-laws/laws.json": "04-laws",
    "06-contact/summary.json": "06-contact",
    "06-contact/contact.nc": "06-contact",
}


# the netCDF files garbled as well as deleted: in the slow suite (the same code path)
CASES = [
    pytest.param(
        name, how, marks=[pytest.mark.slow] if how == "garbled" and name.endswith(".nc") else []
    )
    for name in sorted(DAMAGE)
    for how in ("deleted", "garbled")
]
CASES += [("04-laws/laws.json", "emptied"), ("03-analyze/friction.nc", "emptied")]


@pytest.mark.parametrize("name, how", CASES)
def test_damaged_output_of_a_done_stage_reruns_that_stage_only(copy, finished, capsys, name, how):
    config, run = copy
    target = run / name
    if how == "deleted":
        target.unlink()
    elif how == "garbled":
        target.write_bytes(b"\xff\xfe garbage " * 40)
    else:
        target.write_bytes(b"")
    code, out, err = run_cli(["run", config, "--out", run], capsys)
    assert code == 0, err
    actions = _actions(out)
    stage = DAMAGE[name]
    index = int(stage[:2]) - 1 if stage != "06-contact" else 5
    assert actions[index].startswith("resumed"), out
    others = [a for i, a in enumerate(actions) if i != index and not a.startswith("off")]
    assert all(a == "unchanged, skipped" for a in others), out
    _same_content(target, finished[1] / name)


def test_scan_with_damaged_point_store_recomputes_the_points(copy, finished, capsys):
    config, run = copy
    (run / "02-scan" / "points.db").write_bytes(b"this is not sqlite" * 100)
    code, out, err = run_cli(["run", config, "--out", run], capsys)
    assert code == 0, err
    assert _actions(out)[1].startswith("resumed")
    _same_content(run / "02-scan" / "ispes.nc", finished[1] / "02-scan" / "ispes.nc")


@pytest.mark.parametrize(
    "name, data, expected",
    [
        (
            "03-analyze/stage.json",
            b"\xff\xfe\x00binary",
            ["03-analyze", "stage.json", "remove the folder"],
        ),
        ("04-laws/stage.json", b"{not json", ["04-laws", "stage.json", "remove the folder"]),
        ("04-laws/stage.json", b'{"hello": 1}', ["04-laws", "stage.json", "remove the folder"]),
        ("run.json", b"\xff\xfe\x00binary", ["run.json", "corrupt run marker"]),
        ("run.json", b'{"format": "someone-else/1"}', ["run.json", "not a flatcontact run marker"]),
    ],
)
def test_garbled_record_is_one_line_naming_what_to_remove(copy, capsys, name, data, expected):
    config, run = copy
    (run / name).write_bytes(data)
    before = tree(run)
    code, _, err = run_cli(["run", config, "--out", run], capsys)
    refused(code, err, *expected)
    changed = {k for k in tree(run).keys() ^ before.keys()} | {
        k for k in before if k in tree(run) and tree(run)[k] != before[k]
    }
    assert not any(k.startswith(("0", "report")) for k in changed), changed


def test_moving_the_run_and_its_config_folder_reruns_nothing(copy, tmp_path, capsys):
    config, run = copy
    moved = tmp_path / "elsewhere"
    moved.mkdir()
    shutil.move(run, moved / "run")
    shutil.move(config.parent, moved / "conf")
    code, out, err = run_cli(["run", moved / "conf" / "run.yaml", "--out", moved / "run"], capsys)
    assert code == 0, err
    actions = [a for a in _actions(out) if not a.startswith("off")]
    assert actions == ["unchanged, skipped"] * 6, out


def test_a_finished_run_on_a_read_only_mount_reports_its_results(copy, monkeypatch, capsys):
    from flatcontact import pipeline

    config, run = copy
    monkeypatch.setattr(
        pipeline, "writable", lambda root: OSError(errno.EROFS, "Read-only file system")
    )
    before = tree(run)
    code, out, err = run_cli(["run", config, "--out", run], capsys)
    assert code == 0, err
    # the console wraps long lines anywhere, even inside the path (a worker's longer tmp path)
    assert f"report:{(run / 'report.html').resolve()}" in "".join(out.split())
    assert tree(run) == before
    # with a stage to redo, the read-only run says which and what to do, and writes nothing
    (run / "04-laws" / "laws.json").unlink()
    before = tree(run)
    code, _, err = run_cli(["run", config, "--out", run], capsys)
    refused(code, err, "Read-only file system", "laws", "laws.json", "copy the run directory")
    assert tree(run) == before


def test_a_second_writer_is_refused_while_the_lock_is_held(copy, capsys):
    from flatcontact.foundation.rundir import RunLock

    config, run = copy
    lock = RunLock(run).acquire()
    try:
        code, _, err = run_cli(["run", config, "--out", run], capsys)
        refused(code, err, "--out", str(run), f"pid {os.getpid()}")
        code, _, err = run_cli(["scan", "--out", run, "--grid", "2", "2"], capsys)
        refused(code, err, "--out", f"pid {os.getpid()}")
    finally:
        lock.release()
    # a lock file left by a dead writer (kill -9) does not block: the kernel lock died with it
    (run / ".flatcontact.lock").write_text("999999\n")
    code, _, err = run_cli(["run", config, "--out", run], capsys)
    assert code == 0, err
    assert not (run / ".flatcontact.lock").exists()  # taken over, removed by its new writer


@pytest.mark.parametrize(
    "folder",
    [
        "03-analyze",
        pytest.param("04-laws", marks=pytest.mark.slow),
        pytest.param("06-contact", marks=pytest.mark.slow),
        "07-report",
    ],
)
def test_out_of_disk_in_a_stage_is_one_line_and_the_rerun_resumes(
    copy, monkeypatch, capsys, folder
):
    """ENOSPC on the first file a stage writes (simulated at os.replace, which every atomic
    write of a stage goes through); analysis.p_gpa changed so analyze and what follows rerun."""
    config, run = copy
    config.write_text(
        config.read_text().replace("p_gpa: [0.0, 0.5, 1.0]", "p_gpa: [0.0, 0.5, 1.0, 1.25]")
    )
    real_replace = os.replace

    def full_disk(src, dst, *args, **kwargs):
        if f"/{folder}/" in str(dst):
            raise OSError(errno.ENOSPC, "No space left on device", str(dst))
        return real_replace(src, dst, *args, **kwargs)

    monkeypatch.setattr(os, "replace", full_disk)
    code, _, err = run_cli(["run", config, "--out", run], capsys)
    refused(code, err, "no space left", folder, "rerun the same command")
    record = (
        json.loads((run / folder / "stage.json").read_text())
        if (run / folder / "stage.json").exists()
        else None
    )
    assert record is None or record["state"] == "running"
    assert not list(run.rglob("*.part")), "a partial file was left behind"
    monkeypatch.setattr(os, "replace", real_replace)
    code, out, err = run_cli(["run", config, "--out", run], capsys)
    assert code == 0, err
    assert json.loads((run / folder / "stage.json").read_text())["state"] == "done"
    assert (run / "report.html").is_file()
    assert all(a == "unchanged, skipped" for a in _actions(out)[:2])


def test_out_of_disk_in_the_scan_store_is_one_line_and_the_rerun_resumes(
    copy, finished, monkeypatch, capsys
):
    """SQLite says "database or disk is full" (not ENOSPC) when the point store cannot grow."""
    import sqlite3

    from flatcontact.ispes.store import PointStore

    config, run = copy
    (run / "02-scan" / "ispes.nc").unlink()
    (run / "02-scan" / "points.db").unlink()  # the scan recomputes its points
    (run / "02-scan" / "probe.json").unlink()  # and its probe (a reused probe says so in a line)
    calls = {"n": 0}
    real_write = PointStore.write

    def full_after_ten(self, result):
        calls["n"] += 1
        if calls["n"] > 10:
            raise sqlite3.OperationalError("database or disk is full")
        return real_write(self, result)

    monkeypatch.setattr(PointStore, "write", full_after_ten)
    code, _, err = run_cli(["run", config, "--out", run], capsys)
    refused(code, err, "no space left", "database or disk is full", "rerun the same command")
    monkeypatch.setattr(PointStore, "write", real_write)
    code, _, err = run_cli(["run", config, "--out", run], capsys)
    assert code == 0, err
    _same_content(run / "02-scan" / "ispes.nc", finished[1] / "02-scan" / "ispes.nc")


def _bind_read_only(src, dst) -> bool:
    """Bind-mount ``src`` read-only on ``dst``; False where that needs privileges we lack."""
    import subprocess

    dst.mkdir()
    ok = (
        subprocess.run(["mount", "--bind", str(src), str(dst)], capture_output=True).returncode == 0
    )
    if (
        ok
        and subprocess.run(
            ["mount", "-o", "remount,ro,bind", str(dst)], capture_output=True
        ).returncode
        != 0
    ):
        subprocess.run(["umount", str(dst)], capture_output=True)
        ok = False
    return ok


def test_a_finished_run_on_a_real_read_only_mount(copy, tmp_path, capsys):
    """The same on a real read-only bind mount (needs mount privileges; skipped without)."""
    import subprocess

    config, run = copy
    mounted = tmp_path / "ro"
    if not _bind_read_only(run, mounted):
        pytest.skip("no privilege to bind-mount read-only here")
    again = tmp_path / "ro2"
    try:
        code, out, err = run_cli(["run", config, "--out", mounted], capsys)
        assert code == 0, err
        assert err == ""
        assert "report.html" in "".join(out.split())  # wrapped anywhere by the console
        subprocess.run(["umount", str(mounted)], check=True)
        (run / "06-contact" / "summary.json").unlink()
        assert _bind_read_only(run, again)
        code, _, err = run_cli(["run", config, "--out", again], capsys)
        refused(code, err, "Read-only file system", "contact", "summary.json", "copy")
    finally:
        for m in (mounted, again):
            subprocess.run(["umount", str(m)], capture_output=True)


@pytest.mark.parametrize(
    "outputs",
    [["laws.json"], {"laws.json": 3}, {"../../outside.txt": "0" * 64}, {"/etc/hostname": "0" * 64}],
)
def test_a_tampered_output_list_is_a_corrupt_record_and_removes_nothing(
    copy, tmp_path, capsys, outputs
):
    config, run = copy
    bait = tmp_path / "outside.txt"
    bait.write_text("keep me")
    record_path = run / "04-laws" / "stage.json"
    record = json.loads(record_path.read_text())
    record["outputs"] = outputs
    record_path.write_text(json.dumps(record))
    code, _, err = run_cli(["run", config, "--out", run], capsys)
    refused(code, err, "04-laws", "stage.json", "remove the folder")
    assert bait.read_text() == "keep me"
