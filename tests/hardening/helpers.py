"""Shared by the hardening corpus: run the CLI in-process, check the one-line refusal and
that a refused command wrote nothing (no stage started, nothing outside --out)."""

from __future__ import annotations

import os
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

from flatcontact.cli import main

#: A tiny study on the toy Lennard-Jones interface: the whole run takes seconds. Its 3×3
#: grid trips the contact stage's trust gates (broken_symmetry: 36 % on 3×3 points;
#: negative_slope of σ_MSS; on 5×5, in_slab_slip and degenerate_minima), which these tests,
#: about files and faults, accept.
TOY_YAML = """\
structure: {kind: toy-lj, layers: 3}
potential: {calculator: {target: "flatcontact.ispes.toy:toy_calculator"}}
scan:
  grid: [3, 3]
  p_range_gpa: {lo_gpa: -0.2, hi_gpa: 1.5, n: 4}
  executor: serial
analysis: {p_gpa: [0.0, 0.5, 1.0]}
contact: {p0_gpa: [0.5, 1.0], accept_untrusted: [broken_symmetry, negative_slope, in_slab_slip, degenerate_minima]}
report: {svg: false}
"""


def run_cli(argv, capsys):
    """Run ``flatcontact argv`` in-process; (exit code, stdout, stderr)."""
    with pytest.raises(SystemExit) as info:
        main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return info.value.code, out, err


def tree(root: Path) -> dict[str, tuple[int, int]]:
    """Every file and directory below ``root`` with its size and mtime (ns)."""
    out = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for name in dirnames + filenames:
            p = Path(dirpath) / name
            st = p.lstat()
            out[str(p.relative_to(root))] = (st.st_size if p.is_file() else 0, st.st_mtime_ns)
    return out


def refused(code, err, *names):
    """Assert exit 2 and one ``error:`` line naming every string of ``names``; return it."""
    assert code == 2, err
    lines = err.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert "Traceback" not in err and "Warning" not in err
    for name in names:
        assert name in lines[0], (name, lines[0])
    return lines[0]


def assert_refused_cleanly(argv, capsys, where: Path, names, out: Path | None = None):
    """Run ``argv`` in ``where``: refused in one line naming ``names``; nothing written in
    ``where`` (so nothing outside --out) and no stage folder under ``out``."""
    before = tree(where)
    code, _, err = run_cli(argv, capsys)
    line = refused(code, err, *names)
    assert tree(where) == before, "a refused command wrote files"
    if out is not None:
        assert not any(out.glob("0*-*")), "a stage started"
    return line


def finished_toy_run(base: Path) -> tuple[Path, Path]:
    """(config folder, run directory) of one finished toy study (:data:`TOY_YAML`) in ``base``."""
    from flatcontact.cli import main

    conf = base / "conf"
    conf.mkdir()
    (conf / "run.yaml").write_text(TOY_YAML)
    with pytest.raises(SystemExit) as info:
        main(["run", str(conf / "run.yaml"), "--out", str(base / "run")])
    assert info.value.code == 0
    return conf, base / "run"


def stored_rows(db: Path) -> int:
    """Rows of a point store (``points.db``) as a concurrent reader sees them; 0 before it
    exists or while it is locked."""
    try:
        with sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=0.1) as con:
            return con.execute("SELECT count(*) FROM systems").fetchone()[0]
    except sqlite3.Error:
        return 0


def kill_9_when(argv: list[str], ready, poll_seconds: float = 0.005) -> None:
    """Start ``python -m flatcontact argv`` in its own process group, SIGKILL the group once
    ``ready()`` holds; assert the command was still running then and died of the signal."""
    # every point committed as it is stored, so that ``ready`` reading the store sees the
    # scan's progress (in 0.5 s batches a short grid can end before its first commit)
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(sys.path),
        "FLATCONTACT_COMMIT_INTERVAL_S": "0",
    }
    driver = subprocess.Popen(
        [sys.executable, "-m", "flatcontact", *map(str, argv)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        env=env,
        start_new_session=True,
    )
    try:
        end = time.monotonic() + 300
        while driver.poll() is None and time.monotonic() < end and not ready():
            time.sleep(poll_seconds)
        assert driver.poll() is None, "the command ended before the kill: make it longer"
        os.killpg(driver.pid, signal.SIGKILL)
        assert driver.wait(timeout=30) == -signal.SIGKILL
    finally:
        if driver.poll() is None:
            os.killpg(driver.pid, signal.SIGKILL)
