"""What every task of a scan carries besides its own inputs, pickled once per scan.

A scan sends each of its thousands of tasks with the same :class:`ScanContext` (the reference
interface, the calculator factory, the relaxation settings, the handle of the shared
reference Hessian): 5 KB pickled for the 36-atom quartz cell, 0.09 ms of the driver's CPU per
task measured in a 2-worker scan (0.03 ms in isolation: the driver wakes cold between
results), on the cores the workers compute on. A :class:`ScanContext` therefore pickles its
fields the first time it is pickled and sends those bytes with every later task; a process
turns the same bytes into the same object once (:func:`context_from_bytes`, a small cache
keyed by the bytes themselves, so a changed context is never mistaken for another).

Convention: a context is immutable. It is a frozen dataclass, and the reference it holds
must not be changed in place once a task has carried it (a scan makes a new context when
anything changes, e.g. when the reference Hessian's handle is added).
"""

from __future__ import annotations

import collections
import dataclasses
import pickle
from typing import Any

from ase import Atoms

#: how many distinct contexts a process keeps unpickled (a scan uses one or two at a time)
KEPT_CONTEXTS = 8

_unpickled: collections.OrderedDict[bytes, ScanContext] = collections.OrderedDict()


@dataclasses.dataclass(frozen=True)
class ScanContext:
    """Everything a worker needs besides the task; picklable (its fields once, see the
    module)."""

    reference: Atoms
    factory: Any
    settings: Any
    #: the root of the reference's Hessian the scan's driver computed
    #: (:class:`~flatcontact.ispes.precondition.SharedRoot`), or None
    hessian: Any = None

    def __reduce__(self):
        data = self.__dict__.get("_pickled")
        if data is None:
            fields = (self.reference, self.factory, self.settings, self.hessian)
            data = pickle.dumps(fields, protocol=pickle.HIGHEST_PROTOCOL)
            object.__setattr__(self, "_pickled", data)
        return (context_from_bytes, (data,))


def context_from_bytes(data: bytes) -> ScanContext:
    """The context pickled as ``data``: unpickled once per process, then the same object."""
    context = _unpickled.get(data)
    if context is None:
        context = ScanContext(*pickle.loads(data))
        object.__setattr__(context, "_pickled", data)
        _unpickled[data] = context
        while len(_unpickled) > KEPT_CONTEXTS:
            _unpickled.popitem(last=False)
    else:
        _unpickled.move_to_end(data)
    return context
