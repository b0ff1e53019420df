"""The documentation describes the product, not the machine it was measured on.

Prose pages (README, docs/*.md, examples/README.md) and the example configurations a user
copies name no absolute path of a developer's machine: a measurement names the command that
reproduces it and a folder relative to where it runs. Data records under ``docs/measured/``
(a study's ``study.json`` keeps the ``--out`` it was run with) are logs, not prose, and are
not checked here.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

#: Absolute paths that only exist on one machine: a home, a scratch or a work folder.
MACHINE_PATH = re.compile(r"(?<![\w.~-])/(?:work|tmp|root|home|Users|scratch|mnt)/[\w.-]")

PAGES = sorted(
    [
        ROOT / "README.md",
        ROOT / "examples" / "README.md",
        *(ROOT / "docs").glob("*.md"),
        *(ROOT / "examples").glob("*.yaml"),
    ]
)


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(ROOT)))
def test_page_names_no_path_of_a_machine(page: Path):
    hits = [
        f"{page.relative_to(ROOT)}:{n}: {line.strip()}"
        for n, line in enumerate(page.read_text(encoding="utf-8").splitlines(), 1)
        if MACHINE_PATH.search(line)
    ]
    assert not hits, "machine paths in the docs:\n" + "\n".join(hits)


def test_the_pattern_finds_machine_paths_and_spares_relative_ones():
    assert MACHINE_PATH.search("into `/work/quartz-study/models`")
    assert MACHINE_PATH.search("(`/tmp/q1`, `/tmp/q2`)")
    assert not MACHINE_PATH.search("runs/work/x and docs/measured/tmp/y")
    assert not MACHINE_PATH.search("see https://example.org/home/page")


def _python_blocks(text: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def test_the_api_reference_is_what_the_code_gives():
    """docs/api.md is generated from the docstrings (``python docs/gen_api.py``)."""
    from docs.gen_api import PAGE, render

    assert PAGE.read_text(encoding="utf-8") == render(), "rerun: python docs/gen_api.py"


def test_the_readme_python_example_is_the_tested_one():
    """The README's Python example is the API page's, whose code runs as the doctest of
    ``flatcontact.notebook`` (tests/test_notebook.py): the same lines, statement by statement."""
    import flatcontact.notebook

    readme = _python_blocks((ROOT / "README.md").read_text(encoding="utf-8"))[0]
    api = _python_blocks((ROOT / "docs" / "api.md").read_text(encoding="utf-8"))[0]
    assert readme == api
    doctest_lines = "\n".join(
        line[4:]
        for line in flatcontact.notebook.__doc__.splitlines()
        if line.startswith((">>> ", "... "))
    )
    squash = lambda s: re.sub(r"\s+", "", s.split("#")[0])  # noqa: E731
    for statement in readme.split("\n"):
        if statement.strip() and "=" in statement and not statement.startswith(" "):
            assert squash(statement) in re.sub(r"\s+", "", doctest_lines), statement
