"""Install time of ``make run`` / ``make test`` from a fresh clone (the Makefile's install step).

Clones this repository's committed ``HEAD`` into a temporary folder and runs the Makefile's
install target there, as the first ``make run`` or ``make test`` does before anything else
(``make .venv/.installed``: ``python -m venv .venv``, pip upgraded,
``pip install -e ".[test]"``), with pip's cache off (``PIP_NO_CACHE_DIR=1``: every wheel is
downloaded, as on a fresh machine). Stores the wall time, the Python, the packages
installed and the machine's load as the ``"install"`` block of ``benchmarks/run_record.json``
(:mod:`benchmarks.record`); :mod:`benchmarks.readme_block` adds it to the README's figures
(``make run`` from a fresh clone = install + the default run).

The download speed is the network's: the figure is this machine's, stated with its date.
``FLATCONTACT_BENCH_PYTHON`` names the interpreter that makes the venv (default: the one
behind this process's venv, as ``make``'s ``python3`` would be).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from benchmarks import record

#: The Makefile's install target (its ``STAMP``).
TARGET = ".venv/.installed"


def base_python() -> str:
    """The interpreter that makes the clone's venv."""
    return os.environ.get("FLATCONTACT_BENCH_PYTHON") or getattr(
        sys, "_base_executable", sys.executable
    )


def main() -> None:
    python = base_python()
    block = record.machine()
    version = subprocess.run(
        [python, "-c", "import sys; print(sys.version.split()[0])"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.strip()
    with tempfile.TemporaryDirectory() as tmp:
        clone = Path(tmp) / "flatcontact"
        subprocess.run(["git", "clone", "--quiet", str(record.ROOT), str(clone)], check=True)
        env = {**os.environ, "PIP_NO_CACHE_DIR": "1", "PIP_DISABLE_PIP_VERSION_CHECK": "1"}
        for name in ("VIRTUAL_ENV", "PYTHONPATH"):  # the clone's venv, nothing of this one
            env.pop(name, None)
        start = time.perf_counter()
        out = subprocess.run(
            ["make", "-C", str(clone), TARGET, f"PYTHON={python}"],
            capture_output=True,
            text=True,
            env=env,
            check=False,
        )
        seconds = time.perf_counter() - start
        if out.returncode != 0:
            print(out.stdout[-2000:], out.stderr[-3000:])
            sys.exit(f"error: the install failed (exit status {out.returncode}); nothing stored")
        frozen = subprocess.run(
            [str(clone / ".venv" / "bin" / "python"), "-m", "pip", "list", "--format=freeze"],
            capture_output=True,
            text=True,
            check=True,
        ).stdout.split()
        venv_bytes = sum(
            p.stat().st_size
            for p in (clone / ".venv").rglob("*")
            if p.is_file() and not p.is_symlink()
        )
    block |= {
        "command": f"make {TARGET} (pip cache off)",
        "seconds": round(seconds, 1),
        "python": version,
        "packages": len(frozen),
        "venv_bytes": venv_bytes,
        "load_average_end": round(os.getloadavg()[0], 2),
    }
    print(
        f"install from a fresh clone: {seconds:.0f} s ({block['packages']} packages, "
        f"{venv_bytes / 1e6:.0f} MB venv, Python {version}, pip cache off); load average "
        f"{block['load_average']} -> {block['load_average_end']} on {block['cpus']} cores"
    )
    print(f"  stored: {record.write_block('install', block)}")
