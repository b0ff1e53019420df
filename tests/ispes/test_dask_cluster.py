"""The distributed route for real: a ``dask scheduler`` and a ``dask worker`` (two worker
processes) started as separate processes on localhost; one worker is killed with SIGKILL
in the middle of the scan, and the scan still completes with every point, equal to a
serial scan of the same grid (the warm-start tree makes the result independent of which
worker relaxed which point)."""

import json
import os
import shutil
import signal
import sqlite3
import subprocess
import sys
import threading
import time

import numpy as np
import psutil
import pytest

from flatcontact.ispes.executors import DaskExecutor, SerialExecutor
from flatcontact.ispes.geometry import thickness
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.relax import RelaxSettings
from flatcontact.ispes.scan import run_scan
from flatcontact.potentials.engines import calculator_factory
from flatcontact.potentials.model import InteractionModel

SETTINGS = RelaxSettings(fmax_ev_per_angstrom=1e-4, optimizer="FIRE")


def _rows(db):
    try:
        with sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=1) as con:
            return con.execute("select count(*) from systems").fetchone()[0]
    except sqlite3.OperationalError:
        return 0


def _wait_for(predicate, timeout_s: float, what: str):
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.1)
    raise AssertionError(f"timed out waiting for {what}")


@pytest.fixture
def cluster(tmp_path):
    """A scheduler and one `dask worker` with two single-threaded worker processes."""
    dask = shutil.which("dask", path=os.path.dirname(sys.executable)) or shutil.which("dask")
    if dask is None:
        pytest.skip("the dask command is not installed")
    # the workers import the slowed toy (tests.ispes.slow_toy) and flatcontact from this path
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    env["OMP_NUM_THREADS"] = "1"
    info = tmp_path / "scheduler.json"
    procs = []
    try:
        procs.append(
            subprocess.Popen(
                [
                    dask,
                    "scheduler",
                    "--host",
                    "127.0.0.1",
                    "--port",
                    "0",
                    "--no-dashboard",
                    "--scheduler-file",
                    str(info),
                ],
                env=env,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
        )
        _wait_for(info.exists, 60, "the scheduler file")
        address = _wait_for(
            lambda: json.loads(info.read_text() or "{}").get("address"), 30, "the scheduler address"
        )
        procs.append(
            subprocess.Popen(
                [
                    dask,
                    "worker",
                    address,
                    "--nworkers",
                    "2",
                    "--nthreads",
                    "1",
                    "--no-dashboard",
                    "--host",
                    "127.0.0.1",
                ],
                env=env,
                stdout=subprocess.DEVNULL,
                stderr=subprocess.DEVNULL,
            )
        )
        yield address, procs[1]
    finally:
        for proc in reversed(procs):
            for child in psutil.Process(proc.pid).children(recursive=True):
                child.kill()
            proc.kill()
            proc.wait()


def test_scan_on_a_separate_scheduler_survives_a_killed_worker(cluster, tmp_path, toy_reference):
    address, worker_cmd = cluster
    factory = calculator_factory(
        InteractionModel(calculator={"target": "tests.ispes.slow_toy:slow_toy"})
    )
    z0 = thickness(toy_reference)
    grid = GridSpec(3, 3, thickness_angstrom=(z0 - 0.2, z0, z0 + 0.3))
    total = grid.n_a * grid.n_b * len(grid.thickness_angstrom)

    executor = DaskExecutor(address=address, timeout_s=30)
    _wait_for(lambda: len(executor._client.scheduler_info()["workers"]) >= 2, 60, "two workers")
    assert executor.workers == 2
    out = tmp_path / "dask"
    result = {}

    def scan():
        result["scan"] = run_scan(toy_reference, factory, grid, out, SETTINGS, executor=executor)

    driver = threading.Thread(target=scan)
    driver.start()
    _wait_for(lambda: _rows(out / "points.db") >= 4, 120, "the first stored points")
    nanny_children = psutil.Process(worker_cmd.pid).children(recursive=True)
    # the worker processes are the nannies' children; kill one of them mid-scan
    victims = [p for p in nanny_children if p.children() == []]
    assert victims, "no worker process found"
    before = _rows(out / "points.db")
    os.kill(victims[0].pid, signal.SIGKILL)
    driver.join(timeout=300)
    executor.close()
    assert not driver.is_alive(), "the scan did not finish after a worker was killed"
    assert before < total, "the kill did not land in the middle of the scan"
    scanned = result["scan"].dataset
    assert bool(scanned["converged"].all()), "points were lost with the killed worker"
    assert _rows(out / "points.db") == total

    plain = calculator_factory(
        InteractionModel(calculator={"target": "flatcontact.ispes.toy:toy_calculator"})
    )
    serial = run_scan(
        toy_reference, plain, grid, tmp_path / "serial", SETTINGS, executor=SerialExecutor()
    )
    for name in ("energy", "normal_stress"):
        np.testing.assert_allclose(
            scanned[name].values, serial.dataset[name].values, rtol=0, atol=1e-10
        )


def test_separate_dask_workers_relax_with_the_drivers_reference_hessian(
    cluster, tmp_path, toy_reference, monkeypatch
):
    """With the preconditioner, the workers of a separate ``dask worker`` (processes the driver
    did not start, as on another machine) get the driver's root of the reference's Hessian
    through a worker plugin, also the worker the nanny starts after one is killed mid-scan:
    the scan equals the serial one bit for bit although the driver's eigenvalue floor differs
    from the one a worker would use (``precondition.FLOOR_FRACTION``, changed here only), and
    the Hessian's force calls are the driver's alone."""
    from flatcontact.ispes import precondition
    from flatcontact.ispes.geometry import fixed_mask

    monkeypatch.setattr(precondition, "FLOOR_FRACTION", 0.02)
    settings = RelaxSettings(fmax_ev_per_angstrom=1e-4, optimizer="LBFGS", precondition=True)
    address, worker_cmd = cluster
    z0 = thickness(toy_reference)
    grid = GridSpec(3, 3, thickness_angstrom=(z0 - 0.2, z0, z0 + 0.3))
    total = grid.n_a * grid.n_b * len(grid.thickness_angstrom)
    hessian_calls = 2 * 3 * int((~fixed_mask(toy_reference)).sum())
    slow = calculator_factory(
        InteractionModel(calculator={"target": "tests.ispes.slow_toy:slow_toy"})
    )
    executor = DaskExecutor(address=address, timeout_s=30)
    _wait_for(lambda: len(executor._client.scheduler_info()["workers"]) >= 2, 60, "two workers")
    out, result = tmp_path / "dask", {}

    def scan():
        precondition._CACHE.clear()
        result["scan"] = run_scan(toy_reference, slow, grid, out, settings, executor=executor)

    driver = threading.Thread(target=scan)
    driver.start()
    _wait_for(lambda: _rows(out / "points.db") >= 4, 120, "the first stored points")
    victims = [
        p for p in psutil.Process(worker_cmd.pid).children(recursive=True) if not p.children()
    ]
    before = _rows(out / "points.db")
    os.kill(victims[0].pid, signal.SIGKILL)
    driver.join(timeout=300)
    executor.close()
    assert not driver.is_alive() and before < total
    assert result["scan"].hessian_force_calls == hessian_calls
    assert not [p.name for p in out.iterdir() if p.name.startswith(".")]

    precondition._CACHE.clear()
    plain = calculator_factory(
        InteractionModel(calculator={"target": "flatcontact.ispes.toy:toy_calculator"})
    )
    serial = run_scan(
        toy_reference, plain, grid, tmp_path / "serial", settings, executor=SerialExecutor()
    )
    assert serial.hessian_force_calls == hessian_calls
    for name in ("energy", "normal_stress"):
        np.testing.assert_array_equal(
            result["scan"].dataset[name].values, serial.dataset[name].values
        )
