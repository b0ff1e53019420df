"""The typer application that every ``flatcontact`` sub-command registers on.

Each command lives in its own module of :mod:`flatcontact.cli` and is thin:
it parses flags (named by quantity and unit, e.g. ``--p0-gpa``), calls the
library and prints. Heavy imports happen inside the command functions so
that ``flatcontact --help`` stays fast.
"""

import typer
from rich.console import Console
from rich.text import Text

app = typer.Typer(
    name="flatcontact",
    help="Onset of sliding of a Hertzian asperity with an atomically flat crystalline contact.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)

#: Console for human-readable output (tables, progress); JSON goes to plain stdout.
console = Console()
#: Console for one-line errors, warnings and progress notes. Markup is off: a message is
#: user text (paths, values, ``'name [unit]'`` examples), never rich markup, so nothing in
#: square brackets is swallowed.
err_console = Console(stderr=True, markup=False, highlight=False, soft_wrap=True)


def print_error(message: object) -> None:
    """Print ``error: <message>`` on stderr, the message verbatim (no rich markup)."""
    err_console.print(Text("error: ", style="bold red") + Text(str(message)))


def print_warning(message: object) -> None:
    """Print ``warning: <message>`` on stderr, the message verbatim (no rich markup)."""
    err_console.print(Text("warning: ", style="bold yellow") + Text(str(message)))
