"""A Dask worker plugin that runs one setup function once in every worker process.

:meth:`flatcontact.ispes.executors.DaskExecutor.setup_workers` registers it: ``distributed``
sends it (pickled once) to every worker of the cluster, to those that join later too, and
calls :meth:`SetupPlugin.setup` there before the worker runs tasks. The scan hands its
reference Hessian's root to the workers so (:mod:`flatcontact.ispes.shared_hessian`). Imported
only where Dask runs (``distributed``'s import stays out of the local workers' start).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from distributed.diagnostics.plugin import WorkerPlugin


class SetupPlugin(WorkerPlugin):
    """Calls ``setup(*args)`` in each worker process it is given to (``setup`` importable there,
    ``args`` picklable)."""

    def __init__(self, setup: Callable, args: tuple[Any, ...] = ()):
        self._setup = setup
        self._args = tuple(args)

    def setup(self, worker: Any) -> None:
        self._setup(*self._args)
