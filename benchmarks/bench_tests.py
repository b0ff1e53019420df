"""Wall time of the test suite as ``make test`` runs it (``pytest -n 2``, the fast selection).

Runs the Makefile's pytest command (:data:`COMMAND`, from the repository root, this Python)
and stores the wall time, the counts of its summary line and the machine's load as the
``"tests"`` block of ``benchmarks/run_record.json`` (:mod:`benchmarks.record`); compared with
the figure before issue 33 (``benchmarks/run_baseline.json``). Install time is not included.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time

from benchmarks import record

#: pytest's arguments in ``make test`` (the Makefile's ``PYTEST_ARGS``).
COMMAND = ["-m", "pytest", "-q", "-n", "2", "--dist", "loadfile"]


def counts(summary: str) -> dict[str, int]:
    """``{"passed": n, "failed": n, ...}`` from pytest's last summary line."""
    return {k: int(n) for n, k in re.findall(r"(\d+) (\w+)", summary)}


def main() -> None:
    block = record.machine()
    start = time.perf_counter()
    out = subprocess.run(
        [sys.executable, *COMMAND], cwd=record.ROOT, capture_output=True, text=True, check=False
    )
    seconds = time.perf_counter() - start
    lines = [ln for ln in out.stdout.splitlines() if ln.strip()]
    summary = lines[-1].strip("= ") if lines else ""
    block |= {
        "command": "python " + " ".join(COMMAND),
        "seconds": round(seconds, 1),
        "exit_status": out.returncode,
        "summary": summary,
        **counts(summary),
        "load_average_end": round(os.getloadavg()[0], 2),
    }
    base = json.loads(record.BASELINE.read_text()).get("tests", {})
    print(
        f"make test: {seconds / 60:.1f} min ({summary}); before issue 33: "
        f"{base.get('seconds', 0) / 60:.0f} min; load average {block['load_average']} -> "
        f"{block['load_average_end']} on {block['cpus']} cores"
        + (" (loaded: an upper bound)" if record.loaded(block) else "")
    )
    if out.returncode != 0:
        print(out.stdout[-3000:])
        sys.exit(f"error: the test suite failed (exit status {out.returncode}); nothing stored")
    print(f"  stored: {record.write_block('tests', block)}")
