"""What the local worker pool costs the driver per task (issue 33).

``python -m benchmarks pool``: one command, about 20 s. :class:`flatcontact.ispes.executors.
ProcessExecutor` with 2 workers runs ``N_TASKS`` tasks that do nothing (the pool's own cost)
and ``N_TASKS`` of a scan's size (a 5 KB argument, a 3 KB result, 2 ms of work in the worker),
kept ``IN_FLIGHT`` at a time as the scan's scheduler does: the driver's CPU microseconds per
task (``time.process_time``, its sending, reading and waiting), the tasks per second and
the worker processes' total CPU. Three repeats each; the median is the figure.

On a scan of small points this is what the driver takes from the cores its workers use
(0.23 ms per stored point on the 36-atom quartz cell, the store's writing included) and
what caps how many workers one driver can keep busy: a driver at X µs per task feeds at most
1/X tasks per second.
"""

from __future__ import annotations

import os
import statistics
import time

import numpy as np

N_TASKS = 3000
IN_FLIGHT = 4
REPEATS = 3


def empty(x):
    return x


def scan_sized(payload: bytes, seconds: float):
    """A task the size of a scan's point: busy ``seconds``, a 3 KB reply."""
    end = time.perf_counter() + seconds
    while time.perf_counter() < end:
        pass
    return np.zeros(384)


def children_cpu() -> float:
    r = os.times()
    return r.children_user + r.children_system


def run(executor, fn, args, n: int) -> tuple[float, float]:
    """(driver CPU µs per task, tasks per second) of ``n`` tasks, ``IN_FLIGHT`` at a time."""
    t0, c0 = time.perf_counter(), time.process_time()
    pending = {executor.submit(fn, *args) for _ in range(IN_FLIGHT)}
    sent = IN_FLIGHT
    while pending:
        done, pending = executor.wait_first(pending)
        for handle in done:
            executor.result(handle)
            if sent < n:
                pending.add(executor.submit(fn, *args))
                sent += 1
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    return 1e6 * cpu / n, n / wall


def main() -> None:
    from flatcontact.ispes.executors import ProcessExecutor

    print(f"== worker pool (issue 33), {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f} ==")
    payload = os.urandom(5000)
    cases = {
        "empty task": (empty, (1,)),
        "scan-sized task (5 KB in, 3 KB out, 2 ms)": (scan_sized, (payload, 0.002)),
    }
    for name, (fn, args) in cases.items():
        per_task, rate = [], []
        for _ in range(REPEATS):
            executor = ProcessExecutor(2)
            try:
                run(executor, fn, args, 50)  # the workers started and warm
                us, per_s = run(executor, fn, args, N_TASKS)
            finally:
                executor.close()
            per_task.append(us)
            rate.append(per_s)
        print(
            f"  {name}: driver {statistics.median(per_task):.1f} CPU µs per task "
            f"({', '.join(f'{x:.1f}' for x in per_task)}), "
            f"{statistics.median(rate):,.0f} tasks/s, {N_TASKS} tasks x {REPEATS}",
            flush=True,
        )
