"""One loader of ``module:callable`` targets, and CLI ``key=value`` keyword arguments.

Every ASE calculator a user names (whole interface, per slab, bulk) goes through
:func:`load_callable` and :func:`call_factory`: the callable is called with the given keyword
arguments, plus ``atoms=<Atoms>`` if it accepts a parameter named ``atoms`` (ASE calculator
classes such as ``ase.calculators.emt:EMT`` accept it and store a copy; factories such as
``mace.calculators:mace_mp`` or ``flatcontact.ispes.toy:toy_calculator`` take only keywords).
"""

from __future__ import annotations

import importlib
import inspect
import json
from typing import Any

import yaml

from flatcontact.errors import InputError


def load_callable(target: str, what: str = "calculator") -> Any:
    """Import ``"module:attr[.attr]"`` and return the callable (one-line InputError otherwise)."""
    module_name, sep, attr = str(target).partition(":")
    if not sep or not module_name or not attr:
        raise InputError(
            f"{what} '{target}': expected 'module:callable' returning an ASE calculator"
        )
    try:
        obj = importlib.import_module(module_name)
    except Exception as exc:  # any failure while importing user code is the user's to fix
        raise InputError(
            f"{what} '{target}': cannot import module {module_name} ({type(exc).__name__}: {exc})"
        ) from None
    for part in attr.split("."):
        if not hasattr(obj, part):
            raise InputError(f"{what} '{target}': {module_name} has no '{attr}'")
        obj = getattr(obj, part)
    if not callable(obj):
        raise InputError(f"{what} '{target}': '{attr}' is not callable")
    return obj


def accepts_atoms(fn: Any) -> bool:
    """True when ``fn`` has a parameter named ``atoms``."""
    try:
        return "atoms" in inspect.signature(fn).parameters
    except (TypeError, ValueError):
        return False


def call_factory(target: str, atoms=None, kwargs: dict | None = None, what: str = "calculator"):
    """``callable(**kwargs)`` (with ``atoms=atoms`` when it takes ``atoms``): an ASE calculator."""
    fn = load_callable(target, what)
    kwargs = dict(kwargs or {})
    if atoms is not None and "atoms" not in kwargs and accepts_atoms(fn):
        kwargs["atoms"] = atoms
    try:
        return fn(**kwargs)
    except TypeError as exc:
        raise InputError(
            f"{what} '{target}': bad keyword arguments {sorted(kwargs)} ({exc})"
        ) from None


def parse_kwargs(
    items: list[str] | tuple[str, ...] | None, flag: str = "--calculator-kwarg"
) -> dict:
    """``["model=medium", "device=cpu", "default_dtype=float64", "cutoff=5.0"]`` -> a dict.

    Each item is ``key=value``; the value is read as YAML (numbers, booleans, null, lists,
    mappings), so ``cutoff=5`` gives the int 5 and ``name=medium`` the string. The result is
    JSON-able (it enters the model's fingerprint). A malformed item is a one-line
    :class:`InputError` naming ``flag`` and the item.
    """
    out: dict[str, Any] = {}
    for item in items or ():
        key, sep, text = str(item).partition("=")
        key = key.strip()
        if not sep or not key.isidentifier():
            raise InputError(f"{flag} {item!r}: expected key=value with a Python identifier key")
        try:
            value = yaml.safe_load(text) if text.strip() else ""
            json.dumps(value)
        except (yaml.YAMLError, TypeError, ValueError):
            raise InputError(f"{flag} {item!r}: the value is not plain YAML/JSON data") from None
        out[key] = value
    return out
