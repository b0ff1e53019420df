"""A worker process that dies mid-scan (a model library's crash, the out-of-memory killer):
one ``error:`` line that says how it ended and how to go on, no traceback; the rerun resumes
from the points stored before and finishes the grid."""

import json
import os
import subprocess
import sys
from pathlib import Path

from flatcontact.ispes.geometry import thickness
from flatcontact.structures.interface_io import write_interface
from flatcontact.structures.toy import toy_interface

REPO = Path(__file__).resolve().parents[2]
DYING = "tests.cli.dying_worker:dying_toy"


def _scan(args, env_extra=None):
    env = {**os.environ, "PYTHONPATH": str(REPO), "FLATCONTACT_COMMIT_INTERVAL_S": "0"}
    env.update(env_extra or {})
    return subprocess.run(
        [sys.executable, "-m", "flatcontact", "scan", *args],
        capture_output=True, text=True, env=env, timeout=300,
    )  # fmt: skip


def test_a_dead_worker_is_one_line_and_the_rerun_resumes(tmp_path):
    toy_reference = toy_interface(layers=3)
    interface = write_interface(toy_reference, tmp_path / "interface.extxyz")
    z0 = thickness(toy_reference)
    out = tmp_path / "scan"
    args = [
        "--interface", str(interface), "--calculator", DYING, "--workers", "2",
        "--grid", "4", "4", "--thickness-angstrom", f"{z0 - 0.2},{z0},{z0 + 0.2}",
        "--out", str(out), "--json",
    ]  # fmt: skip
    died = _scan(args)
    assert died.returncode == 1, died.stderr
    lines = [ln for ln in died.stderr.splitlines() if ln.strip()]
    errors = [ln for ln in lines if ln.startswith("error:")]
    assert len(errors) == 1 and "Traceback" not in died.stderr, died.stderr
    assert "SIGKILL" in errors[0] and "run the same command again to resume" in errors[0]
    assert "out-of-memory" in errors[0]
    assert (out / "points.db").exists()

    again = _scan(args, {"FLATCONTACT_TEST_KEEP_WORKERS": "1"})
    assert again.returncode == 0, again.stderr
    summary = json.loads(again.stdout)
    assert summary["points_total"] == 4 * 4 * 3
    assert 0 < summary["points_computed"] < summary["points_total"]  # some were kept
