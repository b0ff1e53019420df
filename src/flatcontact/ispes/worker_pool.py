"""Local worker processes fed over one pipe each, with no thread in the driver.

:class:`WorkerPool` is what :class:`flatcontact.ispes.executors.ProcessExecutor` runs on.
``concurrent.futures.ProcessPoolExecutor`` moves every task through a shared call queue
written by a feeder thread and every result through a result queue read by a manager
thread: on a 2-worker quartz scan of 1,296 points of 2-3 force calls (≈ 9 ms each) those
two threads cost the driver 0.43 CPU s, on the same two cores the workers use
(docs/performance.md). Here the driver's own thread writes each task to its worker's pipe
and reads the results when it waits for them (:meth:`WorkerPool.wait`, or a handle's
``result()``): nothing runs in the driver between its calls.

Protocol
--------
A worker holds one task, or two when both are small and short: the driver sends a worker
that is computing a second task only if both tasks pickle to at most
:data:`SMALL_TASK_BYTES` (together far below a pipe's buffer, so the driver's write never
blocks) and both tasks' functions ran at least twice and their last runs
(:data:`PREFETCH_HISTORY`) all took less than :data:`PREFETCH_BELOW_S` (a long task never
waits behind another while a worker is free; one short run says little: the probe's first
chain, a stretching of 14 ms, had let the next compression of 140 ms wait behind another
while a worker was free). A worker with its next task in its pipe goes on without
sleeping between tasks; the driver reads a worker's results before it
gives that worker more, so neither side can block on a full pipe while the other blocks
too, whatever the size of a task or a result. The tasks no worker can take queue in the
driver (first in, first out) and go to the first worker that can, when its result is read.

Failures
--------
- A task's exception comes back and is raised by its handle's ``result()``, with the
  worker's traceback as its ``__cause__`` (:class:`RemoteTraceback`); a result or an
  exception that cannot be pickled is one ``RuntimeError`` naming the task.
- A worker that dies (a crash in a model's library, the kernel's OOM killer) breaks the
  pool as ``concurrent.futures`` does: every unfinished handle raises
  :class:`BrokenProcessPool` naming the task the worker ran and how it ended, the other
  workers are stopped, and a later ``submit`` raises it too.
- :meth:`WorkerPool.shutdown` with ``cancel=True`` (Ctrl-C, an error in the driver) drops
  the queued tasks and terminates the workers at once; without, it lets every submitted
  task finish first. Workers are daemonic: a driver that exits without shutting the pool
  down takes them with it, and the initializer may make them die with it even on
  ``kill -9`` (:func:`flatcontact.ispes.executors.die_with_parent`).
"""

from __future__ import annotations

import collections
import concurrent.futures as cf
import multiprocessing
import pickle
import signal
import time
import traceback
from collections.abc import Callable, Iterable
from concurrent.futures.process import BrokenProcessPool
from multiprocessing.connection import Connection, wait
from typing import Any

__all__ = ["BrokenProcessPool", "PoolHandle", "RemoteTraceback", "WorkerPool"]

#: seconds a worker gets to exit after the pool is shut down before it is killed
STOP_GRACE_S = 5.0
#: a task pickled to at most this many bytes may wait in a busy worker's pipe (two of them
#: stay far below the pipe's buffer, 64 KiB and more: the driver's write never blocks)
SMALL_TASK_BYTES = 16 * 1024
#: a task may wait behind another in a worker's pipe if the last runs of both tasks'
#: functions (at least two, at most :data:`PREFETCH_HISTORY`) each took less than this (s):
#: a scan's point (~10 ms) does, a study's or an asperity's job (minutes) never, nor
#: anything run fewer than two times
PREFETCH_BELOW_S = 0.05
#: how many of a function's last runs decide whether its tasks may wait in a pipe
PREFETCH_HISTORY = 4


class RemoteTraceback(Exception):
    """The traceback of an exception raised in a worker (its ``__cause__`` in the driver)."""

    def __init__(self, text: str):
        super().__init__(text)
        self.text = text

    def __str__(self) -> str:
        return self.text


def _task_name(fn: Any) -> str:
    return getattr(fn, "__qualname__", None) or getattr(fn, "__name__", None) or repr(fn)


def _worker_main(conn: Connection, initializer: Callable | None, initargs: tuple) -> None:
    """A worker's life: run each task the pipe brings, send back its outcome, until told to
    stop (``None``) or the driver's end closes."""
    if initializer is not None:
        initializer(*initargs)
    while True:
        try:
            message = conn.recv_bytes()
        except (EOFError, OSError):
            return
        try:
            task = pickle.loads(message)
            if task is None:
                return
            fn, args = task
            reply = (True, fn(*args), None)
        except BaseException as exc:  # the task's failure is the driver's to raise
            reply = (False, exc, traceback.format_exc())
        try:
            conn.send(reply)
        except Exception as exc:  # the value or the error cannot be pickled
            text = f"{type(exc).__name__}: {exc}"
            conn.send((False, RuntimeError(f"a worker's reply could not be sent: {text}"), None))


class PoolHandle(cf.Future):
    """A task's handle: a ``concurrent.futures.Future`` whose ``result()`` and ``done()``
    read the pool's pipes (no thread does it in the background)."""

    def __init__(self, pool: WorkerPool, fn: Callable, args: tuple):
        super().__init__()
        self._pool, self.fn, self.args = pool, fn, args
        #: the pickled task until it is sent, and its size in bytes
        self.data, self.size = b"", 0

    def done(self) -> bool:
        if not super().done():
            self._pool.poll(0.0)
        return super().done()

    def result(self, timeout: float | None = None) -> Any:
        self._pool.wait([self], timeout)
        return super().result(timeout=0)

    def exception(self, timeout: float | None = None) -> BaseException | None:
        self._pool.wait([self], timeout)
        return super().exception(timeout=0)

    def finished(self) -> bool:
        """Whether the outcome is in (without reading the pipes)."""
        return super().done()


class _Worker:
    """One worker process, its end of the pipe and the handles of the tasks sent to it
    (in the order it runs them)."""

    def __init__(self, process: Any, conn: Connection):
        self.process, self.conn = process, conn
        self.handles: collections.deque[PoolHandle] = collections.deque()
        #: when its current task started (or, prefetched, its previous one ended)
        self.since = 0.0


class WorkerPool:
    """``workers`` spawned processes, each fed over its own pipe by the driver's thread.

    Parameters
    ----------
    workers
        How many processes (started together at the first task).
    context
        The ``multiprocessing`` start method's context (``spawn`` for the scan).
    initializer, initargs
        Called in every worker before its first task.
    """

    def __init__(
        self,
        workers: int,
        context: Any = None,
        initializer: Callable | None = None,
        initargs: tuple = (),
    ):
        self.size = int(workers)
        self._context = context or multiprocessing.get_context("spawn")
        self._initializer, self._initargs = initializer, initargs
        self._workers: list[_Worker] = []
        self._queued: collections.deque[PoolHandle] = collections.deque()
        self._broken: str | None = None
        self._closed = False
        #: wall seconds of the last runs of each task function (by name)
        self._seconds: dict[str, collections.deque[float]] = {}

    # -- starting and feeding -----------------------------------------------------------
    def _start(self) -> None:
        for k in range(self.size):
            ours, theirs = self._context.Pipe(duplex=True)
            process = self._context.Process(
                target=_worker_main,
                args=(theirs, self._initializer, self._initargs),
                name=f"flatcontact-worker-{k + 1}",
                daemon=True,
            )
            process.start()
            theirs.close()  # only the worker holds it now: its death is our end's EOF
            self._workers.append(_Worker(process, ours))

    def submit(self, fn: Callable, *args: Any) -> PoolHandle:
        """Queue ``fn(*args)`` (pickled now); it starts at once if a worker is free."""
        if self._broken is not None:
            raise BrokenProcessPool(self._broken)
        if self._closed:
            raise RuntimeError("cannot submit a task to a worker pool that is shut down")
        if not self._workers:
            self._start()
        handle = PoolHandle(self, fn, args)
        try:
            handle.data = pickle.dumps((fn, args), protocol=pickle.HIGHEST_PROTOCOL)
            handle.size = len(handle.data)
        except Exception as exc:  # fails this task only
            handle.set_running_or_notify_cancel()
            handle.set_exception(exc)
            return handle
        idle = [w for w in self._workers if not w.handles]
        ready = idle or [w for w in self._workers if self._can_take(w, handle)]
        if ready and not self._queued:
            self._send(ready[0], handle)
        else:
            self._queued.append(handle)
        return handle

    def submit_to_each(self, fn: Callable, *args: Any) -> list[PoolHandle]:
        """``fn(*args)`` once on every worker (each free worker takes one now)."""
        return [self.submit(fn, *args) for _ in range(self.size)]

    def _send(self, worker: _Worker, handle: PoolHandle) -> None:
        """Give ``handle``'s pickled task to ``worker``."""
        if not handle.set_running_or_notify_cancel():
            return
        if not worker.handles:
            worker.since = time.monotonic()
        worker.handles.append(handle)
        try:
            worker.conn.send_bytes(handle.data)
        except OSError:
            self._break(worker)
        handle.data, handle.args = b"", ()  # the worker has them

    def _can_take(self, worker: _Worker, handle: PoolHandle) -> bool:
        """Whether ``worker`` may be sent ``handle`` now: it is free, or it runs one task
        and both are small and short (:data:`SMALL_TASK_BYTES`, :data:`PREFETCH_BELOW_S`)."""
        if not worker.handles:
            return True
        if len(worker.handles) > 1:
            return False
        running = worker.handles[0]
        return all(
            h.size <= SMALL_TASK_BYTES and self._known_short(_task_name(h.fn))
            for h in (running, handle)
        )

    def _known_short(self, name: str) -> bool:
        """Whether the function ``name`` ran at least twice and its last runs were short."""
        runs = self._seconds.get(name, ())
        return len(runs) >= 2 and max(runs) < PREFETCH_BELOW_S

    def _feed(self, worker: _Worker) -> None:
        """Give ``worker`` the oldest queued tasks it can take."""
        while self._queued and self._can_take(worker, self._queued[0]) and not self._broken:
            self._send(worker, self._queued.popleft())

    # -- reading ------------------------------------------------------------------------
    def poll(self, timeout: float | None) -> None:
        """Read every result that arrives within ``timeout`` s (None: until one does),
        giving each worker that finished the next queued tasks it can take."""
        busy = {w.conn: w for w in self._workers if w.handles}
        if not busy:
            return
        sentinels = {w.process.sentinel: w for w in busy.values()}
        for ready in wait([*busy, *sentinels], timeout):
            worker = busy.get(ready) or sentinels[ready]
            while worker.handles and self._read(worker) and worker.conn.poll(0):
                pass

    def _read(self, worker: _Worker) -> bool:
        """Read ``worker``'s next result into its handle; False if the worker died."""
        try:
            ok, value, text = worker.conn.recv()
        except (EOFError, OSError):
            self._break(worker)
            return False
        except Exception as exc:  # a reply the driver cannot unpickle
            ok, text = False, None
            value = RuntimeError(
                f"the result of {_task_name(worker.handles[0].fn)} could not be read: {exc}"
            )
        now = time.monotonic()
        handle = worker.handles.popleft()
        runs = self._seconds.setdefault(
            _task_name(handle.fn), collections.deque(maxlen=PREFETCH_HISTORY)
        )
        runs.append(now - worker.since)
        worker.since = now
        if ok:
            handle.set_result(value)
        else:
            if text:
                value.__cause__ = RemoteTraceback(text)
            handle.set_exception(value)
        self._feed(worker)
        return True

    def wait(self, handles: Iterable[PoolHandle], timeout: float | None = None) -> tuple[set, set]:
        """``(done, not_done)`` of ``handles`` once at least one is done or ``timeout`` s
        have passed (None: no limit)."""
        handles = set(handles)
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            done = {h for h in handles if h.finished()}
            if done:
                return done, handles - done
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                return set(), handles
            if not any(w.handles for w in self._workers):
                self._strand(handles)  # nothing can finish them: cancelled or broken
                continue
            self.poll(left)

    def _strand(self, handles: set) -> None:
        for handle in handles:
            if not handle.finished():
                reason = self._broken or "the worker pool was shut down before the task ran"
                handle.cancel() or handle.set_exception(BrokenProcessPool(reason))

    # -- ending -------------------------------------------------------------------------
    def _break(self, worker: _Worker) -> None:
        """``worker`` died: fail every unfinished task, stop the other workers."""
        worker.process.join(1.0)
        code = worker.process.exitcode
        how = f"exit code {code}" if code is None or code >= 0 else signal.Signals(-code).name
        task = _task_name(worker.handles[0].fn) if worker.handles else "no task"
        self._broken = (
            f"worker process {worker.process.pid} ended ({how}) while running {task}; "
            "the pool's unfinished tasks are lost"
        )
        error = BrokenProcessPool(self._broken)
        for w in self._workers:
            while w.handles:
                w.handles.popleft().set_exception(error)
        while self._queued:
            handle = self._queued.popleft()
            if handle.set_running_or_notify_cancel():
                handle.set_exception(error)
        self._stop(terminate=True)

    def shutdown(self, cancel: bool = False) -> None:
        """End the pool: with ``cancel``, drop the queued tasks and terminate the workers
        now; without, first let every submitted task finish."""
        if self._closed:
            return
        if cancel:
            while self._queued:
                self._queued.popleft().cancel()
        else:
            while self._broken is None and any(w.handles for w in self._workers):
                self.poll(None)
        self._closed = True
        running = [h for w in self._workers for h in w.handles]
        self._stop(terminate=cancel)
        for handle in running:  # terminated in mid-task
            handle.set_exception(BrokenProcessPool("the worker pool was shut down"))

    def _stop(self, terminate: bool) -> None:
        for w in self._workers:
            if terminate:
                if w.process.is_alive():
                    w.process.terminate()
            else:
                try:
                    w.conn.send_bytes(pickle.dumps(None))
                except OSError:
                    pass
        for w in self._workers:
            w.process.join(STOP_GRACE_S)
            if w.process.is_alive():
                w.process.kill()
                w.process.join()
            w.conn.close()
        self._workers = []

    @property
    def pids(self) -> list[int]:
        """The workers' process ids (empty before the first task)."""
        return [w.process.pid for w in self._workers]
