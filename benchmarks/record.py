"""The stored benchmark record of the default run and the test suite (``run_record.json``).

``python -m benchmarks run`` writes its ``"run"`` block, ``python -m benchmarks tests`` its
``"tests"`` block; each block states when, on which commit and how loaded the machine was
(load average against the cores: timings taken next to other work are upper bounds).
:mod:`benchmarks.readme_block` renders the README's figures from this file.
"""

from __future__ import annotations

import datetime
import json
import os
import subprocess
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
#: The record (``FLATCONTACT_BENCH_RECORD`` overrides the path).
RECORD = HERE / "run_record.json"
#: The figures before issue 33 (measured from a fresh clone on a quiet 2-core machine).
BASELINE = HERE / "run_baseline.json"


def record_path() -> Path:
    """Where the record is read and written."""
    return Path(os.environ.get("FLATCONTACT_BENCH_RECORD", RECORD))


def read(path: Path | None = None) -> dict:
    """The stored record (``{}`` when there is none yet)."""
    path = path or record_path()
    return json.loads(path.read_text()) if path.is_file() else {}


def write_block(name: str, block: dict, path: Path | None = None) -> Path:
    """Store ``block`` as the record's ``name`` block, keeping the other blocks."""
    path = path or record_path()
    doc = read(path)
    doc[name] = block
    path.write_text(json.dumps(doc, indent=2) + "\n")
    return path


def machine() -> dict:
    """When, on which commit and how loaded: cores, 1-minute load average, UTC time."""
    try:
        commit = subprocess.run(
            ["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            check=False,
        ).stdout.strip()
    except OSError:
        commit = ""
    return {
        "measured_on": datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M UTC"),
        "commit": commit or None,
        "cpus": os.cpu_count(),
        "load_average": round(os.getloadavg()[0], 2),
    }


def loaded(block: dict) -> bool:
    """True when the machine had more work than half its cores at the start or the end."""
    cpus = block.get("cpus") or 1
    loads = (block.get("load_average"), block.get("load_average_end"))
    return any(x is not None and x > 0.5 * cpus for x in loads)
