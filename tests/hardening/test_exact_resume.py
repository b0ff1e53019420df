"""A scan killed with ``kill -9`` and resumed gives the numbers of an uninterrupted one, bit for bit.

Every point's warm start comes from a fixed neighbour (:mod:`flatcontact.ispes.order`), and
every relaxation starts the LAMMPS engine afresh (:meth:`LammpsEngine.restart`), so a point's
numbers are a function of the grid alone: not of the order the points finished in, of the
worker that relaxed them, or of what that worker's engine computed before (issue 34: after a
resume the noise estimates moved in their 11th digit). The scans are real ``flatcontact
scan`` processes on the Cu(111) EAM interface (LAMMPS), ``normal`` relaxation, so the
symmetry reduction is on; the kill is a real SIGKILL of the process group mid-scan.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from tests.hardening.helpers import kill_9_when, stored_rows

from flatcontact.ispes.geometry import thickness
from flatcontact.ispes.relax import PointTask, RelaxSettings, relax_point
from flatcontact.potentials.calculator import LammpsInterfaceCalculator
from flatcontact.potentials.model import InteractionModel
from flatcontact.structures.construct import build_interface
from flatcontact.structures.interface_io import write_interface

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux only")

STRUCTURE = {"kind": "fcc111", "element": "Cu", "a_angstrom": 3.615, "layers": 4}
#: attributes of ispes.nc that count this invocation's work, not the results
WORK_ATTRS = {"seconds", "points_computed", "force_calls_computed"}


@pytest.fixture(scope="module")
def cu_interface(tmp_path_factory):
    atoms, _ = build_interface(STRUCTURE)
    path = tmp_path_factory.mktemp("cu") / "interface.extxyz"
    write_interface(atoms, path)
    return atoms, path


def _config(folder: Path, scan: str) -> Path:
    path = folder / "scan.yaml"
    path.write_text(
        "structure: {kind: fcc111, element: Cu, a_angstrom: 3.615, layers: 4}\n"
        "potential: {preset: cu-eam}\n"
        f"scan:\n  relax_mode: normal\n  executor: serial\n{scan}"
    )
    return path


def _argv(config: Path, interface: Path, out: Path, *extra: str) -> list[str]:
    return ["scan", str(config), "--interface", str(interface), "--out", str(out), *extra]


def _scan(argv: list[str]) -> None:
    """``flatcontact argv`` in a process of its own."""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run(
        [sys.executable, "-m", "flatcontact", *argv], env=env, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr


def _scan_here(argv: list[str]) -> None:
    """``flatcontact argv`` in this process: its calculator is this process's cached one
    (:func:`flatcontact.ispes.relax.worker_calculator`), with whatever it computed before."""
    from flatcontact.cli import main

    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code in (0, None)


def _identical(a: Path, b: Path) -> None:
    """Every variable, coordinate and result attribute of two ``ispes.nc`` files, bit for bit."""
    with (
        xr.open_dataset(a / "ispes.nc", engine="h5netcdf") as da,
        xr.open_dataset(b / "ispes.nc", engine="h5netcdf") as db,
    ):
        assert set(da.variables) == set(db.variables)
        for name in da.variables:
            x, y = da[name].values, db[name].values
            assert x.dtype == y.dtype and x.shape == y.shape, name
            if x.dtype.kind == "f":
                assert np.array_equal(x, y, equal_nan=True), (name, np.nanmax(np.abs(x - y)))
            else:
                assert np.array_equal(x, y), name
        assert da.attrs.keys() == db.attrs.keys()
        for key in da.attrs.keys() - WORK_ATTRS:
            assert np.array_equal(np.asarray(da.attrs[key]), np.asarray(db.attrs[key])), key


def test_a_point_does_not_depend_on_what_the_engine_computed_before(cu_interface):
    """The same task on a fresh engine and on one that relaxed two other points first (at
    other thicknesses and stackings: other neighbour lists, other images) gives the same
    bits, for the built-in L-BFGS and for ASE's FIRE."""
    ref, _ = cu_interface
    z0 = thickness(ref)
    model = InteractionModel(preset="cu-eam")
    task = PointTask((0, 0, 0), 1 / 6, 1 / 3, z0 - 0.15)
    for settings in (RelaxSettings(0.005, mode="normal"), RelaxSettings(0.005, optimizer="FIRE")):
        fresh = relax_point(ref, LammpsInterfaceCalculator(model, ref), task, settings)
        used = LammpsInterfaceCalculator(model, ref)
        for other in (PointTask((1, 0, 0), 0.5, 0.0, z0 + 0.3), PointTask((2, 0, 0), 0.0, 0.5, z0)):
            relax_point(ref, used, other, settings)
        again = relax_point(ref, used, task, settings)
        assert again.energy_ev == fresh.energy_ev
        assert again.normal_stress_gpa == fresh.normal_stress_gpa
        assert np.array_equal(again.positions, fresh.positions)


def test_kill_9_mid_grid_then_resume_equals_an_uninterrupted_scan(cu_interface, tmp_path):
    """A small grid of given thicknesses: killed after a few stored points, resumed (the
    uninterrupted scan and the resume in this process, one after the other: the resume's
    engine has relaxed the whole grid before)."""
    ref, interface = cu_interface
    z0 = thickness(ref)
    zs = ", ".join(f"{z0 + d:.4f}" for d in (-0.3, -0.15, 0.0, 0.15, 0.3, 0.5))
    config = _config(tmp_path, f"  grid: [6, 6]\n  thickness_angstrom: [{zs}]\n")
    whole, resumed = tmp_path / "whole", tmp_path / "resumed"
    _scan_here(_argv(config, interface, whole))
    kill_9_when(_argv(config, interface, resumed), lambda: stored_rows(resumed / "points.db") >= 6)
    _scan_here(_argv(config, interface, resumed))
    _identical(whole, resumed)


@pytest.mark.slow
def test_kill_9_in_the_probe_and_in_the_grid_and_two_workers_equal_one_serial_scan(
    cu_interface, tmp_path
):
    """A pressure-range grid (probe, extension rounds, symmetry reduction): a scan killed in
    its probe, one killed in its grid (each resumed) and a 2-worker scan all equal the
    uninterrupted serial scan, bit for bit."""
    _, interface = cu_interface
    config = _config(tmp_path, "  grid: [6, 6]\n  p_range_gpa: {lo_gpa: 0.0, hi_gpa: 2.0, n: 4}\n")
    whole = tmp_path / "whole"
    _scan(_argv(config, interface, whole))
    in_probe, in_grid = tmp_path / "in_probe", tmp_path / "in_grid"
    kill_9_when(_argv(config, interface, in_probe), lambda: (in_probe / "probe.json").exists())
    kill_9_when(_argv(config, interface, in_grid), lambda: stored_rows(in_grid / "points.db") >= 20)
    for out in (in_probe, in_grid):
        _scan(_argv(config, interface, out))
        _identical(whole, out)
    two = tmp_path / "two"
    _scan(_argv(config, interface, two, "--executor", "processes", "--workers", "2"))
    _identical(whole, two)
