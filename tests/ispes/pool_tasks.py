"""Tasks for the worker pool's tests, importable by name in a spawned worker
(``tests.ispes.pool_tasks``, with the repository root on the path)."""

import os
import signal

import numpy as np


def square(x):
    return x * x


def echo_array(arr: np.ndarray, extra: int) -> np.ndarray:
    """The array back, larger by ``extra`` values (a reply of another size than the task)."""
    return np.concatenate([arr, np.arange(extra, dtype=float)])


def fail(message: str):
    raise ValueError(message)


def unpicklable_result():
    return lambda: None


def die_by_signal():
    os.kill(os.getpid(), signal.SIGKILL)


def die_with_code(code: int):
    os._exit(code)


def pid_and_nice():
    return os.getpid(), os.nice(0)


def nap(seconds: float) -> int:
    """Sleep ``seconds``, then return this worker's pid."""
    import time

    time.sleep(seconds)
    return os.getpid()
