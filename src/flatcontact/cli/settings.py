"""Flags -> run settings: each command lays its flags over a run configuration and validates it
with the same loader as ``flatcontact run``; errors are translated to the flag the user typed.

A stage's errors name settings paths (``analysis.energy_form``, ``contact.p0_gpa``) or core
parameters; :func:`flag_errors` renames them to the command's flags (``--energy-form``,
``--p0-gpa``), so a YAML user reads the YAML path and a command-line user the flag. The
table settings path -> flag is derived with the options (:func:`flatcontact.cli.options.flags_of`).
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from flatcontact.foundation.errors import InputError

FLAGS_SOURCE = "command-line flags"


def _flag_error(exc: InputError, flag_of: dict[str, str]) -> InputError:
    """A validation error of the flags, with the flag named instead of the config path."""
    text = str(exc).removeprefix(f"{FLAGS_SOURCE}: ")
    where, sep, msg = text.partition(": ")
    field, sep2, rest = msg.partition(": ")  # a section validator naming its field first
    name, eq, value = field.partition("=")  # ... or the field and its value (layers=5)
    if sep2 and f"{where}.{name}" in flag_of:
        if eq:
            return InputError(f"{flag_of[f'{where}.{name}']}={value}: {rest}")
        where, msg = f"{where}.{field}", rest
    for key in sorted(flag_of, key=len, reverse=True):
        if sep and where == key:
            return InputError(f"{flag_of[key]}: {msg}")
        if sep and where.startswith(key + "."):
            return InputError(f"{flag_of[key]} ({where}): {msg}")
    return InputError(f"{FLAGS_SOURCE}: {text}")


def config_source(config: Path | None) -> str:
    """What a refusal of ``config``'s settings names first: the file as the user gave it, or
    ``default config`` (the preset alone), as :func:`flatcontact.config.load_config` does."""
    return "default config" if config is None else str(config)


def resolve_config(
    config: Path | None, preset: str | None, flags: dict[str, Any], flag_of: dict[str, str]
):
    """The :class:`~flatcontact.config.RunConfig` of ``CONFIG`` (or the preset) with ``flags`` laid over.

    ``flags`` holds the flag values as a nested mapping of config sections
    (``{"scan": {"grid": [4, 4]}, "potential": {"intra": "vashishta"}}``). Errors in the file
    name the file and the field path; errors in a flag name the flag (``flag_of``: settings
    path -> flag).
    """
    from flatcontact.config import build_config, load_config, merge_config

    cfg = load_config(config, preset)
    flags = {k: v for k, v in flags.items() if v != {}}
    if not flags:
        return cfg
    merged = merge_config(cfg.to_dict(), flags)
    try:
        return build_config(merged, source=FLAGS_SOURCE)
    except InputError as exc:
        raise _flag_error(exc, flag_of) from None


@contextlib.contextmanager
def flag_errors(flag_of: dict[str, str]) -> Iterator[None]:
    """Re-raise a stage's InputError with settings paths and parameters renamed to flags."""
    from flatcontact.stages._common import rename

    try:
        yield
    except InputError as exc:
        raise InputError(rename(str(exc), flag_of)) from None


def settings_from_flags(data: dict[str, Any], flag_of: dict[str, str]):
    """A validated RunConfig from ``data`` (the flags as config sections) over the preset;
    a bad value is one line naming its flag."""
    from flatcontact.config import build_config

    try:
        return build_config(data, source=FLAGS_SOURCE)
    except InputError as exc:
        raise _flag_error(exc, flag_of) from None
