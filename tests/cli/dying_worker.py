"""The toy calculator, killed in a pool worker after a few force calls (``kill -9`` of itself:
what the kernel's out-of-memory killer does), unless ``FLATCONTACT_TEST_KEEP_WORKERS`` is set.

A module of its own so that spawned workers import it by name (the repository root on the
path)."""

import multiprocessing
import os
import signal

from flatcontact.ispes.toy import toy_calculator

#: force calls a worker makes before it dies
CALLS_BEFORE_DEATH = 12


def dying_toy(atoms):
    calc = toy_calculator(atoms)
    in_worker = multiprocessing.current_process().name.startswith("flatcontact-worker")
    if not in_worker or os.environ.get("FLATCONTACT_TEST_KEEP_WORKERS"):
        return calc
    inner, calls = calc.calculate, [0]

    def calculate(*args, **kwargs):
        calls[0] += 1
        if calls[0] > CALLS_BEFORE_DEATH:
            os.kill(os.getpid(), signal.SIGKILL)
        return inner(*args, **kwargs)

    calc.calculate = calculate
    return calc
