"""Run the benchmarks: ``python -m benchmarks [NAME ...]``.

Every module ``benchmarks/bench_<name>.py`` defines ``main() -> None`` that
prints its measurements (seconds, counts and ratios). With names, only those
run (``python -m benchmarks contact``).
"""

import importlib
import pkgutil
import sys
from pathlib import Path


def main(argv: list[str]) -> None:
    here = Path(__file__).parent
    names = sorted(
        m.name[len("bench_") :]
        for m in pkgutil.iter_modules([str(here)])
        if m.name.startswith("bench_")
    )
    wanted = argv or names
    unknown = sorted(set(wanted) - set(names))
    if unknown:
        sys.exit(f"error: unknown benchmark(s) {unknown}; available: {names}")
    for name in wanted:
        print(f"== benchmark: {name} ==", flush=True)
        importlib.import_module(f"benchmarks.bench_{name}").main()


if __name__ == "__main__":
    main(sys.argv[1:])
