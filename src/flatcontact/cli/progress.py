"""Rich progress for the CLI: the observers the library calls.

The library never imports rich: :func:`flatcontact.ispes.scan.run_scan` takes any callable
``progress(done, total)`` and :class:`flatcontact.pipeline.Pipeline` any ``on_event(event)``.
:class:`ScanBar` is what ``flatcontact scan`` and ``flatcontact run`` attach to the scan,
:class:`StageLines` what ``flatcontact run`` attaches to the pipeline.
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


#: What the console says when a stage ends, by the stage's action.
_ACTION_TEXT = {"skipped": "unchanged, skipped", "resumed": "resumed", "ran": "done"}


class StageLines:
    """The stages of ``flatcontact run`` on the console: a bold ``N. stage`` line when a stage
    starts, a spinner while it works (a scan has its :class:`ScanBar` instead) and a line
    with what it did. Use as ``with StageLines(console) as lines: Pipeline(...,
    on_event=lines)``; leaving the block stops a spinner a failure left running."""

    def __init__(self, console: Any):
        self.console = console
        self._status = None

    def __enter__(self) -> StageLines:
        return self

    def __exit__(self, *exc) -> None:
        self._stop()

    def _stop(self) -> None:
        if self._status is not None:
            self._status.stop()
            self._status = None

    def __call__(self, event) -> None:
        """Show one :class:`flatcontact.pipeline.StageEvent`."""
        if event.kind == "start":
            self.console.print(f"[bold]{event.index}. {event.name}[/]", highlight=False)
            if event.name != "scan":
                self._status = self.console.status(f"{event.name} ...")
                self._status.start()
        elif event.kind == "end":
            self._stop()
            seconds = f" in {event.seconds:.1f} s" if event.action != "skipped" else ""
            self.console.print(f"   {_ACTION_TEXT[event.action]}{seconds}", highlight=False)
            if event.message:
                self.console.print(f"   warning: {event.message}", highlight=False)
        elif event.kind == "off":
            self.console.print(
                f"[bold]{event.index}. {event.name}[/]\n   off: {event.message}", highlight=False
            )
        else:  # failed: the exception is reported by the command
            self._stop()
