"""Where grid points run: serially, in local worker processes, or on a Dask cluster.

Every executor follows the :class:`Executor` protocol: ``submit(fn, *args)`` returns a
handle; ``wait_first`` blocks until at least one handle is finished, ``done`` says whether a
handle already is, ``result`` gives its value. Workers build their calculator once
(:func:`flatcontact.ispes.relax.worker_calculator`, cached per worker thread) and
reuse it for every point they receive, with the root of the reference's Hessian the driver
computed (:mod:`flatcontact.ispes.shared_hessian`: a file local workers read, a worker plugin
on Dask, :meth:`DaskExecutor.setup_workers`). Workers never write files: results come back
to the driver, which alone writes the point store.

- :class:`SerialExecutor`: in the driver process (debugging, tests, 1 core).
- :class:`ProcessExecutor`: worker processes fed over pipes by the driver's own thread
  (:mod:`flatcontact.ispes.worker_pool`), started with the ``spawn`` start method (no
  fork of a process that holds a LAMMPS instance or MPI), one worker per core by default;
  workers ignore SIGINT so Ctrl-C reaches only the driver, and die with the driver
  (``kill -9`` of the driver alone leaves no worker).
- :class:`DaskExecutor`: a ``distributed.Client`` on a running scheduler
  (``--dask-address tcp://host:8786``), a ``LocalCluster``, or a dask-jobqueue
  cluster (SLURM, PBS, ...) described by a dict (see :func:`jobqueue_cluster`).
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import ctypes
import multiprocessing
import os
import signal
import sys
from collections.abc import Callable, Iterable
from typing import Any, Protocol, runtime_checkable

from flatcontact.foundation.errors import InputError
from flatcontact.ispes.main_guard import serial_instead
from flatcontact.ispes.relax import worker_calculator
from flatcontact.ispes.worker_pool import PoolHandle, WorkerPool


def default_workers() -> int:
    """One worker per core available to this process."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # pragma: no cover - not on Linux
        return max(1, os.cpu_count() or 1)


@runtime_checkable
class Executor(Protocol):
    """What the scan driver asks of an executor (:mod:`flatcontact.ispes.scan`).

    ``workers``: how many tasks run at once (the driver keeps twice as many in flight and
    from :data:`flatcontact.ispes.scan_probe.MANY_WORKERS` on probes in parallel chains).
    ``inline``: tasks run at submission in the driver's process (the driver commits its
    store before a submission that would leave points uncommitted past their deadline).
    ``wait_first``: the finished handles, waiting at most ``timeout`` seconds (None: until
    one finishes; nothing finished: an empty first set). ``prestart``: start the workers
    and build their calculators without waiting (a no-op where there is nothing to start).
    An executor may also have ``serve()``: hand queued tasks to the workers that are free,
    without waiting (the driver calls it between the steps of its own computations).
    """

    name: str
    inline: bool

    @property
    def workers(self) -> int: ...

    def submit(self, fn: Callable, *args: Any) -> Any: ...

    def wait_first(
        self, handles: Iterable[Any], timeout: float | None = None
    ) -> tuple[set, set]: ...

    def done(self, handle: Any) -> bool: ...

    def result(self, handle: Any) -> Any: ...

    def prestart(self, factory: Any, reference: Any) -> None: ...

    def close(self, cancel: bool = False) -> None: ...


def _finite(timeout: float | None) -> float | None:
    """``wait_first``'s time limit as the waits take it: None (no limit) for None or inf."""
    return None if timeout is None or timeout == float("inf") else timeout


class SerialExecutor:
    """Runs each task at submission, in the driver process."""

    workers = 1
    name = "serial"
    inline = True

    def submit(self, fn: Callable, *args: Any) -> cf.Future:
        fut: cf.Future = cf.Future()
        try:
            fut.set_result(fn(*args))
        except BaseException as exc:
            if isinstance(exc, KeyboardInterrupt):
                raise
            fut.set_exception(exc)
        return fut

    def wait_first(
        self, handles: Iterable[cf.Future], timeout: float | None = None
    ) -> tuple[set, set]:
        return cf.wait(list(handles), timeout=_finite(timeout), return_when=cf.FIRST_COMPLETED)

    @staticmethod
    def done(handle: Any) -> bool:
        """Whether ``handle`` is finished (``concurrent.futures`` and Dask futures alike)."""
        return bool(handle.done())

    @staticmethod
    def result(handle: cf.Future) -> Any:
        return handle.result()

    def prestart(self, factory: Any, reference: Any) -> None:
        """Nothing to start: the driver builds its calculator when it first needs it."""

    def serve(self) -> None:
        """Nothing to hand out: every task ran at its submission."""

    def close(self, cancel: bool = False) -> None:
        pass


#: ``prctl`` option that asks the kernel to signal a process when its parent dies (Linux).
_PR_SET_PDEATHSIG = 1


def die_with_parent(parent_pid: int) -> None:
    """Make this process receive SIGKILL when ``parent_pid`` (its parent) dies.

    Linux ``prctl(PR_SET_PDEATHSIG)``: a worker of a driver killed with ``kill -9`` must not
    go on computing points nobody will store. If the parent is already gone (it died
    between the spawn and this call), exit at once. A no-op on other systems.
    """
    if not sys.platform.startswith("linux"):  # pragma: no cover - Linux only
        return
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
    if os.getppid() != parent_pid:
        os._exit(1)


#: how much lower than the driver the local workers run (``os.nice``): with one worker per
#: core the driver shares the cores with them, and every stored point waits for it (store,
#: next task); at equal priority it waited for the scheduler's time slice
WORKER_NICE_INCREMENT = 3


def _init_worker(parent_pid: int) -> None:
    """Worker initializer: Ctrl-C reaches only the driver; die with the driver; run at a
    lower priority than the driver (:data:`WORKER_NICE_INCREMENT`)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    die_with_parent(parent_pid)
    try:
        os.nice(WORKER_NICE_INCREMENT)
    except OSError:  # pragma: no cover - not permitted: keep the priority
        pass


class ProcessExecutor(SerialExecutor):
    """Local worker processes (``spawn``), ``workers`` of them (default: one per core), fed
    by the driver's own thread (:class:`~flatcontact.ispes.worker_pool.WorkerPool`)."""

    name = "processes"
    inline = False

    def __init__(self, workers: int | None = None):
        workers = default_workers() if workers is None else workers
        if int(workers) != workers or workers < 1:
            raise InputError(
                f"workers: expected a positive number of worker processes, got {workers}"
            )
        self.workers = int(workers)
        one_blas_thread_in_workers()
        self._pool = WorkerPool(
            self.workers,
            multiprocessing.get_context("spawn"),
            initializer=_init_worker,
            initargs=(os.getpid(),),
        )

    def submit(self, fn: Callable, *args: Any) -> PoolHandle:
        return self._pool.submit(fn, *args)

    def wait_first(
        self, handles: Iterable[PoolHandle], timeout: float | None = None
    ) -> tuple[set, set]:
        return self._pool.wait(handles, _finite(timeout))

    def prestart(self, factory: Any, reference: Any) -> None:
        """Start every worker now and build its calculator, without waiting.

        The driver calls this before its own serial work (the reference Hessian, the probe):
        the workers' start (spawn, imports, the model's set-up) then overlaps it instead of
        delaying the first points. One task per worker.
        """
        self._pool.submit_to_each(warm_worker, factory, reference)

    def serve(self) -> None:
        """Read the results that are in and give the workers that finished their next
        queued tasks, without waiting: a driver that computes for a while itself (the
        reference Hessian, 0.3-0.5 s) calls this between its own steps, or a worker done
        with its start and first task would wait for the driver's next wait (measured on
        the 12 × 12 quartz scan: both workers idle for the Hessian's last 0.1 s)."""
        self._pool.poll(0.0)

    def close(self, cancel: bool = False) -> None:
        self._pool.shutdown(cancel=cancel)


def one_blas_thread_in_workers() -> None:
    """Worker processes started from now on use one OpenBLAS thread (unless the user set
    ``OPENBLAS_NUM_THREADS``): one worker per core, and BLAS threads inside a worker only
    contend with the others. The current process's BLAS, already loaded, is unchanged."""
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def warm_worker(factory: Any, reference: Any) -> None:
    """Build this worker's calculator for ``factory`` (cached for its later points)."""
    worker_calculator(factory, reference)


def jobqueue_cluster(spec: dict) -> Any:
    """A dask-jobqueue cluster from ``{"kind": "slurm"|"pbs"|..., "jobs": N, **kwargs}``.

    ``kwargs`` go to the cluster class unchanged (``cores``, ``memory``, ``queue``,
    ``account``, ``walltime``, ``job_extra_directives``, ...); ``jobs`` batch jobs are
    requested with ``cluster.scale(jobs=N)``. Needs the ``jobqueue`` extra
    (``pip install 'flatcontact[jobqueue]'``).
    """
    spec = dict(spec)
    kind = str(spec.pop("kind", "")).lower()
    jobs = int(spec.pop("jobs", 1))
    try:
        import dask_jobqueue
    except ImportError:
        raise InputError(
            "jobqueue: dask-jobqueue is not installed; pip install 'flatcontact[jobqueue]'"
        ) from None
    classes = {
        "slurm": "SLURMCluster",
        "pbs": "PBSCluster",
        "sge": "SGECluster",
        "lsf": "LSFCluster",
        "htcondor": "HTCondorCluster",
        "oar": "OARCluster",
        "moab": "MoabCluster",
    }
    if kind not in classes:
        raise InputError(f"jobqueue.kind: expected one of {', '.join(classes)}, got {kind!r}")
    try:
        cluster = getattr(dask_jobqueue, classes[kind])(**spec)
    except (TypeError, ValueError) as exc:
        raise InputError(f"jobqueue: cannot build a {classes[kind]} from {spec} ({exc})") from None
    cluster.scale(jobs=jobs)
    return cluster


def check_scheduler_address(
    address: str, timeout_s: float = 3.0, field: str = "dask-address"
) -> None:
    """Refuse a Dask scheduler address that is malformed or where nothing listens, in one
    line naming it, within ``timeout_s`` (a refused port answers at once; an unroutable host
    takes the timeout). Only the TCP-based transports are probed."""
    import socket

    from flatcontact.config.scan import parse_dask_address

    try:
        scheme, host, port = parse_dask_address(address)
    except ValueError as exc:
        raise InputError(f"{field}: {exc}") from None
    if scheme not in ("tcp", "tls", "ws", "wss"):
        return
    try:
        with socket.create_connection((host, port), timeout=timeout_s):
            pass
    except OSError as exc:
        reason = exc.strerror or exc.__class__.__name__
        raise InputError(
            f"{field} {address}: no Dask scheduler reachable at {host}:{port} ({reason}); "
            "start one (dask scheduler) or check the address"
        ) from None


def _abandon(client: Any) -> None:
    """Mark a ``distributed.Client`` whose start failed as closed and stop its event loop, so
    its finaliser does not wait 10 s on a scheduler that never answered and print a
    traceback at exit."""
    client.status = "closed"
    runner = getattr(client, "_loop_runner", None)
    if runner is not None:
        with contextlib.suppress(Exception):
            runner.stop()


class DaskExecutor(SerialExecutor):
    """Tasks on a Dask distributed cluster.

    Parameters
    ----------
    address
        Scheduler address (``tcp://host:8786``); checked with a ``timeout_s`` connection
        attempt, and an unreachable scheduler is a one-line InputError.
    cluster
        Alternatively a cluster object (``LocalCluster``, a dask-jobqueue cluster).
    """

    name = "dask"
    inline = False

    def __init__(self, address: str | None = None, cluster: Any = None, timeout_s: float = 5.0):
        from distributed import Client

        if (address is None) == (cluster is None):
            raise InputError("dask: give either a scheduler address or a cluster")
        self._own_cluster = None
        if address is not None:
            check_scheduler_address(address, timeout_s)
        client = Client.__new__(Client)
        try:
            client.__init__(
                address if address is not None else cluster,
                timeout=f"{timeout_s}s",
                set_as_default=False,
            )
        except ValueError as exc:
            _abandon(client)
            raise InputError(f"dask-address {address!r}: not a scheduler address ({exc})") from None
        except Exception as exc:  # refused, timed out, or a peer that is no scheduler (its
            # bytes read as a frame length: MemoryError), all the same to the user
            _abandon(client)
            said = " ".join(str(exc).split())[:120]
            raise InputError(
                f"dask-address {address}: no Dask scheduler answers there "
                f"({exc.__class__.__name__}{': ' + said if said else ''}); start one "
                "(dask scheduler) or check the address"
            ) from None
        self._client = client

    @property
    def workers(self) -> int:
        """Worker threads the scheduler has now (asked each time: workers join and leave,
        e.g. ``dask worker`` processes started after the client, or a batch job queue)."""
        info = self._client.scheduler_info()
        return max(1, sum(w.get("nthreads", 1) for w in info.get("workers", {}).values()))

    @classmethod
    def local(cls, workers: int = 2) -> DaskExecutor:
        """A ``LocalCluster`` of ``workers`` single-threaded worker processes (owned and closed)."""
        from distributed import LocalCluster

        one_blas_thread_in_workers()
        cluster = LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None
        )
        ex = cls(cluster=cluster)
        ex._own_cluster = cluster
        return ex

    def submit(self, fn: Callable, *args: Any):
        return self._client.submit(fn, *args, pure=False)

    def wait_first(self, handles, timeout: float | None = None):
        from distributed import wait

        handles = list(handles)
        with self._client.as_current():
            try:
                done, not_done = wait(
                    handles, timeout=_finite(timeout), return_when="FIRST_COMPLETED"
                )
            except TimeoutError:  # distributed raises it when nothing finished in time
                return set(), set(handles)
        return set(done), set(not_done)

    def setup_workers(self, name: str, setup: Callable, *args: Any) -> None:
        """Run ``setup(*args)`` once in every worker process, now and in each that joins later
        (a worker plugin named ``name``: :class:`flatcontact.ispes.worker_plugin.SetupPlugin`):
        the arguments travel once per worker, also to workers on other machines, not with
        every task."""
        from flatcontact.ispes.worker_plugin import SetupPlugin

        self._client.register_plugin(SetupPlugin(setup, args), name=name)

    def withdraw_setup(self, name: str) -> None:
        """Stop giving :meth:`setup_workers`'s ``name`` to the workers that join from now on."""
        self._client.unregister_worker_plugin(name)

    def close(self, cancel: bool = False) -> None:
        self._client.close()
        if self._own_cluster is not None:
            self._own_cluster.close()


def make_executor(
    kind: str = "processes",
    workers: int | None = None,
    dask_address: str | None = None,
    jobqueue: dict | None = None,
) -> Executor:
    """Build an executor: ``serial``, ``processes`` (default), or ``dask``.

    ``dask_address`` or ``jobqueue`` imply ``dask``; without either, ``dask`` starts a
    ``LocalCluster`` of ``workers`` processes.
    """
    if dask_address is not None or jobqueue is not None:
        kind = "dask"
    if kind == "serial":
        return SerialExecutor()
    if kind == "processes":
        if workers == 1 or serial_instead(workers):  # a script without its __main__ guard
            return SerialExecutor()
        return ProcessExecutor(workers)
    if kind == "dask":
        if dask_address is not None:
            return DaskExecutor(address=dask_address)
        if jobqueue is not None:
            return DaskExecutor(cluster=jobqueue_cluster(jobqueue))
        if serial_instead(workers):  # a local cluster spawns its workers too
            return SerialExecutor()
        return DaskExecutor.local(workers or default_workers())
    raise InputError(f"executor: expected serial, processes or dask, got {kind!r}")
