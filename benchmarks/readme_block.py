"""The README's measured figures, rendered from the stored benchmark record.

``python -m benchmarks.readme_block`` rewrites each marked block of ``README.md`` and
``docs/run.md``
(``<!-- benchmark:NAME -->…<!-- /benchmark:NAME -->``) from ``benchmarks/run_record.json``
(written by ``python -m benchmarks run`` and ``python -m benchmarks tests``); nothing in the
blocks is typed by hand. ``--check`` exits 1 when a block differs from the record.
"""

from __future__ import annotations

import re
import sys

from benchmarks import record

README = record.ROOT / "README.md"
#: The files whose marked blocks are rewritten (the README; the presets table of docs/run.md).
FILES = (README, record.ROOT / "docs" / "run.md")
STAGE_ORDER = ("build", "scan", "analyze", "laws", "elastic", "contact", "report")


def _when(block: dict) -> str:
    load = (
        f"next to other work (load average {max(block['load_average'], block.get('load_average_end') or 0):.0f} "
        f"on {block['cpus']} cores): an upper bound"
        if record.loaded(block)
        else f"on a quiet machine ({block['cpus']} cores)"
    )
    return f"measured {block['measured_on'][:10]} at commit {block['commit']}, {load}"


def _seconds(s: float) -> str:
    return f"{s:.0f} s" if s >= 10 else f"{s:.1f} s"


def render_run(block: dict) -> str:
    """The default run's figures: total, per stage, run directory and report size."""
    stages = ", ".join(
        f"{name} {_seconds(block['stages_s'][name])}"
        for name in STAGE_ORDER
        if name in block["stages_s"]
    )
    return (
        f"{_seconds(block['total_s'])} on {block['cpus']} cores with the quick preset, after the "
        f"install ({stages}); a run directory of {block['run_dir_bytes'] / 1e6:.1f} MB with a "
        f"{block['report_bytes'] / 1e6:.1f} MB report.html; `python -m benchmarks run`, "
        f"{_when(block)}"
    )


def render_tests(block: dict) -> str:
    """The test suite's figures: wall time and counts."""
    return (
        f"{block['seconds'] / 60:.0f} min for {block.get('passed', 0)} tests with 2 workers, "
        f"install excluded; `python -m benchmarks tests`, {_when(block)}"
    )


def render_run_cell(block: dict) -> str:
    """The default run's wall time for a table cell (docs/run.md's presets table)."""
    scan = block["stages_s"].get("scan")
    return (
        f"{_seconds(block['total_s'])}"
        + (f" (scan {_seconds(scan)})" if scan is not None else "")
        + (", a loaded machine: upper bound" if record.loaded(block) else ", a quiet machine")
    )


def render_install(block: dict) -> str:
    """The install step of a fresh clone's first ``make run`` / ``make test``."""
    return (
        f"{block['seconds'] / 60:.0f} min ({block['seconds']:.0f} s) for the venv and "
        f'`pip install -e ".[test]"`, {block["packages"]} packages downloaded with pip\'s cache '
        f"off; `python -m benchmarks install`, {_when(block)}"
    )


RENDER = {
    "run": render_run,
    "tests": render_tests,
    "run-cell": render_run_cell,
    "install": render_install,
}
#: The record's block behind each rendered block.
SOURCE = {"run": "run", "tests": "tests", "run-cell": "run", "install": "install"}


def marker(name: str) -> re.Pattern:
    """The block ``name`` in the README (its opening and closing comments kept)."""
    return re.compile(rf"(<!-- benchmark:{name} -->)(.*?)(<!-- /benchmark:{name} -->)", re.S)


def rewrite(text: str, doc: dict) -> str:
    """``text`` with every marked block whose record exists rendered from ``doc``."""
    for name, render in RENDER.items():
        if SOURCE[name] in doc:
            body = render(doc[SOURCE[name]])
            text = marker(name).sub(lambda m, body=body: m.group(1) + body + m.group(3), text)
    return text


def main(argv: list[str]) -> int:
    doc, stale = record.read(), []
    for path in FILES:
        text = path.read_text()
        new = rewrite(text, doc)
        if new == text:
            continue
        if "--check" in argv:
            stale.append(path.relative_to(record.ROOT).as_posix())
        else:
            path.write_text(new)
            print(f"rewrote the benchmark blocks of {path.relative_to(record.ROOT)}")
    if stale:
        print(
            f"error: the benchmark blocks of {', '.join(stale)} differ from "
            "benchmarks/run_record.json; run python -m benchmarks.readme_block"
        )
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
