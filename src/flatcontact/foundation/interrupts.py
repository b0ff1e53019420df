"""SIGTERM as an exception: a terminated process unwinds like Ctrl-C, so ``finally`` blocks run
(temporary files removed, stored points committed) before it exits.

One mechanism for every place that needs it: the command line (:func:`flatcontact.cli.
sigterm_unwinds`) and the scan's point store (:class:`flatcontact.ispes.store.PointStore`).
Before either exists, while the command line starts (imports take most of a second),
:func:`exit_on_sigterm` ends the process at once with the command line's one line: nothing
has been written yet, so there is nothing to unwind.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from collections.abc import Callable
from typing import Any

#: The line (after ``error: ``) of a command stopped by SIGTERM; ``kept`` says what it kept.
TERMINATED_LINE = (
    "terminated (SIGTERM); temporary files removed, {kept}: rerun the same command to resume"
)
#: The exit status of a command stopped by SIGTERM (the shell's 128 + signal number).
TERMINATED_STATUS = 128 + signal.SIGTERM
#: The line (after ``error: ``) of a command stopped by Ctrl-C that does not say it itself.
INTERRUPTED_LINE = (
    "interrupted; temporary files removed, finished work kept: rerun the same command to resume"
)
#: The exit status of a command stopped by Ctrl-C (128 + SIGINT).
INTERRUPTED_STATUS = 128 + signal.SIGINT


def _in_charge() -> bool:
    """Whether SIGTERM is this code's to handle: the main thread, the default action in place
    or only a start-up handler (:func:`exit_on_sigterm`) that gives way."""
    if threading.current_thread() is not threading.main_thread():
        return False
    current = signal.getsignal(signal.SIGTERM)
    return current is signal.SIG_DFL or getattr(current, "gives_way", False)


def exit_on_sigterm(
    line: str = "error: " + TERMINATED_LINE.format(kept="finished work kept"),
    status: int = TERMINATED_STATUS,
) -> Any | None:
    """Install a start-up SIGTERM handler: write ``line`` on stderr and end the process at once
    (``os._exit``) with ``status``.

    For a process that has not yet written anything, while its slow imports run: it gives way
    to :func:`raise_on_sigterm` once the command is ready to unwind, and comes back when that
    is restored. Installed only where SIGTERM would otherwise kill the process silently (the
    main thread, the default action in place); a forked process dies of SIGTERM as before.

    Returns
    -------
    The previous handler, or None when nothing was installed.
    """
    if not _in_charge():
        return None
    pid = os.getpid()
    text = (line.rstrip("\n") + "\n").encode("utf-8", "replace")

    def stop(signum, frame):
        if os.getpid() != pid:  # a forked child: die as it would have
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            os.kill(os.getpid(), signal.SIGTERM)
            return
        for stream in (sys.stdout, sys.stderr):  # what was printed before stays printed
            try:
                stream.flush()
            except (OSError, ValueError, RuntimeError, AttributeError):
                pass
        try:
            os.write(2, text)
        except OSError:
            pass
        os._exit(status)

    stop.gives_way = True
    return signal.signal(signal.SIGTERM, stop)


def raise_on_sigterm(make_error: Callable[[int], BaseException]) -> Any | None:
    """Install a SIGTERM handler that raises ``make_error(signum)`` in this process.

    Only where SIGTERM would otherwise kill the process at once: in the main thread, with the
    default action in place (an earlier handler is left alone, except the start-up one of
    :func:`exit_on_sigterm`, which gives way). A process forked after the install (a pool's
    worker) gets the default action back and dies of SIGTERM as before.

    Returns
    -------
    The previous handler, to restore with ``signal.signal(signal.SIGTERM, previous)``, or None
    when nothing was installed.
    """
    if not _in_charge():
        return None
    pid = os.getpid()

    def terminated(signum, frame):
        if os.getpid() != pid:  # a forked child: die as it would have
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            os.kill(os.getpid(), signal.SIGTERM)
            return
        raise make_error(signum)

    return signal.signal(signal.SIGTERM, terminated)
