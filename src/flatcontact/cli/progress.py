"""Rich progress for the CLI: an observer the library calls as ``progress(done, total)``.

The library never imports rich (:func:`flatcontact.ispes.scan.run_scan` takes any callable);
this bar is what ``flatcontact scan`` and ``flatcontact run`` attach.
"""

from __future__ import annotations

from typing import Any


class ScanBar:
    """A rich progress bar of ISPES points, usable as ``with ScanBar(console) as bar: ...``
    and passed as the ``progress`` callback."""

    def __init__(self, console: Any, label: str = "ISPES"):
        self.console = console
        self.label = label
        self._progress = None
        self._task = None

    def __enter__(self) -> ScanBar:
        return self

    def __exit__(self, *exc) -> None:
        if self._progress is not None:
            self._progress.stop()
            self._progress = None

    def __call__(self, done: int, total: int) -> None:
        if self._progress is None:
            self._start(total, done)
        self._progress.update(self._task, completed=done, total=total)

    def _start(self, total: int, done: int) -> None:
        from rich.progress import (
            BarColumn,
            MofNCompleteColumn,
            Progress,
            ProgressColumn,
            TextColumn,
            TimeElapsedColumn,
            TimeRemainingColumn,
        )
        from rich.text import Text

        class Rate(ProgressColumn):
            def render(self, task):
                speed = task.finished_speed or task.speed
                return Text("-- pt/s" if speed is None else f"{speed:.2f} pt/s")

        self._progress = Progress(
            TextColumn(self.label),
            BarColumn(),
            MofNCompleteColumn(),
            Rate(),
            TimeElapsedColumn(),
            TextColumn("ETA"),
            TimeRemainingColumn(),
            console=self.console,
            transient=False,
            # twice a second: the driver shares the cores with the scan's workers, and a
            # redraw at rich's default 10 Hz costs it CPU they would use
            refresh_per_second=2,
        )
        self._task = self._progress.add_task("scan", total=total, completed=done)
        self._progress.start()
