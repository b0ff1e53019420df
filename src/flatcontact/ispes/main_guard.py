"""Whether local worker processes can start from here: a script's missing ``__main__`` guard.

Local workers are started with ``spawn`` (:mod:`flatcontact.ispes.executors`: no fork of a
process that holds a LAMMPS instance or MPI). A spawned worker imports the parent's main
script again as ``__mp_main__`` before it runs a task; a script that calls flatcontact at
module level, outside ``if __name__ == "__main__":``, therefore runs the whole study again in
every worker, which meets the parent's run-directory lock and dies, and the parent sees
``BrokenProcessPool`` (issue 32: following docs/tutorial.md literally in a plain script).

An ASE user writes scripts without that guard (ASE's own calculators and optimisers never
start processes), so the scan does not refuse such a script: :func:`unguarded_script` finds
it and :func:`flatcontact.ispes.executors.make_executor` runs the points in the driver
(serially), with one :class:`SerialFallback` warning naming the guard that would give the
workers back. Nothing else is affected: a notebook, ``python -c``, the REPL and standard
input have no main file for a worker to import (they get their workers), and so do the
``flatcontact`` command, ``python -m flatcontact`` and every script whose call sits inside
the guard.
"""

from __future__ import annotations

import ast
import logging
import sys
import warnings
from pathlib import Path
from types import FrameType


class SerialFallback(UserWarning):
    """Worker processes were asked for from a script without a ``__main__`` guard; the
    points run in the driver process instead."""


def _is_main_test(test: ast.expr) -> bool:
    """``__name__ == "__main__"`` (either order)."""
    if not (isinstance(test, ast.Compare) and len(test.ops) == 1):
        return False
    if not isinstance(test.ops[0], ast.Eq):
        return False
    sides = [test.left, test.comparators[0]]
    names = [s for s in sides if isinstance(s, ast.Name) and s.id == "__name__"]
    consts = [s for s in sides if isinstance(s, ast.Constant) and s.value == "__main__"]
    return len(names) == 1 and len(consts) == 1


def guarded_lines(source: str) -> list[tuple[int, int]]:
    """The line ranges (first, last; 1-based, inclusive) of the bodies of the module-level
    ``if __name__ == "__main__":`` blocks of ``source`` (empty if it does not parse)."""
    try:
        tree = ast.parse(source)
    except (SyntaxError, ValueError):
        return []
    out = []
    for node in tree.body:
        if isinstance(node, ast.If) and _is_main_test(node.test) and node.body:
            out.append((node.body[0].lineno, node.body[-1].end_lineno or node.body[-1].lineno))
    return out


def _module_frame(main_globals: dict) -> FrameType | None:
    """The frame running the main module's top level, if it is on the current stack."""
    frame = sys._getframe(1)
    while frame is not None:
        if frame.f_code.co_name == "<module>" and frame.f_globals is main_globals:
            return frame
        frame = frame.f_back
    return None


def unguarded_script() -> Path | None:
    """The main script's path when this call comes from its top level outside an
    ``if __name__ == "__main__":`` block (a spawned worker would import it and run the
    call again), else None.

    None also when there is no main file (notebook, REPL, ``python -c``, standard input: a
    worker imports nothing of the parent's), when the call does not come from the main
    module's top level (a thread, a callback: nothing to judge) and when the script cannot
    be read or parsed (never a false alarm).
    """
    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    if main is None or not path:
        return None
    frame = _module_frame(vars(main))
    if frame is None:
        return None
    try:
        source = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None
    line = frame.f_lineno
    if any(lo <= line <= hi for lo, hi in guarded_lines(source)):
        return None
    return Path(path)


def serial_instead(workers: int | None) -> bool:
    """Whether worker processes asked for (``workers`` of them, None = one per core) must
    run in the driver instead, because the caller is an unguarded script
    (:func:`unguarded_script`); warns once per call (:class:`SerialFallback`) when so."""
    script = unguarded_script()
    if script is None:
        return False
    line = (
        f"{script.name}: runs flatcontact outside 'if __name__ == \"__main__\":', so worker "
        "processes (which import the script again) cannot start; the points run serially in "
        "this process. Put the calls under that guard to use "
        + ("one worker per core" if workers is None else f"{workers} workers")
    )
    logging.getLogger("flatcontact.scan").warning("%s", line)
    warnings.warn(line, SerialFallback, stacklevel=3)
    return True
