"""SIGTERM as an exception: a terminated process unwinds like Ctrl-C, so ``finally`` blocks run
(temporary files removed, stored points committed) before it exits.

One mechanism for every place that needs it: the command line (:func:`flatcontact.cli.
sigterm_unwinds`) and the scan's point store (:class:`flatcontact.ispes.store.PointStore`).
"""

from __future__ import annotations

import os
import signal
import threading
from collections.abc import Callable
from typing import Any


def raise_on_sigterm(make_error: Callable[[int], BaseException]) -> Any | None:
    """Install a SIGTERM handler that raises ``make_error(signum)`` in this process.

    Only where SIGTERM would otherwise kill the process at once: in the main thread, with the
    default action in place (an earlier handler is left alone). A process forked after the
    install (a pool's worker) gets the default action back and dies of SIGTERM as before.

    Returns
    -------
    The previous handler, to restore with ``signal.signal(signal.SIGTERM, previous)``, or None
    when nothing was installed.
    """
    if threading.current_thread() is not threading.main_thread():
        return None
    if signal.getsignal(signal.SIGTERM) is not signal.SIG_DFL:
        return None
    pid = os.getpid()

    def terminated(signum, frame):
        if os.getpid() != pid:  # a forked child: die as it would have
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            os.kill(os.getpid(), signal.SIGTERM)
            return
        raise make_error(signum)

    return signal.signal(signal.SIGTERM, terminated)
