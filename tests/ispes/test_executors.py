"""Local worker processes die with their driver: ``kill -9`` of the parent alone leaves nothing."""

import os
import signal
import subprocess
import sys
import textwrap

import psutil
import pytest

DRIVER = textwrap.dedent(
    """
    import os, sys, time
    from flatcontact.ispes.executors import ProcessExecutor

    pool = ProcessExecutor(2)
    pids = {pool.submit(os.getpid).result() for _ in range(8)}
    for _ in range(4):
        pool.submit(time.sleep, 600)   # workers busy, as in the middle of a scan
    print("ready", flush=True)
    time.sleep(600)
    """
)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="PR_SET_PDEATHSIG is Linux")
def test_workers_die_when_the_driver_is_killed():
    proc = subprocess.Popen(
        [sys.executable, "-c", DRIVER], stdout=subprocess.PIPE, text=True, env=dict(os.environ)
    )
    try:
        assert proc.stdout.readline().strip() == "ready"
        children = psutil.Process(proc.pid).children(recursive=True)
        workers = [c for c in children if c.is_running()]
        assert len(workers) >= 2, "the pool did not start its two workers"
        proc.send_signal(signal.SIGKILL)
        proc.wait()
        _gone, alive = psutil.wait_procs(workers, timeout=15)
        assert not alive, f"workers left behind after the driver died: {[p.pid for p in alive]}"
    finally:
        if proc.poll() is None:
            proc.kill()


SCAN_DRIVER = textwrap.dedent(
    """
    import os, sys
    from flatcontact.potentials.engines import calculator_factory
    from flatcontact.potentials.model import InteractionModel
    from flatcontact.ispes.grid import GridSpec
    from flatcontact.ispes.scan import run_scan
    from flatcontact.structures.interface_contract import thickness
    from flatcontact.structures.toy import toy_interface

    ref = toy_interface(layers=3)
    toy = InteractionModel(calculator={"target": "flatcontact.ispes.toy:toy_calculator"})
    factory = calculator_factory(toy)
    z = thickness(ref)
    r = run_scan(ref, factory, GridSpec(2, 2, thickness_angstrom=(z, z + 0.3)), sys.argv[1],
                 executor_options={"kind": "processes", "workers": 2})
    print("points", r.points_done, flush=True)
    """
)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="process groups: POSIX")
def test_a_two_worker_scan_leaves_no_process_behind(tmp_path):
    """The scan runs in its own session; once it has exited, nothing of that session is left
    (its workers, and the workers started early while it probes, all ended with it)."""
    proc = subprocess.Popen(
        [sys.executable, "-c", SCAN_DRIVER, str(tmp_path / "scan")],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=dict(os.environ),
        start_new_session=True,
    )
    out, err = proc.communicate(timeout=300)
    assert proc.returncode == 0, err
    assert out.split() == ["points", "8"]
    sid = proc.pid  # the session id of a process started as its session's leader

    def left():
        out = []
        for p in psutil.process_iter(["pid"]):
            try:
                if os.getsid(p.pid) == sid:
                    out.append(p)
            except (ProcessLookupError, PermissionError):
                pass
        return out

    _gone, alive = psutil.wait_procs(left(), timeout=10)
    assert not alive, f"processes left in the scan's session: {[p.pid for p in alive]}"


def test_the_three_executors_follow_the_executor_protocol():
    """The scan driver asks every executor the same things (:class:`Executor`), never probing
    with hasattr: the serial executor, the local pool and Dask all answer them. A serial
    submission runs at once (``inline``, ``done`` at once); the pool runs it on a worker."""
    import typing

    from flatcontact.ispes.executors import (
        DaskExecutor,
        Executor,
        ProcessExecutor,
        SerialExecutor,
        make_executor,
    )

    members = {
        name
        for name in vars(Executor)
        if not name.startswith("_") and name not in typing.Protocol.__dict__
    } | set(typing.get_type_hints(Executor))
    assert members >= {"name", "inline", "workers", "submit", "wait_first", "done", "result"}
    for cls in (SerialExecutor, ProcessExecutor, DaskExecutor):
        assert all(hasattr(cls, m) for m in members), (cls, members - set(dir(cls)))
    serial = make_executor("serial")
    assert isinstance(serial, Executor) and serial.inline and serial.workers == 1
    handle = serial.submit(pow, 2, 10)
    assert serial.done(handle) and serial.result(handle) == 1024
    serial.prestart(None, None)  # nothing to start
    pool = make_executor("processes", workers=2)
    try:
        assert isinstance(pool, Executor) and not pool.inline and pool.workers == 2
        handle = pool.submit(os.getpid)
        done, _ = pool.wait_first([handle])
        assert done == {handle} and pool.done(handle) and pool.result(handle) != os.getpid()
    finally:
        pool.close()
