"""The typer application that every ``flatcontact`` sub-command registers on.

Each command lives in its own module of :mod:`flatcontact.cli` and is thin:
it parses flags (named by quantity and unit, e.g. ``--p0-gpa``), calls the
library and prints. Heavy imports happen inside the command functions so
that ``flatcontact --help`` stays fast.
"""

import typer
from rich.console import Console

app = typer.Typer(
    name="flatcontact",
    help="Onset of sliding of a Hertzian asperity with an atomically flat crystalline contact.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)

#: Console for human-readable output (tables, progress); JSON goes to plain stdout.
console = Console()
#: Console for one-line errors and warnings.
err_console = Console(stderr=True)
