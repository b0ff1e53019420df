"""Helpers shared by the stages: figures in the configured formats, captured warnings."""

from __future__ import annotations

import contextlib
import re
import warnings
from collections.abc import Iterator
from pathlib import Path


def figure_formats(svg: bool) -> tuple[str, ...]:
    """``("png", "svg")`` or ``("png",)``: the formats of ``report.svg``."""
    return ("png", "svg") if svg else ("png",)


def save(fig, folder: Path, stem: str, svg: bool) -> list[Path]:
    """Save ``fig`` as ``folder/stem.png`` (+ ``.svg``) atomically and close it."""
    from flatcontact.plots import save_figure

    return save_figure(fig, folder / stem, figure_formats(svg))


@contextlib.contextmanager
def captured(category: type[Warning]) -> Iterator[list[warnings.WarningMessage]]:
    """Collect the warnings of ``category`` raised inside the block (each one, not once per
    location); other warnings are passed on to the caller's filters unchanged.

    The stages store what they collect in their JSON (``warnings``), so the CLI and the run
    report the same list.
    """
    kept: list[warnings.WarningMessage] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", category)
        yield kept
    for w in caught:
        if issubclass(w.category, category):
            kept.append(w)
        else:
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)


def rename(message: str, names: dict[str, str]) -> str:
    """``message`` with each parameter name of ``names`` replaced by what the user wrote.

    Whole names only (``p_gpa`` is not found inside ``analysis.p_gpa``, ``p0_gpa`` or a file
    path), longest first, each position once.
    """
    if not names:
        return message
    keys = sorted(names, key=len, reverse=True)
    # a name inside a longer name, a dotted path or a file path (…/p_gpa/x.nc) is left alone
    pattern = re.compile(
        r"(?<![\w.\-/\\])(" + "|".join(map(re.escape, keys)) + r")(?![\w\-/\\]|\.\w)"
    )
    return pattern.sub(lambda m: names[m.group(1)], message)


@contextlib.contextmanager
def renamed_errors(names: dict[str, str]) -> Iterator[None]:
    """Re-raise an :class:`~flatcontact.foundation.errors.InputError` of the block with the parameter
    names of ``names`` translated (core parameter -> settings path, or settings path -> flag)."""
    from flatcontact.foundation.errors import InputError

    try:
        yield
    except InputError as exc:
        raise InputError(rename(str(exc), names)) from None
