"""The scan's local worker pool (:mod:`flatcontact.ispes.worker_pool`): every task's outcome
comes back to its own handle, errors and crashes are named, nothing deadlocks on large
messages, and shutting down leaves no process."""

import concurrent.futures as cf
import multiprocessing
import pickle
import time

import numpy as np
import psutil
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from tests.ispes import pool_tasks

from flatcontact.ispes.worker_pool import BrokenProcessPool, RemoteTraceback, WorkerPool


@pytest.fixture(scope="module")
def pool():
    p = WorkerPool(2, multiprocessing.get_context("spawn"))
    yield p
    p.shutdown()


@settings(max_examples=15, deadline=None)
@given(st.lists(st.integers(-(10**6), 10**6), max_size=12))
def test_every_handle_gets_its_own_tasks_result(pool, values):
    """More tasks than workers, waited for in any order: each handle holds its own result."""
    handles = [pool.submit(pool_tasks.square, v) for v in values]
    for h, v in reversed(list(zip(handles, values, strict=True))):
        assert h.result() == v * v


def test_wait_returns_the_first_finished_and_honours_the_timeout(pool):
    slow = pool.submit(time.sleep, 1.0)
    t0 = time.perf_counter()
    done, not_done = pool.wait([slow], timeout=0.05)
    assert done == set() and not_done == {slow} and time.perf_counter() - t0 < 0.5
    fast = pool.submit(pool_tasks.square, 3)
    done, not_done = pool.wait([slow, fast])
    assert done == {fast} and not_done == {slow} and fast.result() == 9
    assert slow.result() is None and slow.done()


def test_a_tasks_error_is_raised_with_the_workers_traceback(pool):
    handle = pool.submit(pool_tasks.fail, "no such site")
    with pytest.raises(ValueError, match="no such site") as info:
        handle.result()
    assert isinstance(info.value.__cause__, RemoteTraceback)
    assert "pool_tasks.py" in str(info.value.__cause__)
    assert pool.submit(pool_tasks.square, 4).result() == 16  # the pool goes on


def test_what_cannot_be_pickled_fails_its_task_only(pool):
    with pytest.raises((pickle.PicklingError, AttributeError, TypeError)):
        pool.submit(pool_tasks.square, lambda: 1).result()
    with pytest.raises(RuntimeError, match="reply could not be sent"):
        pool.submit(pool_tasks.unpicklable_result).result()
    assert pool.submit(pool_tasks.square, 5).result() == 25


def test_large_tasks_and_results_both_ways_do_not_deadlock(pool):
    """Tasks and replies far larger than a pipe's buffer (64 KiB), more tasks than workers:
    a worker holds one task at a time, so neither end can block on the other."""
    arrays = [np.random.default_rng(k).normal(size=400_000) for k in range(6)]  # 3.2 MB each
    handles = [pool.submit(pool_tasks.echo_array, a, 100_000) for a in arrays]
    for h, a in zip(handles, arrays, strict=True):
        out = h.result(timeout=120)
        np.testing.assert_array_equal(out[: a.size], a)
        assert out.size == a.size + 100_000


def test_the_workers_are_started_with_the_initializer():
    import os

    from flatcontact.ispes.executors import _init_worker

    p = WorkerPool(2, multiprocessing.get_context("spawn"), _init_worker, (os.getpid(),))
    try:
        first = p.submit_to_each(pool_tasks.pid_and_nice)
        pids = {h.result()[0] for h in first}
        assert pids == set(p.pids) and len(pids) == 2  # one each
        assert {h.result()[1] for h in first} == {os.nice(0) + 3}
    finally:
        p.shutdown()


@pytest.mark.parametrize(
    "task, args, how",
    [(pool_tasks.die_by_signal, (), "SIGKILL"), (pool_tasks.die_with_code, (3,), "exit code 3")],
)
def test_a_worker_that_dies_breaks_the_pool_with_a_named_reason(task, args, how):
    """As ``concurrent.futures`` does: every unfinished task fails, the message names how the
    worker ended and what it ran, the other worker is stopped, later submissions fail."""
    p = WorkerPool(2, multiprocessing.get_context("spawn"))
    try:
        other = p.submit(time.sleep, 30)
        doomed = p.submit(task, *args)
        queued = p.submit(pool_tasks.square, 2)
        procs = [psutil.Process(pid) for pid in p.pids]
        with pytest.raises(BrokenProcessPool, match=f"{how}.*{task.__name__}"):
            doomed.result(timeout=60)
        for h in (other, queued):
            with pytest.raises(BrokenProcessPool, match=task.__name__):
                h.result(timeout=1)
        with pytest.raises(BrokenProcessPool):
            p.submit(pool_tasks.square, 3)
        _gone, alive = psutil.wait_procs(procs, timeout=10)
        assert not alive
    finally:
        p.shutdown(cancel=True)


def test_shutdown_waits_for_submitted_tasks_or_cancels_them():
    p = WorkerPool(2, multiprocessing.get_context("spawn"))
    handles = [p.submit(pool_tasks.square, k) for k in range(7)]
    p.shutdown()
    assert [h.result() for h in handles] == [k * k for k in range(7)]
    with pytest.raises(RuntimeError, match="shut down"):
        p.submit(pool_tasks.square, 1)

    p = WorkerPool(2, multiprocessing.get_context("spawn"))
    running = [p.submit(time.sleep, 600) for _ in range(2)]
    queued = p.submit(time.sleep, 600)
    p.wait(running, timeout=0.5)
    procs = [psutil.Process(pid) for pid in p.pids]
    t0 = time.perf_counter()
    p.shutdown(cancel=True)
    assert time.perf_counter() - t0 < 10
    assert queued.cancelled()
    for h in running:
        with pytest.raises((BrokenProcessPool, cf.CancelledError)):
            h.result(timeout=0)
    _gone, alive = psutil.wait_procs(procs, timeout=10)
    assert not alive


def test_serve_gives_a_finished_worker_its_next_task_without_waiting():
    """A driver busy with its own computation calls ``ProcessExecutor.serve`` between its
    steps: the result that is in is read and the queued task sent, so the worker does not
    idle until the driver's next wait. Tasks of a function not run before are never
    prefetched, so the second waits in the driver's queue until then."""
    from flatcontact.ispes.executors import ProcessExecutor

    executor = ProcessExecutor(1)
    try:
        first = executor.submit(pool_tasks.square, 4)
        second = executor.submit(time.sleep, 0.0)
        pool = executor._pool
        assert list(pool._queued) == [second]
        deadline = time.monotonic() + 60.0
        while not pool._workers[0].conn.poll(0) and time.monotonic() < deadline:
            time.sleep(0.01)  # the first result is in the pipe, nobody has read it
        assert not first.finished() and list(pool._queued) == [second]
        executor.serve()
        assert first.finished() and first.result() == 16
        assert not pool._queued and list(pool._workers[0].handles) == [second]
        assert second.result() is None
    finally:
        executor.close()


def test_one_short_run_does_not_let_a_long_task_wait_behind_another():
    """A task waits in a busy worker's pipe only when its function ran at least twice, each
    time briefly. After one short run of ``nap``, a long one (0.2 s) submitted while both
    workers are busy stays in the driver's queue and goes to the worker that frees first
    (the one on a 0.1 s nap), not behind the 0.4 s nap it would have been prefetched to."""
    p = WorkerPool(2, multiprocessing.get_context("spawn"))
    try:
        for handle in p.submit_to_each(pool_tasks.pid_and_nice):  # both workers started
            handle.result()
        first = p.submit(pool_tasks.nap, 0.005)
        first.result()  # one short run of nap: ``first``'s worker is free again
        long_a = p.submit(pool_tasks.nap, 0.4)
        short_b = p.submit(pool_tasks.nap, 0.1)
        late = p.submit(pool_tasks.nap, 0.2)
        assert late.result() == short_b.result() != long_a.result()
    finally:
        p.shutdown()
