"""A command that stops leaves no ``.flatcontact.lock`` in its ``--out``: a calculator that fails
mid-scan, Ctrl-C and SIGTERM in ``scan`` and ``run`` unwind through the writer's release, which
removes the file while the lock is still held; the point store is kept and the same command
resumes from it (a lock left by ``kill -9`` is taken over: tests/hardening/test_run_directory.py).
"""

from __future__ import annotations

import json
import os
import signal

import pytest
from tests.hardening.helpers import TOY_YAML, refused, run_cli, stored_rows

from flatcontact.cli.progress import ScanBar
from flatcontact.structures.interface_io import write_interface
from flatcontact.structures.toy import toy_interface

LOCK = ".flatcontact.lock"
FAILS = "tests.hardening.failing_calculators:FailsWhenPressed"


@pytest.fixture(scope="module")
def toy(tmp_path_factory):
    folder = tmp_path_factory.mktemp("toy")
    return write_interface(toy_interface(layers=3), folder / "interface.extxyz")


def test_a_scan_whose_calculator_fails_mid_scan_leaves_no_lock_file(toy, tmp_path, capsys):
    """The toy model that raises once the slabs are pressed closer than 2 Å: the reference
    evaluates, the compressed points fail; the store keeps the points relaxed before."""
    out = tmp_path / "scan"
    argv = ["scan", "--interface", toy, "--calculator", FAILS]
    argv += ["--calculator-kwarg", "fail_gap_angstrom=2.0", "--p-range-gpa", "0", "1", "3"]
    argv += ["--grid", "2", "2", "--executor", "serial", "--out", out]
    code, _, err = run_cli(argv, capsys)
    refused(code, err, "scan: point at shift", "RuntimeError: gap")
    assert stored_rows(out / "points.db") > 0
    assert not (out / LOCK).exists()
    # the rerun resumes from the store (no lock to take over) and fails again mid-scan
    code, _, err = run_cli(argv, capsys)
    refused(code, err, "scan: point at shift", "RuntimeError: gap")
    assert not (out / LOCK).exists()


def _stop_after(monkeypatch, points: int, stop) -> None:
    """The scan's progress bar calls ``stop()`` once ``points`` grid points are done."""
    shown = ScanBar.__call__

    def call(self, done, total):
        shown(self, done, total)
        if done >= points:
            stop()

    monkeypatch.setattr(ScanBar, "__call__", call)


def _ctrl_c():
    raise KeyboardInterrupt


def _sigterm():
    os.kill(os.getpid(), signal.SIGTERM)


@pytest.mark.parametrize(
    ("stop", "status"), [(_ctrl_c, 130), (_sigterm, 143)], ids=["ctrl-c", "sigterm"]
)
def test_a_run_stopped_mid_scan_leaves_no_lock_file_and_resumes(
    stop, status, tmp_path, capsys, monkeypatch
):
    config = tmp_path / "run.yaml"
    config.write_text(TOY_YAML)
    run = tmp_path / "run"
    with monkeypatch.context() as patch:
        _stop_after(patch, 5, stop)
        code, _, err = run_cli(["run", config, "--out", run], capsys)
    assert code == status, err
    assert "rerun the same command to resume" in err
    assert json.loads((run / "02-scan" / "stage.json").read_text())["state"] == "running"
    assert not (run / LOCK).exists()
    code, out, err = run_cli(["run", config, "--out", run], capsys)
    assert code == 0, err
    assert "resumed" in out.split("2. scan", 1)[1].split("3. analyze", 1)[0]
    assert "stale" not in (run / "run.log").read_text()
    assert not (run / LOCK).exists()


def test_a_scan_stopped_by_ctrl_c_leaves_its_store_and_no_lock_file(
    toy, tmp_path, capsys, monkeypatch
):
    out = tmp_path / "scan"
    argv = ["scan", "--interface", toy, "--calculator", "flatcontact.ispes.toy:toy_calculator"]
    argv += ["--p-range-gpa", "0", "1", "3", "--grid", "3", "3", "--executor", "serial"]
    argv += ["--out", out]
    with monkeypatch.context() as patch:
        _stop_after(patch, 5, _ctrl_c)
        code, _, err = run_cli(argv, capsys)
    assert code == 130, err
    assert stored_rows(out / "points.db") >= 5
    assert sorted(p.name for p in out.iterdir() if p.name.startswith(".")) == []
    code, _, err = run_cli(argv, capsys)
    assert code == 0, err
    assert (out / "ispes.nc").is_file() and not (out / LOCK).exists()
