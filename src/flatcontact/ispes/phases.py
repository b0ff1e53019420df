"""Wall time of a scan's phases (the probe, the ideal work of separation, symmetry, the grid).

:func:`flatcontact.ispes.scan.run_scan` records into a :class:`PhaseClock` (``ScanResult.
phase_seconds``); code anywhere below it marks a phase with :func:`phase`, which does
nothing when no scan is recording (a probe or a relaxation called on its own). Each
finished phase is also logged at DEBUG level on the ``flatcontact.ispes.phases`` logger
(``"<name> <seconds>"``), so a caller that only sees the pipeline (the run benchmark) can
collect them with a logging handler.

Names nest with ``/``: ``"probe/ideal W"`` is part of ``"probe"``. A phase entered twice
(the grid's rounds) adds up. Seconds are the driver's wall time: on a worker's result the
driver's wait counts, which is how much a phase holds the scan up.
"""

from __future__ import annotations

import contextlib
import contextvars
import logging
import time
from collections.abc import Iterator

log = logging.getLogger("flatcontact.ispes.phases")

_CURRENT: contextvars.ContextVar[PhaseClock | None] = contextvars.ContextVar(
    "flatcontact_scan_phases", default=None
)


class PhaseClock:
    """Seconds per phase name, in the order the phases first ended (an inner phase first)."""

    def __init__(self) -> None:
        self.seconds: dict[str, float] = {}

    def add(self, name: str, seconds: float) -> None:
        self.seconds[name] = self.seconds.get(name, 0.0) + seconds
        log.debug("%s %.6f", name, seconds)


@contextlib.contextmanager
def recording() -> Iterator[PhaseClock]:
    """Record the phases marked inside the block (in this thread) into a new clock."""
    clock = PhaseClock()
    token = _CURRENT.set(clock)
    try:
        yield clock
    finally:
        _CURRENT.reset(token)


@contextlib.contextmanager
def phase(name: str) -> Iterator[None]:
    """Time the block as phase ``name`` of the scan being recorded (else do nothing)."""
    clock = _CURRENT.get()
    if clock is None:
        yield
        return
    start = time.perf_counter()
    try:
        yield
    finally:
        clock.add(name, time.perf_counter() - start)
