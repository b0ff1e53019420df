"""The ``flatcontact`` command line.

``main`` runs the typer app and turns every user mistake into a single ``error: ...`` line
on stderr with exit status 2 (the status click uses for usage errors), never a traceback
or a boxed multi-line message:

- :class:`~flatcontact.foundation.errors.InputError` raised by a command (bad values, files, configs);
- a full disk (``ENOSPC``, ``EDQUOT``) in any stage: one line saying to free space and
  rerun (the rerun resumes: stage records and scan points are written atomically);
- a resource limit of the process: the file-size limit (``ulimit -f``, ``EFBIG``) and the
  memory limit (``ulimit -v``, ``MemoryError``), one line naming the limit and the file;
- SIGTERM: raised as :class:`Terminated` (a ``KeyboardInterrupt``) in the main thread, so
  every stage and standalone command unwinds as on Ctrl-C: temporary files are removed
  (``.<name>.<random>.part``), the point store commits; one line, exit status 143 (the
  console script's entry, :func:`flatcontact.__main__.main`, says the same line while this
  module is still being imported);
- Python warnings: flatcontact's own (analysis diagnostics, dated deprecations) as one
  ``warning:`` line each; the libraries' numerical warnings (numpy, scipy, ASE) into the
  run log and one summary line after a successful command
  (:mod:`flatcontact.cli.warning_lines`);
- click's own usage errors (``--layers abc``, a missing argument, an unknown option),
  printed as click's one-line message followed by where to find help.

Tests call ``main([...])`` and catch ``SystemExit`` (0 on success, as in click's
standalone mode).
"""

from __future__ import annotations

import os

# One BLAS thread per process, set before numpy is first imported (a user's setting wins):
# a scan runs one worker process per core, and OpenBLAS's threads on the small matrices of an
# L-BFGS step only contend with them (a 100-pair step took 18 ms threaded on a loaded
# 2-core machine against 0.2 ms on one thread). Worker processes inherit it.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import contextlib
import errno
import logging
import resource
import signal
import sqlite3
import sys
from concurrent.futures.process import BrokenProcessPool
from typing import Annotated

import typer

from flatcontact import __version__
from flatcontact.cli import memory_floor  # noqa: F401  (refuses a too low ulimit -v)
from flatcontact.cli.app import STOPPED, app, check_out_flags, console, print_error
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import remove_live_temporaries
from flatcontact.foundation.interrupts import (
    INTERRUPTED_LINE,
    TERMINATED_LINE,
    TERMINATED_STATUS,
)

try:  # registers the sub-commands; their modules load numpy and the settings
    from flatcontact.cli import commands as _commands  # noqa: F401
except ImportError as _exc:  # numpy's libraries under a memory limit that leaves no room
    if not any(w in str(_exc).lower() for w in ("failed to map segment", "cannot allocate")):
        raise
    _line = (str(_exc).strip().splitlines() or [""])[-1][:200]
    sys.stderr.write(
        f"error: out of memory loading the numerical libraries ({_line}); raise the memory "
        "limit of this process (ulimit -v) and rerun\n"
    )
    sys.exit(2)

__all__ = ["app", "main", "usage_error_line"]


def _print_version(value: bool) -> None:
    if value:
        console.print(__version__, highlight=False)
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option(
            "--version",
            help="Print the flatcontact version and exit.",
            is_eager=True,
            callback=_print_version,
        ),
    ] = False,
) -> None:
    """Onset of sliding of a Hertzian asperity with an atomically flat crystalline contact."""


@app.command("version")
def version_command() -> None:
    """Print the flatcontact version."""
    console.print(__version__, highlight=False)


def usage_error_line(exc: Exception) -> str:
    """One line for a typer/click usage error: its message (whitespace collapsed) and where the help is."""
    format_message = getattr(exc, "format_message", None)
    message = " ".join((format_message() if callable(format_message) else str(exc)).split())
    ctx = getattr(exc, "ctx", None)
    if ctx is not None:
        message += f" (see '{ctx.command_path} --help')"
    return message


#: errno values of a full disk or an exhausted quota.
_DISK_FULL = (errno.ENOSPC, errno.EDQUOT)


def disk_full_line(exc: OSError) -> str:
    """One line for a write that failed because the disk (or the quota) is full."""
    where = f" writing {exc.filename}" if exc.filename else ""
    soft, _ = resource.getrlimit(resource.RLIMIT_FSIZE)
    limit = (
        f" or the file size limit of this process ({soft} bytes, ulimit -f) reached"
        if soft != resource.RLIM_INFINITY
        else ""
    )
    return (
        f"no space left on the device{where}{limit} ({exc.strerror or 'disk full'}); free some "
        "space and rerun the same command: finished stages and scan points are kept"
    )


def _file_size_limited() -> bool:
    """Whether this process runs under a file-size limit (``ulimit -f``)."""
    return resource.getrlimit(resource.RLIMIT_FSIZE)[0] != resource.RLIM_INFINITY


def file_size_line(exc: OSError) -> str:
    """One line for a write stopped by the process's file-size limit (``ulimit -f``)."""
    where = f" writing {exc.filename}" if exc.filename else ""
    soft = resource.getrlimit(resource.RLIMIT_FSIZE)[0]
    limit = f" (ulimit -f: {soft} bytes)" if soft != resource.RLIM_INFINITY else ""
    return (
        f"file size limit of this process{limit} reached{where} "
        f"({exc.strerror or 'File too large'}); "
        "raise it (ulimit -f) and rerun the same command: finished stages and scan points are kept"
    )


#: What the dynamic loader says when the memory limit (ulimit -v) leaves no room for a library.
_NO_ROOM = ("failed to map segment", "cannot allocate memory", "out of memory")


def _first_line(exc: BaseException) -> str:
    return (str(exc).strip().splitlines() or [""])[0][:200]


def _starved(exc: BaseException) -> bool:
    """Whether ``exc`` (an ImportError, an OSError of ctypes) is a library the memory limit
    did not let load (the loader's words), not a missing module or another I/O fault."""
    if isinstance(exc, OSError) and exc.errno == errno.ENOMEM:
        return True
    text = str(exc).lower()
    return any(words in text for words in _NO_ROOM)


def memory_line(exc: MemoryError) -> str:
    """One line for an allocation refused by the memory limit (``ulimit -v``) or the machine."""
    said = " ".join(str(exc).split())
    detail = f" ({said})" if said else ""
    return (
        f"out of memory{detail}; raise the memory limit (ulimit -v) or run a smaller study, "
        "then rerun the same command: finished stages and scan points are kept"
    )


class Terminated(KeyboardInterrupt):
    """SIGTERM in a flatcontact command: unwinds like Ctrl-C (every ``finally`` runs)."""


@contextlib.contextmanager
def sigterm_unwinds():
    """While a command runs, SIGTERM raises :class:`Terminated` in the main thread; yields a
    list that holds the signal once it came. A process forked from this one dies of SIGTERM
    as before (a pool's workers); nothing changes where SIGTERM already has a handler."""
    from flatcontact.foundation.interrupts import raise_on_sigterm

    got: list[int] = STOPPED["signals"]
    got.clear()
    STOPPED["kept"].clear()

    def terminated(signum: int) -> Terminated:
        got.append(signum)
        return Terminated("SIGTERM")

    old = raise_on_sigterm(terminated)
    try:
        yield got
    finally:
        if old is not None:
            signal.signal(signal.SIGTERM, old)


def main(argv: list[str] | None = None) -> None:
    """Entry point of the ``flatcontact`` console script."""
    from flatcontact.cli.app import print_warning
    from flatcontact.cli.warning_lines import captured_warnings

    # a full disk under the run log must not print logging's own traceback on stderr
    logging.raiseExceptions = False
    with captured_warnings(print_warning) as lines:
        code = _run(argv)
        if code == 0 and lines.summary() is not None:
            print_warning(lines.summary())
    sys.exit(code)


def _run(argv: list[str] | None) -> int:
    """Run the command; its exit status (an error is printed as one line here)."""
    with sigterm_unwinds() as got:
        try:
            code = _command(argv)
        except KeyboardInterrupt:
            code = 130
        if code == 130 or got:  # what the unwinding could not reach (fileio's registry)
            remove_live_temporaries()
        # typer turns a KeyboardInterrupt it sees into exit status 130 without a word
        if code == 130 and not got and not STOPPED["kept"]:
            # Ctrl-C in a command that does not say it itself
            print_error(INTERRUPTED_LINE)
            return 130
        if got:  # the one line: what the command kept (say_interrupted) and the status
            kept = "; ".join(STOPPED["kept"]) or "finished work kept"
            print_error(TERMINATED_LINE.format(kept=kept))
            return TERMINATED_STATUS
        return code


def worker_died_line(exc: BaseException) -> str:
    """The one line for a worker process that died mid-run: what happened, that the finished
    work is kept (the point store, the probe's units, a study's finished jobs), how to go on;
    SIGKILL with the out-of-memory killer's usual cure."""
    line = f"{exc}. The finished work is kept: run the same command again to resume"
    if "SIGKILL" in str(exc):
        line += (
            " (SIGKILL is what the system's out-of-memory killer sends: fewer workers need"
            " less memory)"
        )
    return line


def _command(argv: list[str] | None) -> int:
    """The command's exit status; every refusal and resource fault one line."""
    try:
        check_out_flags([str(a) for a in (sys.argv[1:] if argv is None else argv)])
        rv = app(args=argv, standalone_mode=False, prog_name="flatcontact")
    except InputError as exc:
        print_error(exc)
        return 2
    except OSError as exc:
        if exc.errno == errno.EFBIG:
            print_error(file_size_line(exc))
            return 2
        if _starved(exc):  # ctypes could not map LAMMPS's library under ulimit -v
            print_error(memory_line(MemoryError(f"loading a shared library: {_first_line(exc)}")))
            return 2
        if exc.errno not in _DISK_FULL:
            raise
        print_error(disk_full_line(exc))
        return 2
    except MemoryError as exc:  # numpy's _ArrayMemoryError included
        print_error(memory_line(exc))
        return 2
    except ImportError as exc:
        # a shared library (numpy's BLAS, LAMMPS) the memory limit leaves no room to map
        if not _starved(exc):
            raise
        name = getattr(exc, "name", None) or "a shared library"
        print_error(memory_line(MemoryError(f"loading {name}: {_first_line(exc)}")))
        return 2
    except sqlite3.OperationalError as exc:  # the scan's point store on a full disk
        if "full" in str(exc):
            print_error(disk_full_line(OSError(errno.ENOSPC, str(exc))))
            return 2
        if "disk I/O error" in str(exc) and _file_size_limited():
            # SQLite reports a write past ulimit -f (its write-ahead log grows to 4 MB before
            # a checkpoint) as an I/O error, not as EFBIG
            print_error(file_size_line(OSError(errno.EFBIG, f"SQLite: {exc}")))
            return 2
        raise
    except BrokenProcessPool as exc:  # a worker process died (a crash, the OOM killer)
        print_error(worker_died_line(exc))
        return 1
    except typer.TyperException as exc:  # typer's (vendored click's) usage errors
        code = getattr(exc, "exit_code", 2)
        if type(exc).__name__ != "NoArgsIsHelpError":  # that one has printed the help already
            print_error(usage_error_line(exc))
        return code
    except typer.Abort:
        print_error("aborted")
        return 1
    return rv if isinstance(rv, int) else 0
