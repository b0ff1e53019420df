"""The README's run and test figures are the stored benchmark record's (issue 33), and the
benchmark times what ``make test`` runs."""

from __future__ import annotations

import json
import re

import pytest
from benchmarks import bench_tests, readme_block, record

ROOT = record.ROOT


def _block(name: str, file: str = "README.md") -> str:
    found = readme_block.marker(name).search((ROOT / file).read_text())
    assert found, f"{file} has no benchmark:{name} block"
    return found.group(2)


def test_readme_blocks_are_rendered_from_the_stored_record():
    """Each block is its record's rendering; a block whose record is not stored yet is empty
    (no typed-in figure)."""
    doc = json.loads(record.RECORD.read_text())
    assert "run" in doc
    for name, file in (
        ("run", "README.md"),
        ("tests", "README.md"),
        ("run-cell", "docs/run.md"),
        ("install", "README.md"),
    ):
        source = readme_block.SOURCE[name]
        want = readme_block.RENDER[name](doc[source]) if source in doc else ""
        assert _block(name, file) == want, name
    assert readme_block.main(["--check"]) == 0


def test_the_record_states_its_machine_and_the_run_its_stages():
    doc = json.loads(record.RECORD.read_text())
    for block in doc.values():
        assert block["cpus"] >= 1 and block["load_average"] >= 0 and block["measured_on"]
    run = doc["run"]
    assert run["preset"] == "quick"
    # the total covers the stages that ran (plus the pipeline's own bookkeeping)
    assert sum(run["stages_s"].values()) <= run["total_s"]
    # the second pass computed nothing
    assert set(run["rerun_actions"]) <= {"skipped", "off"}
    assert run["report_bytes"] < run["run_dir_bytes"]
    # issue 33's bounds on the default run: a directory a user can keep
    assert run["run_dir_bytes"] <= 10_000_000 and run["report_bytes"] <= 2_000_000
    if "tests" in doc:
        assert doc["tests"]["exit_status"] == 0 and doc["tests"]["passed"] > 0
    if "install" in doc:
        assert doc["install"]["seconds"] > 0 and doc["install"]["packages"] > 0


def _made_up_record() -> dict:
    machine = {"measured_on": "2030-01-02 03:04 UTC", "commit": "abc1234", "cpus": 2}
    return {
        "run": machine
        | {
            "load_average": 0.3,
            "load_average_end": 0.4,
            "total_s": 58.04,
            "stages_s": {"build": 2.34, "scan": 41.0, "contact": 7.5},
            "run_dir_bytes": 9_400_000,
            "report_bytes": 1_250_000,
        },
        "tests": machine | {"load_average": 9.0, "seconds": 540.0, "passed": 1600},
        "install": machine | {"load_average": 0.2, "seconds": 151.4, "packages": 87},
    }


def test_rendering_carries_the_records_numbers_and_its_load():
    doc = _made_up_record()
    run = readme_block.render_run(doc["run"])
    assert run.startswith("58 s on 2 cores")
    assert "build 2.3 s, scan 41 s, contact 7.5 s" in run
    assert "9.4 MB" in run and "1.2 MB report.html" in run
    assert "quiet machine" in run and "abc1234" in run
    tests = readme_block.render_tests(doc["tests"])
    assert tests.startswith("9 min for 1600 tests")
    assert "load average 9 on 2 cores): an upper bound" in tests
    install = readme_block.render_install(doc["install"])
    assert install.startswith("3 min (151 s) for the venv") and "87 packages" in install


def test_rewrite_replaces_only_the_blocks_and_is_idempotent():
    doc = _made_up_record()
    text = (
        "before <!-- benchmark:run -->60 s typed in<!-- /benchmark:run --> middle "
        "<!-- benchmark:tests -->old<!-- /benchmark:tests --> after"
    )
    once = readme_block.rewrite(text, doc)
    assert once.startswith("before <!-- benchmark:run -->58 s")
    assert " middle <!-- benchmark:tests -->9 min" in once and once.endswith(" after")
    assert "typed in" not in once and "old" not in once
    assert readme_block.rewrite(once, doc) == once
    # a block without a record is left as it is
    assert readme_block.rewrite(text, {"tests": doc["tests"]}).startswith(
        "before <!-- benchmark:run -->60 s typed in"
    )


def test_the_benchmark_times_the_makefiles_pytest_command():
    makefile = (ROOT / "Makefile").read_text()
    args = re.search(r"^PYTEST_ARGS \?= (.*)$", makefile, re.M).group(1).split()
    assert re.search(r"^\t\$\(BIN\)/python -m pytest -q \$\(PYTEST_ARGS\)$", makefile, re.M)
    assert bench_tests.COMMAND == ["-m", "pytest", "-q", *args]


@pytest.mark.parametrize(
    "summary, want",
    [
        ("1595 passed, 12 deselected in 601.2s", {"passed": 1595, "deselected": 12}),
        ("3 failed, 10 passed, 1 skipped in 2.0s", {"failed": 3, "passed": 10, "skipped": 1}),
    ],
)
def test_summary_counts(summary, want):
    got = bench_tests.counts(summary)
    assert {k: got[k] for k in want} == want
