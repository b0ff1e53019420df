"""The start-up window of the ``flatcontact`` command: how long after the process starts a
SIGTERM still kills it silently (status -15, no line).

``python -m benchmarks startup`` (about 10 s). For each of :data:`RUNS` fresh interpreters it
takes the time from just before the parent starts the child (``time.monotonic``, a clock the
whole machine shares) to three moments in the child:

- ``interpreter``: the child's first statement (Python's own start-up, ``site``);
- ``handler``: :func:`flatcontact.__main__.main`'s start-up SIGTERM handler installed (the
  entry module imported; what the console script does first). Before this moment a SIGTERM
  ends the process with status -15 and no line; after it, with the one line and 143;
- ``command line``: :mod:`flatcontact.cli` imported (typer, rich, numpy, the settings: where
  the command line's own handler takes over; the whole window before the start-up handler).

Prints the median and the largest of each, in milliseconds. On a machine shared with other
work the figures are upper bounds.
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

#: Fresh interpreters per moment.
RUNS = 15

_SRC = str(Path(__file__).resolve().parents[1] / "src")

_PROGRAMS = {
    "interpreter": "import time; print(time.monotonic())",
    "handler": (
        "import time, signal; from flatcontact.__main__ import exit_on_sigterm; "
        "exit_on_sigterm(); t = time.monotonic(); "
        "assert signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL; print(t)"
    ),
    "command line": "import time; import flatcontact.cli; print(time.monotonic())",
}


def _elapsed_ms(program: str) -> float:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([_SRC, os.environ.get("PYTHONPATH", "")])}
    start = time.monotonic()
    done = subprocess.run(
        [sys.executable, "-c", program], capture_output=True, text=True, env=env, check=True
    )
    return (float(done.stdout.strip().splitlines()[-1]) - start) * 1e3


def measure(runs: int = RUNS) -> dict[str, list[float]]:
    """Milliseconds from the parent's start of the child to each moment, ``runs`` times."""
    return {name: [_elapsed_ms(p) for _ in range(runs)] for name, p in _PROGRAMS.items()}


def main() -> None:
    for name, values in measure().items():
        print(
            f"{name:>13}: median {statistics.median(values):7.1f} ms, "
            f"largest {max(values):7.1f} ms ({len(values)} runs)"
        )


if __name__ == "__main__":
    main()
