"""Every point of a scan relaxes with the driver's reference Hessian, whichever process relaxes
it (:mod:`flatcontact.ispes.shared_hessian`; Cu(111) EAM interface, LAMMPS).

The driver's floor fraction of the Hessian's eigenvalues is changed in these tests
(``precondition.FLOOR_FRACTION``, 0.01 → 0.02): a root computed anywhere else (a worker
process starts with the module's own 0.01) gives other iterates, so scans on other executors
equal the serial one bit for bit only if every process used the driver's bits. The Hessian's
force calls are counted where they are spent (each task reports its process's): exactly one
computation per scan, in the driver.
"""

from __future__ import annotations

import json
import sys

import pytest
from tests.hardening.test_exact_resume import STRUCTURE, _identical

from flatcontact.ispes import precondition
from flatcontact.ispes.executors import DaskExecutor, ProcessExecutor, SerialExecutor
from flatcontact.ispes.geometry import fixed_mask, thickness
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.relax import RelaxSettings
from flatcontact.ispes.scan import ScanInterrupted, run_scan
from flatcontact.ispes.shared_hessian import FILE_PREFIX, shared_key
from flatcontact.potentials.engines import calculator_factory
from flatcontact.potentials.model import InteractionModel
from flatcontact.structures.construct import build_interface

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux only")

FACTORY = calculator_factory(InteractionModel(preset="cu-eam"))
SETTINGS = RelaxSettings(0.005, "LBFGS", precondition=True)
PROBED = GridSpec(3, 3, p_range_gpa=(-0.5, 2.0, 4))


@pytest.fixture(scope="module")
def cu_reference():
    atoms, _ = build_interface(STRUCTURE)
    return atoms


@pytest.fixture(autouse=True)
def _driver_floor(monkeypatch):
    """The driver's root differs from one a fresh process would compute."""
    monkeypatch.setattr(precondition, "FLOOR_FRACTION", 0.02)


def _scan(ref, grid, out, executor, **kw):
    precondition._CACHE.clear()  # as in a new driver process
    precondition._RECEIVED.clear()
    try:
        return run_scan(ref, FACTORY, grid, out, SETTINGS, executor=executor, **kw)
    finally:
        executor.close()


def _hessian_calls(ref) -> int:
    return 2 * 3 * int((~fixed_mask(ref)).sum())


def _probe_units(out) -> dict:
    """``probe.json``'s units, a stretching keyed without the load it starts from (the driver
    keys it by the compression's first load, the workers' chains by None: the same unit)."""
    units = json.loads((out / "probe.json").read_text())["units"]
    keyed = {}
    for key, value in units.items():
        parts = json.loads(key)
        if parts[0] == "stretch":
            parts[3] = None
        keyed[json.dumps(parts)] = value
    return keyed


def _left_behind(out) -> list:
    return sorted(p.name for p in out.iterdir() if p.name.startswith("."))


def test_two_worker_processes_relax_with_the_drivers_bits(cu_reference, tmp_path):
    """The probe's chains, the ideal work of separation and the grid on two worker processes:
    the same ``ispes.nc`` and probe units (energies, loads, force calls) as the serial scan, one
    Hessian, in the driver; a stale file under this run's own name (a kill -9 of an earlier run
    with other bits) is not trusted, and the folder keeps no hidden file."""
    ref = cu_reference
    serial, processes = tmp_path / "serial", tmp_path / "processes"
    one = _scan(ref, PROBED, serial, SerialExecutor())
    processes.mkdir()
    key = shared_key(ref, FACTORY, "full")
    stale = processes / f"{FILE_PREFIX}{key[:16]}.npy"
    stale.write_bytes((serial / "ispes.nc").read_bytes()[:4096])
    two = _scan(ref, PROBED, processes, ProcessExecutor(2))
    assert one.hessian_force_calls == two.hessian_force_calls == _hessian_calls(ref)
    assert two.points_computed == one.points_computed > 50
    _identical(serial, processes)
    assert _probe_units(serial) == _probe_units(processes)
    assert _left_behind(serial) == _left_behind(processes) == []


def test_an_interrupted_two_worker_scan_resumes_to_the_serial_bits(cu_reference, tmp_path):
    """Ctrl-C after 10 stored points on two worker processes leaves no hidden file; the
    resumed scan (a new driver: its own Hessian, the same bits) equals the serial one."""
    ref = cu_reference
    z0 = thickness(ref)
    grid = GridSpec(4, 4, thickness_angstrom=(z0 - 0.2, z0, z0 + 0.3))
    whole, resumed = tmp_path / "whole", tmp_path / "resumed"
    _scan(ref, grid, whole, SerialExecutor())

    def stop(done, total):
        if done >= 10:
            raise KeyboardInterrupt

    with pytest.raises(ScanInterrupted):
        _scan(ref, grid, resumed, ProcessExecutor(2), progress=stop)
    assert _left_behind(resumed) == []
    again = _scan(ref, grid, resumed, ProcessExecutor(2))
    assert again.hessian_force_calls == _hessian_calls(ref)
    assert 0 < again.points_computed < 48
    _identical(whole, resumed)


@pytest.mark.slow
def test_dask_workers_relax_with_the_drivers_bits(cu_reference, tmp_path):
    """A local Dask cluster of two worker processes (the root reaches them by a worker plugin,
    as on another machine): the serial scan's bits, one Hessian, no file written."""
    ref = cu_reference
    serial, dask = tmp_path / "serial", tmp_path / "dask"
    _scan(ref, PROBED, serial, SerialExecutor())
    result = _scan(ref, PROBED, dask, DaskExecutor.local(2))
    assert result.hessian_force_calls == _hessian_calls(ref)
    _identical(serial, dask)
    assert _probe_units(serial) == _probe_units(dask)
    assert _left_behind(dask) == []
