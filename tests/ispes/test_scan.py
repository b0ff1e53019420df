"""The scan driver on the toy interface: store, resume after kill -9, executors, orders, errors."""

import os
import signal
import sqlite3
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest

from flatcontact.foundation.errors import InputError
from flatcontact.ispes.contract import open_ispes
from flatcontact.ispes.executors import DaskExecutor, ProcessExecutor, SerialExecutor
from flatcontact.ispes.geometry import thickness
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.relax import RelaxSettings
from flatcontact.ispes.scan import run_scan

SETTINGS = RelaxSettings(fmax_ev_per_angstrom=1e-4, optimizer="FIRE")


def _grid(ref, n=2):
    z0 = thickness(ref)
    return GridSpec(n, n, thickness_angstrom=(z0 - 0.25, z0 + 0.3))


def _values(ds):
    return ds.energy.values, ds.normal_stress.values


def test_scan_writes_a_contract_grid_and_a_rerun_computes_nothing(
    tmp_path, toy_reference, toy_factory
):
    r = run_scan(
        toy_reference,
        toy_factory,
        _grid(toy_reference),
        tmp_path,
        SETTINGS,
        executor=SerialExecutor(),
    )
    assert r.points_done == r.points_computed == r.points_total == 8
    ds = open_ispes(tmp_path / "ispes.nc")
    assert ds.converged.all() and np.isfinite(ds.energy).all()
    assert (ds.force_calls > 0).all()
    # compressed thickness loads, stretched thickness pulls, at every stacking
    assert (ds.normal_stress.isel(thickness=0) > 0).all() and (
        ds.normal_stress.isel(thickness=1) < 0
    ).all()
    again = run_scan(
        toy_reference,
        toy_factory,
        _grid(toy_reference),
        tmp_path,
        SETTINGS,
        executor=SerialExecutor(),
    )
    assert again.points_computed == 0
    np.testing.assert_array_equal(_values(again.dataset)[0], _values(ds)[0])


def test_store_with_other_settings_is_refused(tmp_path, toy_reference, toy_factory):
    run_scan(
        toy_reference,
        toy_factory,
        GridSpec(1, 1, thickness_angstrom=(thickness(toy_reference),)),
        tmp_path,
        SETTINGS,
        executor=SerialExecutor(),
    )
    other = RelaxSettings(fmax_ev_per_angstrom=1e-3, optimizer="FIRE")
    with pytest.raises(
        InputError, match=r"relax\.fmax_ev_per_a: 0\.0001 in the store vs 0\.001 now"
    ) as err:
        run_scan(
            toy_reference,
            toy_factory,
            GridSpec(1, 1, thickness_angstrom=(thickness(toy_reference),)),
            tmp_path,
            other,
            executor=SerialExecutor(),
        )
    assert "\n" not in str(err.value)
    with pytest.raises(InputError, match=r"grid\.n_a"):
        run_scan(
            toy_reference,
            toy_factory,
            GridSpec(2, 1, thickness_angstrom=(thickness(toy_reference),)),
            tmp_path,
            SETTINGS,
            executor=SerialExecutor(),
        )


@pytest.mark.parametrize("thicknesses", ["given", "probed"])
def test_executors_give_the_same_grid(tmp_path, toy_reference, toy_factory, thicknesses):
    """Serial, local processes and Dask give the same grid; with a pressure range the probed
    columns run on the workers of the last two (same thicknesses to round-off)."""
    grid = _grid(toy_reference)
    if thicknesses == "probed":
        grid = GridSpec(3, 3, p_range_gpa=(-0.05, 0.5, 4))
    serial = run_scan(
        toy_reference, toy_factory, grid, tmp_path / "s", SETTINGS, executor=SerialExecutor()
    )
    pool = ProcessExecutor(2)
    try:
        procs = run_scan(toy_reference, toy_factory, grid, tmp_path / "p", SETTINGS, executor=pool)
    finally:
        pool.close()
    dask = DaskExecutor.local(2)
    try:
        dsk = run_scan(toy_reference, toy_factory, grid, tmp_path / "d", SETTINGS, executor=dask)
    finally:
        dask.close()
    for other in (procs, dsk):
        np.testing.assert_allclose(
            other.dataset.thickness.values, serial.dataset.thickness.values, rtol=0, atol=1e-12
        )
        for a, b in zip(_values(serial.dataset), _values(other.dataset), strict=True):
            np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)
        # the probe's columns (two chains each on the workers) and the ideal work of
        # separation (a worker's chain beside them) are the serial driver's
        assert other.adhesion.keys() == serial.adhesion.keys()
        for key, value in serial.adhesion.items():
            if isinstance(value, float):
                assert other.adhesion[key] == pytest.approx(value, rel=1e-12, abs=1e-12), key
            else:
                assert other.adhesion[key] == value, key


def test_warm_start_orders_agree_within_tolerance(tmp_path, toy_reference, toy_factory):
    z0 = thickness(toy_reference)
    grid = GridSpec(3, 3, thickness_angstrom=tuple(z0 + np.linspace(-0.15, 0.15, 4)))
    settings = RelaxSettings(fmax_ev_per_angstrom=1e-4, optimizer="LBFGS")
    runs = {
        o: run_scan(
            toy_reference,
            toy_factory,
            grid,
            tmp_path / o,
            settings,
            order=o,
            executor=SerialExecutor(),
        )
        for o in ("columns", "planes", "cold")
    }
    e_ref, p_ref = _values(runs["cold"].dataset)
    # fmax = 1e-4 eV/Å bounds the energy error to ~fmax^2/k per atom and the load to ~fmax/A per atom
    for o in ("columns", "planes"):
        e, p = _values(runs[o].dataset)
        np.testing.assert_allclose(e, e_ref, atol=1e-6)
        np.testing.assert_allclose(p, p_ref, atol=5e-3)
    assert np.median(runs["columns"].force_calls_computed) < np.median(
        runs["cold"].force_calls_computed
    )


KILLED_RUN = textwrap.dedent(
    """
    import sys
    from flatcontact.potentials.engines import calculator_factory
    from flatcontact.potentials.model import InteractionModel
    from flatcontact.ispes.executors import SerialExecutor
    from flatcontact.ispes.geometry import thickness
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.relax import RelaxSettings
    from flatcontact.ispes.scan import run_scan
    from flatcontact.structures.toy import toy_interface

    ref = toy_interface(layers=3)
    z0 = thickness(ref)
    toy = InteractionModel(calculator={"target": "flatcontact.ispes.toy:toy_calculator"})
    run_scan(ref, calculator_factory(toy),
             GridSpec(6, 6, thickness_angstrom=(z0 - 0.25, z0 + 0.3)), sys.argv[1],
             RelaxSettings(fmax_ev_per_angstrom=1e-4, optimizer="FIRE"), executor=SerialExecutor())
    """
)


def _rows(db):
    if not db.exists():
        return 0
    try:
        with sqlite3.connect(f"file:{db}?mode=ro", uri=True, timeout=1) as con:
            return con.execute("select count(*) from systems").fetchone()[0]
    except sqlite3.OperationalError:
        return 0


def test_resume_after_kill_9_gives_the_uninterrupted_grid(tmp_path, toy_reference, toy_factory):
    out = tmp_path / "killed"
    proc = subprocess.Popen(
        [sys.executable, "-c", KILLED_RUN, str(out)],
        # every point committed as stored: the rows read below show where the scan is
        env={**os.environ, "OMP_NUM_THREADS": "1", "FLATCONTACT_COMMIT_INTERVAL_S": "0"},
    )
    deadline = time.monotonic() + 120
    while _rows(out / "points.db") < 4 and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.02)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    before = _rows(out / "points.db")
    assert 4 <= before < 72, "the run was not killed mid-scan"
    z0 = thickness(toy_reference)
    grid = GridSpec(6, 6, thickness_angstrom=(z0 - 0.25, z0 + 0.3))
    resumed = run_scan(toy_reference, toy_factory, grid, out, SETTINGS, executor=SerialExecutor())
    assert resumed.points_computed == 72 - before
    whole = run_scan(
        toy_reference, toy_factory, grid, tmp_path / "whole", SETTINGS, executor=SerialExecutor()
    )
    for a, b in zip(_values(resumed.dataset), _values(whole.dataset), strict=True):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12)


def test_bad_input_fails_before_any_work(tmp_path, toy_reference, toy_factory):
    z0 = thickness(toy_reference)
    with pytest.raises(InputError, match="overlap"):
        run_scan(
            toy_reference,
            toy_factory,
            GridSpec(2, 2, thickness_angstrom=(z0 - 2.5,)),
            tmp_path / "o",
            SETTINGS,
            executor=SerialExecutor(),
        )
    assert not (tmp_path / "o").exists()
    broken = toy_reference.copy()
    del broken.arrays["surface"]
    with pytest.raises(InputError, match="surface"):
        run_scan(
            broken,
            toy_factory,
            _grid(toy_reference),
            tmp_path / "b",
            SETTINGS,
            executor=SerialExecutor(),
        )
    with pytest.raises(InputError, match="order"):
        run_scan(
            toy_reference,
            toy_factory,
            _grid(toy_reference),
            tmp_path / "b",
            SETTINGS,
            order="spiral",
            executor=SerialExecutor(),
        )
    with pytest.raises(InputError, match="no Dask scheduler reachable"):
        DaskExecutor(address="tcp://127.0.0.1:9", timeout_s=2)
    with pytest.raises(InputError, match="optimizer"):
        RelaxSettings(optimizer="Newton")


def test_stale_lock_file_of_a_killed_writer_does_not_block_a_rerun(
    tmp_path, toy_reference, toy_factory
):
    grid = GridSpec(1, 1, thickness_angstrom=(thickness(toy_reference),))
    first = run_scan(
        toy_reference, toy_factory, grid, tmp_path, SETTINGS, executor=SerialExecutor()
    )
    # what a writer killed inside ASE's locked section leaves behind
    (tmp_path / "points.db.lock").write_text("")
    (tmp_path / "points.db.driver").write_text("")
    again = run_scan(
        toy_reference, toy_factory, grid, tmp_path, SETTINGS, executor=SerialExecutor()
    )
    assert again.points_computed == 0 and again.points_done == first.points_done


def test_a_second_driver_on_the_same_store_is_refused(tmp_path, toy_reference, toy_factory):
    from flatcontact.foundation.layout import POINTS_DB
    from flatcontact.ispes.scan import scan_settings
    from flatcontact.ispes.store import PointStore

    grid = GridSpec(1, 1, thickness_angstrom=(thickness(toy_reference),))
    settings = scan_settings(toy_reference, toy_factory, grid, SETTINGS)
    with PointStore(tmp_path / POINTS_DB, settings, toy_reference):
        with pytest.raises(InputError, match="another flatcontact scan is writing") as err:
            run_scan(
                toy_reference, toy_factory, grid, tmp_path, SETTINGS, executor=SerialExecutor()
            )
        assert "\n" not in str(err.value)
    # released with the first driver: the scan now runs
    done = run_scan(toy_reference, toy_factory, grid, tmp_path, SETTINGS, executor=SerialExecutor())
    assert done.points_done == 1


def test_jobqueue_cluster_from_config_builds_the_batch_job():
    """A SLURM cluster from the config's ``scan.jobqueue`` dict (no job submitted: jobs = 0)."""
    pytest.importorskip("dask_jobqueue")
    from flatcontact.ispes.executors import jobqueue_cluster

    spec = {
        "kind": "slurm",
        "jobs": 0,
        "cores": 4,
        "memory": "8GB",
        "processes": 1,
        "queue": "short",
        "walltime": "02:00:00",
    }
    cluster = jobqueue_cluster(spec)
    try:
        script = cluster.job_script()
    finally:
        cluster.close()
    for line in ("#SBATCH -p short", "#SBATCH --cpus-per-task=4", "#SBATCH -t 02:00:00"):
        assert line in script
    with pytest.raises(InputError, match=r"jobqueue\.kind: expected one of slurm"):
        jobqueue_cluster({"kind": "cloud"})
    with pytest.raises(InputError, match="cannot build a SLURMCluster"):
        jobqueue_cluster({"kind": "slurm", "jobs": 0, "cores": 1, "memory": "1GB", "bogus": 1})


class _LateResults(SerialExecutor):
    """Tasks run on submission; each result is handed over ``delay_s`` after the driver starts
    waiting for it (simulated: a wait whose time limit is shorter sees nothing finished)."""

    inline = False

    def __init__(self, delay_s: float):
        self.delay_s = delay_s
        self.timed_out = []  # (timeout, uncommitted points at that moment)
        self.waits = 0

    def wait_first(self, handles, timeout=None):
        handles = list(handles)
        if timeout is not None and timeout < self.delay_s:
            self.timed_out.append((timeout, self.store.uncommitted))
            return set(), set(handles)
        self.waits += 1
        return {handles[0]}, set(handles[1:])


@pytest.mark.parametrize("delay_s", [1e-3, 10.0])
def test_points_stored_are_committed_when_due_also_while_the_driver_waits(
    tmp_path, toy_reference, toy_factory, monkeypatch, delay_s
):
    """The driver waits for a result at most until the stored points are due
    (COMMIT_INTERVAL_S after the last commit), commits them then and waits on: with results
    slower than that every point is committed before the next wait goes on; with fast results
    the points that arrive within the interval share a commit instead of one commit each."""
    from flatcontact.ispes import store as store_module

    commits = []
    original = store_module.PointStore._commit

    def counted(self):
        commits.append(self._uncommitted)
        original(self)

    monkeypatch.setattr(store_module.PointStore, "_commit", counted)
    late = _LateResults(delay_s)
    opened = store_module.PointStore.__init__

    def remember(self, *args, **kwargs):
        opened(self, *args, **kwargs)
        late.store = self

    monkeypatch.setattr(store_module.PointStore, "__init__", remember)
    z0 = thickness(toy_reference)
    grid = GridSpec(3, 3, thickness_angstrom=(z0 - 0.2, z0))
    run_scan(toy_reference, toy_factory, grid, tmp_path / "s", SETTINGS, executor=late)
    assert late.waits == 18  # every point's result came out of a wait
    assert sum(commits) == 18  # every point committed once
    assert all(0 <= t <= 0.5 and n > 0 for t, n in late.timed_out)  # only with points due
    if delay_s > 0.5:  # each wait outlasts the deadline: a commit before each goes on
        assert len(late.timed_out) == 17 and max(commits) == 1
    else:  # the results arrive in time: commits only when due, far fewer than points
        assert len([n for n in commits if n]) < 6


@pytest.mark.parametrize(
    ("raw", "expected"),
    [(None, 0.5), ("", 0.5), ("0", 0.0), ("2.5", 2.5), ("-1", None), ("x", None)],
)
def test_the_commit_interval_comes_from_the_environment_or_is_one_line(raw, expected, monkeypatch):
    from flatcontact.ispes.scan_scheduler import COMMIT_INTERVAL_ENV, commit_interval_s

    if raw is None:
        monkeypatch.delenv(COMMIT_INTERVAL_ENV, raising=False)
    else:
        monkeypatch.setenv(COMMIT_INTERVAL_ENV, raw)
    if expected is None:
        with pytest.raises(InputError, match=COMMIT_INTERVAL_ENV):
            commit_interval_s()
    else:
        assert commit_interval_s() == expected
