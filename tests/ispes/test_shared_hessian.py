"""The reference Hessian's root, computed once by the scan's driver and handed to the processes
(:mod:`flatcontact.ispes.shared_hessian`): the bits that travel are the driver's, checked on
arrival, never recomputed, never left behind (toy interface: no LAMMPS)."""

from __future__ import annotations

import numpy as np
import pytest

from flatcontact.ispes import precondition
from flatcontact.ispes.executors import SerialExecutor
from flatcontact.ispes.geometry import fixed_mask, thickness
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.relax import (
    RelaxSettings,
    constraint_projector,
    context_calculator,
    reference_root,
    worker_calculator,
)
from flatcontact.ispes.scan import ScanInterrupted, run_scan
from flatcontact.ispes.shared_hessian import FILE_PREFIX, HessianSharing, shared_key

SETTINGS = RelaxSettings(1e-3, "LBFGS", precondition=True)


class _LocalProcesses:
    """What :class:`HessianSharing` sees of local worker processes: not inline, no Dask plugin."""

    inline = False
    workers = 2


class _Inline:
    inline = True
    workers = 1


@pytest.fixture(autouse=True)
def _fresh_process_state():
    """As in a new process: no root computed or received."""
    precondition._CACHE.clear()
    precondition._RECEIVED.clear()
    yield
    precondition._CACHE.clear()
    precondition._RECEIVED.clear()


def _relaxed_coordinates(reference) -> int:
    return 3 * int((~fixed_mask(reference)).sum())


def test_the_driver_computes_once_and_a_worker_reads_its_bits_from_the_file(
    tmp_path, toy_reference, toy_factory
):
    """Two force calls per relaxed coordinate, once; the file holds those bits, a process that
    has none in memory reads and checks them; the scan's end removes the file and a stale one."""
    stale = tmp_path / f"{FILE_PREFIX}0123456789abcdef.npy"  # a killed run's, another key
    with HessianSharing(tmp_path, toy_reference, toy_factory, SETTINGS) as sharing:
        stale.write_bytes(b"not a root")
        context = sharing.context(_LocalProcesses())
        assert sharing.context(_LocalProcesses()) is context  # once per scan
        assert sharing.hessian_force_calls == 2 * _relaxed_coordinates(toy_reference)
        shared = context.hessian
        driver_calc = worker_calculator(toy_factory, toy_reference)
        fixed = fixed_mask(toy_reference)
        driver_root = reference_root(
            toy_reference, driver_calc, fixed, "full", constraint_projector(fixed, "full", [])
        )
        assert shared.sha256 == precondition.root_sha256(driver_root)
        assert shared.key == shared_key(toy_reference, toy_factory, "full")
        assert shared.path.endswith(f"{FILE_PREFIX}{shared.key[:16]}.npy")
        assert not stale.exists()  # the driver writes its own, the folder holds no other
        precondition._RECEIVED.clear()  # a worker process: nothing in memory
        read = precondition.shared_root(shared)
        assert read is not driver_root and np.array_equal(read, driver_root)
        assert precondition.shared_root(shared) is read  # read once per process
        stale.write_bytes(b"left by a kill -9")
    assert not list(tmp_path.glob(f"{FILE_PREFIX}*"))


def test_a_file_that_is_not_the_drivers_is_refused(tmp_path, toy_reference, toy_factory):
    """Other bits under the file's name (a run killed with other settings, a changed file) or
    no file at all: the process fails its task, it does not compute a root of its own."""
    with HessianSharing(tmp_path, toy_reference, toy_factory, SETTINGS) as sharing:
        shared = sharing.context(_LocalProcesses()).hessian
        root = np.load(shared.path)
        np.save(shared.path, root * (1 + 1e-15))
        precondition._RECEIVED.clear()
        with pytest.raises(RuntimeError, match="not the driver's"):
            precondition.shared_root(shared)
        np.save(shared.path, np.eye(3))
        with pytest.raises(RuntimeError, match=r"holds a \(3, 3\) matrix"):
            precondition.shared_root(shared)
    with pytest.raises(RuntimeError, match="cannot read"):
        precondition.shared_root(shared)


def test_a_workers_calculator_takes_the_drivers_root_over_its_own(
    tmp_path, toy_reference, toy_factory
):
    """:func:`context_calculator` puts the driver's root in the worker calculator's cache, even
    over one that calculator computed before (another run's): :func:`reference_root` then
    computes nothing."""
    with HessianSharing(tmp_path, toy_reference, toy_factory, SETTINGS) as sharing:
        context = sharing.context(_LocalProcesses())
        precondition._CACHE.clear()
        precondition._RECEIVED.clear()
        calc = worker_calculator(toy_factory, toy_reference)
        key = precondition.root_key(toy_reference, fixed_mask(toy_reference), "full")
        precondition.cached_root(calc, key, lambda: np.eye(3 * len(toy_reference)))
        assert context_calculator(context) is calc
        fixed = fixed_mask(toy_reference)
        before = calc.force_calls
        root = reference_root(
            toy_reference, calc, fixed, "full", constraint_projector(fixed, "full", [])
        )
        assert calc.force_calls == before
        assert precondition.root_sha256(root) == context.hessian.sha256


def test_nothing_is_written_where_nothing_travels(tmp_path, toy_reference, toy_factory):
    """The serial executor's tasks run in the driver: no file. Settings without the
    preconditioner: no Hessian at all."""
    with HessianSharing(tmp_path, toy_reference, toy_factory, SETTINGS) as sharing:
        shared = sharing.context(_Inline()).hessian
        assert shared.path is None and not list(tmp_path.iterdir())
        assert precondition.shared_root(shared).shape == (shared.size, shared.size)
    plain = RelaxSettings(1e-3, "FIRE")
    with HessianSharing(tmp_path, toy_reference, toy_factory, plain) as sharing:
        assert sharing.context(_LocalProcesses()).hessian is None
        assert sharing.hessian_force_calls == 0
    assert not list(tmp_path.iterdir())


class _NotInline(SerialExecutor):
    """Runs each task at submission, but tells the scan it does not (as local processes do):
    the scan writes the file for it."""

    inline = False
    name = "not-inline"


@pytest.mark.parametrize("stop", [RuntimeError, KeyboardInterrupt])
def test_the_file_lives_while_the_scan_relaxes_and_goes_with_an_error_or_ctrl_c(
    tmp_path, toy_reference, toy_factory, stop
):
    """During the grid the folder holds one ``.reference-hessian-*.npy`` (the driver's root);
    an error or a Ctrl-C in the middle removes it, and the store keeps the points."""
    z0 = thickness(toy_reference)
    grid = GridSpec(3, 3, thickness_angstrom=(z0 - 0.1, z0, z0 + 0.2))
    seen = []

    def progress(done, total):
        seen.append(sorted(p.name for p in tmp_path.glob(f"{FILE_PREFIX}*")))
        if done >= 5:
            raise stop("stop here")

    with pytest.raises(ScanInterrupted if stop is KeyboardInterrupt else RuntimeError):
        run_scan(toy_reference, toy_factory, grid, tmp_path, SETTINGS, executor=_NotInline(),
                 progress=progress)  # fmt: skip
    key = shared_key(toy_reference, toy_factory, "full")
    assert seen[-1] == [f"{FILE_PREFIX}{key[:16]}.npy"]
    assert not [p.name for p in tmp_path.iterdir() if p.name.startswith(".")]
    assert (tmp_path / "points.db").exists()
