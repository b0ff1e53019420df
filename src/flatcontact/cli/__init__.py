"""The ``flatcontact`` command line.

``main`` runs the typer app and turns user mistakes (:class:`~flatcontact.errors.InputError`)
into a single ``error: ...`` line on stderr with exit status 2, the same status
click uses for usage errors. Tests call ``main([...])`` and catch ``SystemExit``.
"""

from __future__ import annotations

import sys

from flatcontact import __version__
from flatcontact.cli import commands as _commands  # noqa: F401  (registers the sub-commands)
from flatcontact.cli.app import app, console, print_error
from flatcontact.errors import InputError

__all__ = ["app", "main"]


@app.callback()
def _root() -> None:
    """Onset of sliding of a Hertzian asperity with an atomically flat crystalline contact."""


@app.command("version")
def version_command() -> None:
    """Print the flatcontact version."""
    console.print(__version__)


def main(argv: list[str] | None = None) -> None:
    """Entry point of the ``flatcontact`` console script."""
    try:
        app(args=argv)
    except InputError as exc:
        print_error(exc)
        sys.exit(2)
