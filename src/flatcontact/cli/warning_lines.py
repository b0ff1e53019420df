"""What the command line does with Python warnings: flatcontact's own are lines, the
libraries' numerical noise is one summary.

A warning *of flatcontact* — a category defined in the package (``AnalysisWarning``,
``PointStoreRepaired``, ...) or a dated deprecation of an old configuration form
(``"... is deprecated since 2026-11-25: use ..."``) — is
news for the user: one ``warning:`` line each, without source lines. Everything else (numpy's
``RuntimeWarning: overflow encountered ...``, scipy's ``OptimizeWarning``, ASE's notes) is an
implementation detail of a computation whose result the code checks anyway: it is written to
the ``flatcontact.warnings`` logger (so a run's ``run.log`` keeps each one with its source
line) and counted; a command that succeeds then prints one ``warning:`` line saying how many
there were and the first, and a refused command prints only its ``error:`` line.
``FLATCONTACT_WARNINGS=all`` prints each library warning as its own line instead (debugging).

Only the command line does this, inside :func:`captured_warnings`, which restores the
warning filters and ``warnings.showwarning`` when the command ends: library callers and the
tests see every warning as Python raises it.
"""

from __future__ import annotations

import contextlib
import logging
import os
import re
import warnings
from collections.abc import Iterator

#: The form of flatcontact's dated deprecations (old factory names).
DEPRECATION = re.compile(r".+ is deprecated since \d{4}-\d{2}-\d{2}")
#: The environment variable that prints every library warning as its own line.
ENV = "FLATCONTACT_WARNINGS"

log = logging.getLogger("flatcontact.warnings")


def is_flatcontact_warning(category: type[Warning], message: object) -> bool:
    """True for a warning the user is meant to read (see the module)."""
    if getattr(category, "__module__", "").split(".")[0] == "flatcontact":
        return True
    return issubclass(category, DeprecationWarning) and bool(DEPRECATION.match(str(message)))


def one_line(category: type[Warning], message: object) -> str:
    """``Category: message`` with its whitespace collapsed."""
    return " ".join(f"{category.__name__}: {message}".split())


class WarningLines:
    """The ``warnings.showwarning`` of a command (see the module); ``library`` counts the rest."""

    def __init__(self, print_line, show_all: bool = False) -> None:
        self.print_line = print_line
        self.show_all = show_all
        self.library: list[str] = []

    def show(self, message, category, filename, lineno, file=None, line=None) -> None:
        text = one_line(category, message)
        if is_flatcontact_warning(category, message) or self.show_all:
            self.print_line(text)
            return
        self.library.append(text)
        # INFO: recorded by a run's run.log handler; never printed by logging's last resort
        log.info("%s (%s:%s)", text, filename, lineno)

    def summary(self) -> str | None:
        """The one line of a successful command that had library warnings, or None."""
        if not self.library:
            return None
        n = len(self.library)
        return (
            f"{n} numerical warning{'s' if n > 1 else ''} of the libraries not shown "
            f"(first: {self.library[0]}); a run's run.log has each, {ENV}=all prints them"
        )


@contextlib.contextmanager
def captured_warnings(print_line) -> Iterator[WarningLines]:
    """Route the warnings raised inside the block through a :class:`WarningLines`; the
    filters and ``warnings.showwarning`` are restored afterwards."""
    lines = WarningLines(print_line, os.environ.get(ENV, "").lower() == "all")
    with warnings.catch_warnings():
        warnings.showwarning = lines.show
        # flatcontact's dated deprecations are shown (Python hides DeprecationWarning
        # outside __main__); once per place, as Python's "default" action
        warnings.filterwarnings("default", message=DEPRECATION.pattern, category=DeprecationWarning)
        # ASE's note on reading its own extxyz files (info it cannot hash): noise, not news
        warnings.filterwarnings("ignore", message="Skipping unhashable information")
        yield lines
