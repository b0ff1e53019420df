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
