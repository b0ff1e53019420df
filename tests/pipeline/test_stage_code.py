"""Stage fingerprints hold the code each stage runs: its stage module's import closure.

Edits are made in a copy of the source tree (``root=``), never in the installed package.
"""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from flatcontact.foundation.codegraph import SOURCE_ROOT, closure_digest, import_closure
from flatcontact.pipeline import (
    FIGURE_MODULES,
    PUBLIC_API_MODULE,
    STAGE_MODULES,
    STAGES,
    stage_code,
    stage_code_digest,
)


@pytest.fixture(scope="module")
def source_copy(tmp_path_factory):
    """A copy of the installed flatcontact source (the folder holding the package)."""
    root = tmp_path_factory.mktemp("src")
    shutil.copytree(
        SOURCE_ROOT / "flatcontact",
        root / "flatcontact",
        ignore=shutil.ignore_patterns("__pycache__", "*.pyc"),
    )
    return root


def _file(root, module):
    path = root / module.replace(".", "/")
    return path / "__init__.py" if path.is_dir() else path.with_suffix(".py")


def _edited(root, module, change):
    """The digest of ``change()`` with ``module``'s file edited (a comment appended)."""
    path = _file(root, module)
    original = path.read_bytes()
    path.write_bytes(original + b"\n# edited\n")
    try:
        return change()
    finally:
        path.write_bytes(original)


def test_the_copy_has_the_installed_digests(source_copy):
    for name in STAGES:
        assert stage_code_digest(name, source_copy) == stage_code_digest(name), name
        assert stage_code(name, source_copy) == stage_code(name), name


def test_the_closures_hold_the_modules_the_hand_lists_missed():
    assert "flatcontact.analysis.uncertainty" in stage_code("contact")
    assert "flatcontact.potentials.teachers" in stage_code("elastic")
    assert "flatcontact.ispes.contract" in stage_code("analyze")
    # imported inside a function (the laws stage fits the other energy form the analyze
    # stage stored)
    assert "flatcontact.analysis.energy_forms" in stage_code("laws")
    # the parent packages' __init__ run on import
    assert "flatcontact.ispes" in stage_code("scan")


@pytest.mark.parametrize("name", list(STAGES))
def test_an_edit_of_any_module_in_a_stage_closure_changes_its_digest(source_copy, name):
    before = stage_code_digest(name, source_copy)
    modules = stage_code(name, source_copy)
    assert f"flatcontact.stages.{name}" in modules
    for module in sorted(modules):
        after = _edited(source_copy, module, lambda: stage_code_digest(name, source_copy))
        assert after != before, f"{name}: editing {module} leaves its digest unchanged"
    assert stage_code_digest(name, source_copy) == before  # restored


def test_an_edit_outside_a_stage_closure_leaves_its_digest(source_copy):
    before = stage_code_digest("contact", source_copy)
    assert "flatcontact.ispes.relax" not in stage_code("contact")
    edited = _edited(
        source_copy, "flatcontact.ispes.relax", lambda: stage_code_digest("contact", source_copy)
    )
    assert edited == before


def test_shipped_package_data_is_in_the_digest(source_copy):
    """The reference slab shipped in structures/data/ is code the build runs."""
    data = source_copy / "flatcontact" / "structures" / "data"
    shipped = sorted(p for p in data.iterdir() if p.is_file())[0]
    before = stage_code_digest("build", source_copy)
    original = shipped.read_bytes()
    shipped.write_bytes(original + b"\n")
    try:
        assert stage_code_digest("build", source_copy) != before
    finally:
        shipped.write_bytes(original)


@pytest.mark.parametrize(
    ("stage", "figures"),
    [("scan", "flatcontact.plots.scan"), ("build", "flatcontact.plots.structures")],
)
def test_a_figure_edit_does_not_rerun_an_expensive_stage(source_copy, stage, figures):
    assert figures in import_closure(STAGE_MODULES[stage])  # the stage does draw it
    assert not any(m.startswith(FIGURE_MODULES) for m in stage_code(stage))
    before = stage_code_digest(stage, source_copy)
    for module in (figures, FIGURE_MODULES):
        edited = _edited(source_copy, module, lambda: stage_code_digest(stage, source_copy))
        assert edited == before, module


def test_a_figure_edit_reruns_a_cheap_stage(source_copy):
    before = stage_code_digest("analyze", source_copy)
    edited = _edited(
        source_copy, "flatcontact.plots.analysis", lambda: stage_code_digest("analyze", source_copy)
    )
    assert edited != before


def test_an_edit_of_the_public_api_map_reruns_no_stage(source_copy):
    """The top-level ``__init__`` (version + lazy names) is in every closure but no digest."""
    assert all(PUBLIC_API_MODULE in import_closure(STAGE_MODULES[n]) for n in STAGES)
    before = {n: stage_code_digest(n, source_copy) for n in STAGES}
    after = _edited(
        source_copy,
        PUBLIC_API_MODULE,
        lambda: {n: stage_code_digest(n, source_copy) for n in STAGES},
    )
    assert after == before


def test_closure_digest_is_a_digest_of_a_set():
    ispes = import_closure("flatcontact.ispes.scan")
    assert closure_digest(ispes) == closure_digest(sorted(ispes, reverse=True))
    assert closure_digest(ispes) == closure_digest([*ispes, "flatcontact.ispes.scan"])
    assert closure_digest(ispes) != closure_digest(import_closure("flatcontact.analysis.laws"))
    with pytest.raises(ValueError, match="not a module"):
        import_closure("flatcontact.no_such_module")


_LOADED = """
import importlib, json, sys
import flatcontact
importlib.import_module(sys.argv[1])
print(json.dumps({"file": flatcontact.__file__,
                  "loaded": sorted(m for m in sys.modules if m.split(".")[0] == "flatcontact")}))
"""


@pytest.mark.parametrize("name", list(STAGES))
def test_every_module_an_import_loads_is_in_the_static_closure(name):
    """Importing stages/<stage>.py in a fresh interpreter loads only modules of its closure."""
    out = subprocess.run(
        [sys.executable, "-c", _LOADED, STAGE_MODULES[name]],
        capture_output=True,
        text=True,
        check=True,
        timeout=300,
    )
    seen = json.loads(out.stdout.strip().splitlines()[-1])
    assert Path(seen["file"]).resolve() == SOURCE_ROOT / "flatcontact" / "__init__.py"
    missing = set(seen["loaded"]) - import_closure(STAGE_MODULES[name])
    assert not missing, f"{name}: loaded but not in the static closure: {sorted(missing)}"
