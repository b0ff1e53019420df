"""The typer application that every ``flatcontact`` sub-command registers on.

Each command lives in its own module of :mod:`flatcontact.cli` and is thin:
it parses flags (named by quantity and unit, e.g. ``--p0-gpa``), calls the
library and prints. Heavy imports happen inside the command functions so
that ``flatcontact --help`` stays fast.
"""

from pathlib import Path

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


#: Control characters as they are shown in a one-line message (a file name may hold them).
_SHOWN_CONTROLS = {c: repr(chr(c))[1:-1] for c in (*range(0x20), 0x7F)}


def one_line(message: object) -> str:
    """``message`` as one line: a newline, tab or other control character in it (a file name
    the user gave, a library's text) is shown escaped (``\\n``), so it cannot split the line."""
    return str(message).translate(_SHOWN_CONTROLS)


def print_error(message: object) -> None:
    """Print ``error: <message>`` on stderr, the message verbatim (no rich markup) and on one
    line (:func:`one_line`)."""
    err_console.print(Text("error: ", style="bold red") + Text(one_line(message)))


def print_warning(message: object) -> None:
    """Print ``warning: <message>`` on stderr, the message verbatim (no rich markup), on one
    line (:func:`one_line`)."""
    err_console.print(Text("warning: ", style="bold yellow") + Text(one_line(message)))


def print_progress(message: object) -> None:
    """A progress line of a long command (dim, on stderr, so ``--json`` output stays clean)."""
    err_console.print(message, style="dim")


def check_out_dir(path: str | Path, flag: str = "--out") -> Path:
    """Refuse an output directory that cannot be used, before any work starts.

    ``path`` must be an existing writable directory or one that can be created (its nearest
    existing ancestor is a writable directory). The check really creates the missing
    directories and a probe file and removes them again, so it holds for root and for
    special file systems (``/proc``) where permission bits say nothing; it then restores the
    modification time of the directory it probed in, so a command refused later has changed
    nothing outside ``path``.

    Returns
    -------
    Path
        ``path`` as a :class:`~pathlib.Path` (not created).

    Raises
    ------
    InputError
        One line naming ``flag`` and the path: empty, a name longer than 255 bytes, exists and
        is not a directory, or not creatable / not writable (with the operating system's
        reason).
    """
    import os
    import tempfile

    from flatcontact.foundation.errors import InputError
    from flatcontact.foundation.fileio import check_path_length

    if not str(path).strip():
        raise InputError(f"{flag} {str(path)!r}: empty path; name a directory (. for this one)")
    check_path_length(path, flag)
    out = Path(path).expanduser()
    if out.exists() and not out.is_dir():
        raise InputError(f"{flag} {str(out)!r}: exists and is not a directory")
    created: list[Path] = []
    probe = out
    while not probe.exists():
        created.append(probe)
        probe = probe.parent
    if not probe.is_dir():
        raise InputError(f"{flag} {str(out)!r}: {str(probe)!r} is not a directory")
    before = probe.stat()  # the probe leaves no trace: not even a changed mtime
    try:
        for d in reversed(created):
            d.mkdir()
        fd, name = tempfile.mkstemp(prefix=".flatcontact-probe.", dir=out)
        os.close(fd)
        os.unlink(name)
    except OSError as exc:
        raise InputError(
            f"{flag} {str(out)!r}: cannot write there ({exc.strerror or type(exc).__name__})"
        ) from None
    finally:
        for d in created:  # innermost first; only what this check made
            try:
                d.rmdir()
            except OSError:
                pass
        try:
            os.utime(probe, ns=(before.st_atime_ns, before.st_mtime_ns))
        except OSError:  # not the owner: the time stays changed, nothing else does
            pass
    return out


def check_out_flags(argv: list[str], flags: tuple[str, ...] = ("--out",)) -> None:
    """Refuse an empty or over-long value of an output flag in ``argv``, before any command runs.

    ``--out ''`` would otherwise become the working directory (a path type turns ``''`` into
    ``.``), and a name over 255 bytes fails in the first ``stat``. Both are one line naming
    the flag; nothing is touched.
    """
    from flatcontact.foundation.errors import InputError
    from flatcontact.foundation.fileio import check_path_length

    for i, token in enumerate(argv):
        for flag in flags:
            if token == flag and i + 1 < len(argv):
                value = argv[i + 1]
            elif token.startswith(flag + "="):
                value = token[len(flag) + 1 :]
            else:
                continue
            if not value.strip():
                raise InputError(f"{flag} {value!r}: empty path; name a directory (. for this one)")
            check_path_length(value, flag)


def split_list(values: list[str] | None, flag: str, *, whitespace: bool = True) -> list[str]:
    """The items of a list flag: repeated flags, comma- and/or whitespace-separated tokens.

    ``--p0-gpa 1,2 --p0-gpa 3`` and ``--p0-gpa '1 2 3'`` both give ``['1', '2', '3']``;
    with ``whitespace=False`` only commas separate (items are stripped), for lists that
    may hold paths with spaces.
    An empty item (``1,,2``, ``1,``, ``,1``, an empty string) is refused: it is a typo, not a
    value, and silently dropping it would run something the user did not ask for.

    Raises
    ------
    InputError
        One line naming ``flag`` and the token with the empty item.
    """
    from flatcontact.foundation.errors import InputError

    items: list[str] = []
    for token in values or []:
        parts = token.split(",")
        if any(not part.strip() for part in parts):
            raise InputError(
                f"{flag} {token!r}: empty item in the comma-separated list "
                "(expected values separated by single commas, e.g. 0.5,1,2)"
            )
        for part in parts:
            items.extend(part.split() if whitespace else [part.strip()])
    return items


def parse_floats(values: list[str] | None, flag: str, unit: str = "", bounds=None) -> list[float]:
    """The numbers of a list flag (see :func:`split_list`); a non-number, or with ``bounds``
    (:class:`~flatcontact.foundation.numbers.Bounds`) a number outside them, is one line naming ``flag``."""
    from flatcontact.foundation.errors import InputError

    out = []
    for item in split_list(values, flag):
        try:
            out.append(float(item))
        except ValueError:
            what = f"a number{f' in {unit}' if unit else ''}"
            raise InputError(f"{flag}: {item!r} is not {what}") from None
    return out if bounds is None else [bounded(x, flag, bounds) for x in out]


def bounded(value: float, flag: str, bounds) -> float:
    """A float flag's value within ``bounds`` (:class:`~flatcontact.foundation.numbers.Bounds`: finite,
    no subnormal, ``lo..hi``), else one :class:`~flatcontact.foundation.errors.InputError` line
    naming ``flag``, the bounds and the value. For flags that do not pass through a bounded
    setting; a flag that mirrors a setting takes the setting's bounds
    (:func:`setting_bounds`)."""
    from flatcontact.foundation.errors import InputError

    try:
        return bounds.check(value)
    except ValueError as exc:
        raise InputError(f"{flag}: {exc}") from None


def bounded_int(value: int, flag: str, lo: int, hi: int, what: str = "") -> int:
    """An integer flag's value within ``lo..hi``, else one line naming ``flag``."""
    from flatcontact.foundation.errors import InputError

    if not lo <= value <= hi:
        detail = f" ({what})" if what else ""
        raise InputError(f"{flag}: expected an integer from {lo} to {hi}{detail}, got {value}")
    return int(value)


def setting_bounds(model, field: str):
    """The :class:`~flatcontact.foundation.numbers.Bounds` of the bounded float ``field`` of the
    pydantic class ``model`` (a settings section, the recipe, the LJ): a flag that sets the
    same quantity is held to the same bounds."""
    from flatcontact.foundation.numbers import field_bounds

    found = field_bounds(model.model_fields[field])
    if found is None:
        raise TypeError(f"{model.__name__}.{field} is not a bounded float")
    return found


#: The SIGTERMs of the running command and what it said it kept (:func:`say_interrupted`).
STOPPED: dict[str, list] = {"signals": [], "kept": []}


def say_interrupted(kept: str) -> None:
    """A command stopped by Ctrl-C or SIGTERM says what it kept, ``kept`` (one clause, e.g.
    ``"finished work is kept in OUT"``): after Ctrl-C one line ``interrupted; <kept>; rerun the
    same command to resume``; after SIGTERM nothing here, the clause goes into the command's
    one ``error: terminated (SIGTERM)`` line (:func:`flatcontact.cli.main`), so stderr holds one
    line either way."""
    STOPPED["kept"].append(kept)
    if STOPPED["signals"]:
        return
    err_console.print(
        f"interrupted; {kept}; rerun the same command to resume", highlight=False, soft_wrap=True
    )
