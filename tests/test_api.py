"""The public API: the names a notebook user guesses, loaded lazily, each the real object."""

from __future__ import annotations

import importlib
import subprocess
import sys

import pytest

import flatcontact

#: The names docs/architecture.md and the README teach, with the module that defines each.
TAUGHT = {
    "load_config": "flatcontact.config.load",
    "build_config": "flatcontact.config.load",
    "RunConfig": "flatcontact.config.run",
    "Pipeline": "flatcontact.pipeline",
    "InputError": "flatcontact.foundation.errors",
    "InteractionModel": "flatcontact.potentials.model",
    "make_calculator": "flatcontact.potentials.engines",
    "calculator_factory": "flatcontact.potentials.engines",
    "read_interface": "flatcontact.structures.interface_io",
    "build_interface": "flatcontact.structures.construct",
    "run_scan": "flatcontact.ispes.scan",
    "GridSpec": "flatcontact.ispes.grid",
    "open_ispes": "flatcontact.ispes.contract",
    "analyze_ispes": "flatcontact.analysis.analyze",
    "AnalysisOptions": "flatcontact.analysis.options",
    "fit_load_laws": "flatcontact.analysis.laws",
    "ContactParameters": "flatcontact.contact.parameters",
    "solve_hertz": "flatcontact.contact.hertz",
    "lateral_force": "flatcontact.contact.mindlin",
}

PACKAGES = [
    "flatcontact",
    "flatcontact.config",
    "flatcontact.potentials",
    "flatcontact.structures",
    "flatcontact.ispes",
    "flatcontact.analysis",
    "flatcontact.contact",
    "flatcontact.stages",
    "flatcontact.report",
    "flatcontact.training",
    "flatcontact.plots",
]


@pytest.mark.parametrize("name, module", sorted(TAUGHT.items()))
def test_each_taught_name_is_the_object_of_its_defining_module(name, module):
    assert name in flatcontact.__all__
    assert getattr(flatcontact, name) is getattr(importlib.import_module(module), name)


@pytest.mark.parametrize("package", PACKAGES)
def test_every_exported_name_resolves(package):
    mod = importlib.import_module(package)
    assert mod.__all__, package
    for name in mod.__all__:
        assert getattr(mod, name) is not None, f"{package}.{name}"
    assert set(mod.__all__) <= set(dir(mod))


def test_the_top_level_scan_is_the_core_and_the_stage_door_has_its_own_name():
    """``flatcontact.run_scan`` is the ISPES core; every stage door is ``<stage>_stage``, so no
    stage door shares a name (and a different signature) with a public function."""
    from flatcontact import stages
    from flatcontact.foundation.layout import STAGES
    from flatcontact.ispes import scan as ispes_scan
    from flatcontact.stages import scan as stage_scan

    assert flatcontact.run_scan is ispes_scan.run_scan
    assert stages.scan_stage is stage_scan.scan_stage
    doors = {name for name in stages.__all__ if name.endswith("_stage")}
    assert doors == {f"{stage}_stage" for stage in STAGES}
    assert not doors & set(flatcontact.__all__)
    assert not any(name.startswith("run_") for name in stages.__all__)


def test_an_unknown_name_is_an_attribute_error():
    with pytest.raises(AttributeError):
        flatcontact.no_such_name  # noqa: B018


def test_importing_the_package_loads_no_numpy():
    """``import flatcontact`` stays cheap, so ``flatcontact.cli`` sets OPENBLAS_NUM_THREADS before
    numpy is first imported (one BLAS thread per scan worker)."""
    code = (
        "import sys, flatcontact; "
        "heavy = sorted(m for m in ('numpy', 'ase', 'xarray', 'lammps') if m in sys.modules); "
        "print(','.join(heavy))"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    ).stdout.strip()
    assert out == ""
