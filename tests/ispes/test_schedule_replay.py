"""The schedule replay (benchmarks/schedule_replay.py) runs the scan's own driver: its
virtual clock, and a toy scan with many workers against the real executors.

A scan with many workers probes each column's compression in cold-started segments
(:class:`flatcontact.ispes.probe.CompressionSegments`); its grid equals the sequential
probe's to the force tolerance (the thicknesses move with the probe's loads).
"""

import numpy as np
import pytest
from benchmarks.schedule_replay import VirtualExecutor, task_key

from flatcontact.foundation.units import EV_PER_A3_TO_GPA
from flatcontact.ispes.executors import ProcessExecutor, SerialExecutor
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.relax import RelaxSettings
from flatcontact.ispes.scan import run_scan
from flatcontact.ispes.scan_probe import MANY_WORKERS

SETTINGS = RelaxSettings(fmax_ev_per_angstrom=1e-3)
#: HI high enough that the compression runs over several segments of 3 steps
GRID = GridSpec(3, 3, p_range_gpa=(-0.05, 3.0, 4))


def job(context, k):
    return k


def test_the_virtual_clock_is_a_fifo_pool_of_w_workers():
    """Two workers, costs 3, 1, 1, 2 s submitted at 0: the third starts when the second
    ends (1 s), the fourth when the third does (2 s); the driver's own time left out."""
    costs = {1: 3.0, 2: 1.0, 3: 1.0, 4: 2.0}
    cache = {("job", k): (k, None, c) for k, c in costs.items()}
    ex = VirtualExecutor(2, cache, driver_cpu=False)
    handles = [ex.submit(job, None, k) for k in costs]
    assert [(h.start, h.end) for h in handles] == [(0.0, 3.0), (0.0, 1.0), (1.0, 2.0), (2.0, 4.0)]
    done, rest = ex.wait_first(handles)
    assert [h.key for h in done] == [("job", 2)] and ex.clock == 1.0 and len(rest) == 3
    assert ex.result(handles[3]) == 4 and ex.clock == 4.0
    # a task not in the cache runs here, once, and its CPU time is its cost
    fresh = ex.submit(job, None, 5)
    assert ex.cache[("job", 5)][0] == 5 and fresh.start == 4.0


class Recording:
    """An executor that logs what the driver submits and receives, in order (an
    :class:`~flatcontact.ispes.executors.Executor` around ``inner``; no worker prestart)."""

    name = "recording"
    inline = False

    def __init__(self, inner):
        self.inner, self.workers, self.events, self.keys = inner, inner.workers, [], {}

    def submit(self, fn, *args):
        handle = self.inner.submit(fn, *args)
        self.keys[handle] = task_key(fn, args)
        self.events.append(("submit", self.keys[handle]))
        return handle

    def wait_first(self, handles, timeout=None):
        return self.inner.wait_first(handles, timeout)

    def done(self, handle):
        return self.inner.done(handle)

    def prestart(self, factory, reference):
        pass

    def result(self, handle):
        self.events.append(("result", self.keys[handle]))
        return self.inner.result(handle)

    def close(self, cancel=False):
        self.inner.close(cancel)


def _order_holds(events):
    """Every grid point is submitted after its warm-start parent's result, and after every
    probed column's stretching is in; returns the grid's (point, parent) edges."""
    received, edges = set(), set()
    first_point = next(i for i, (e, k) in enumerate(events) if k[0] == "run_task")
    stretched = [
        i for i, (e, k) in enumerate(events) if e == "result" and k[0] == "probe_chain_task"
    ]
    assert stretched and max(stretched) < first_point
    for event, key in events:
        if event == "result":
            received.add(key[:2])
        elif key[0] == "run_task":
            _, index, parent = key
            assert parent is None or ("run_task", parent) in received, key
            edges.add((index, parent))
    return edges


@pytest.mark.slow
def test_many_workers_replay_the_scans_order_and_grid(tmp_path, toy_reference, toy_factory):
    """A toy scan on 4 local processes (the many-worker probe) and its replay on 4 virtual
    workers: the same tasks in the same dependency order, the same ispes.nc to round-off."""
    assert MANY_WORKERS <= 4
    pool = Recording(ProcessExecutor(4))
    try:
        real = run_scan(toy_reference, toy_factory, GRID, tmp_path / "p", SETTINGS, executor=pool)
    finally:
        pool.close()
    virtual = VirtualExecutor(4, {})
    replayed = run_scan(
        toy_reference, toy_factory, GRID, tmp_path / "v", SETTINGS, executor=virtual
    )
    events = [(e, k) for e, k, *_ in virtual.log]
    assert _order_holds(pool.events) == _order_holds(events)
    kinds = {k[0] for _, k in events}
    assert {"rigid_rows_task", "probe_chain_task", "probe_segment_task"} <= kinds

    # the tasks other than the speculative segments are the same
    def fixed(evts):
        return sorted({k for e, k in evts if e == "submit" and k[0] != "probe_segment_task"})

    assert fixed(pool.events) == fixed(events)
    for name in ("thickness", "energy", "normal_stress"):
        np.testing.assert_allclose(
            replayed.dataset[name].values, real.dataset[name].values, rtol=0, atol=1e-12
        )
    assert replayed.adhesion == pytest.approx(real.adhesion)


def test_many_workers_give_the_sequential_grid_to_the_tolerance(
    tmp_path, toy_reference, toy_factory
):
    """The many-worker probe's cold-started segments move its loads, and the thicknesses
    with them (measured: 6e-4 Å); at the moved thickness the grid is the serial scan's to
    first order: U(z + dz) = U(z) - p A dz and p(z + dz) = p(z) + p'(z) dz, within the force
    tolerance (measured: 3e-7 eV, 1.7e-4 GPa against fmax/A = 0.023 GPa)."""
    serial = run_scan(
        toy_reference, toy_factory, GRID, tmp_path / "s", SETTINGS, executor=SerialExecutor()
    )
    virtual = VirtualExecutor(8, {}, driver_cpu=False)
    many = run_scan(toy_reference, toy_factory, GRID, tmp_path / "m", SETTINGS, executor=virtual)
    assert sum(1 for e, k, *_ in virtual.log if e == "submit" and k[0] == "probe_segment_task") > 2
    s, m = serial.dataset, many.dataset
    z = s.thickness.values
    dz = m.thickness.values - z
    assert 0 < np.abs(dz).max() < 0.01  # moved, by less than a tenth of the probe's step
    area = float(s.attrs["area"])
    p_s = s.normal_stress.values
    fmax_gpa = SETTINGS.fmax_ev_per_angstrom / area * EV_PER_A3_TO_GPA
    first_order_u = s.energy.values - p_s / EV_PER_A3_TO_GPA * area * dz
    np.testing.assert_allclose(m.energy.values, first_order_u, rtol=0, atol=1e-5)
    first_order_p = p_s + np.gradient(p_s, z, axis=-1) * dz
    np.testing.assert_allclose(m.normal_stress.values, first_order_p, rtol=0, atol=fmax_gpa)
    # the adhesion (the ideal work of separation ran beside the grid) is the serial one
    assert many.adhesion.keys() == serial.adhesion.keys()
    for key, value in serial.adhesion.items():
        if isinstance(value, str):  # where W is taken (work_of_separation_stacking)
            assert many.adhesion[key] == value, key
        elif key.startswith("work_of_separation"):
            assert many.adhesion[key] == pytest.approx(value, rel=1e-9, abs=1e-12), key
