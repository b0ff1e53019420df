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
import math
from typing import Any

import yaml

from flatcontact.foundation.errors import InputError


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


def is_calculator(obj: Any) -> bool:
    """True for an ASE calculator: an object with callable ``get_potential_energy`` and
    ``get_forces`` (what :class:`ase.Atoms` asks of ``atoms.calc``; ASE's own classes and
    third-party ones that do not subclass them alike); a class is not one (its methods are
    callable too, unbound)."""
    return not isinstance(obj, type) and all(
        callable(getattr(obj, name, None)) for name in ("get_potential_energy", "get_forces")
    )


def call_factory(target: str, atoms=None, kwargs: dict | None = None, what: str = "calculator"):
    """``callable(**kwargs)`` (with ``atoms=`` a copy of ``atoms`` when it takes ``atoms``): an
    ASE calculator. ``atoms`` itself is not modified (an ASE ``Calculator`` class given atoms
    sets their ``calc``; here it sets the copy's).

    Raises
    ------
    InputError
        One line naming ``target`` when a keyword argument is not finite data, the callable
        refuses its arguments or fails (the exception's type and message), or returns
        something that is not an ASE calculator (``None``, a number, a class). A memory or
        disk failure is passed on unchanged (the command line names the limit).
    """
    fn = load_callable(target, what)
    kwargs = dict(kwargs or {})
    check_finite_data(kwargs, f"{what} '{target}' keyword argument")
    if atoms is not None and "atoms" not in kwargs and accepts_atoms(fn):
        # a copy: an ASE Calculator class attaches itself to the atoms it is given
        # (``atoms.calc = self``), and the caller's atoms (the scan's reference, pickled to
        # every worker task) must not carry the calculator
        kwargs["atoms"] = atoms.copy()
    try:
        made = fn(**kwargs)
    except TypeError as exc:
        raise InputError(
            f"{what} '{target}': bad keyword arguments {sorted(kwargs)} ({exc})"
        ) from None
    except (InputError, MemoryError, OSError):
        raise
    except Exception as exc:  # the user's factory failed: its message, in one line
        said = " ".join(str(exc).split())[:200]
        raise InputError(f"{what} '{target}' failed: {type(exc).__name__}: {said}") from None
    if not is_calculator(made):
        raise InputError(
            f"{what} '{target}' returned {_describe(made)}, expected an ASE calculator "
            "(an object with get_potential_energy and get_forces)"
        )
    return made


def _describe(obj: Any) -> str:
    """``None``, ``a float (1.0)``, ``the class EMT``: what a factory returned, briefly."""
    if obj is None:
        return "None"
    if isinstance(obj, type):
        return f"the class {obj.__name__} (call it: a factory returns an instance)"
    text = repr(obj)
    return f"a {type(obj).__name__} ({text[:40]}{'...' if len(text) > 40 else ''})"


def _non_finite(item: Any) -> bool:
    """NaN or ±inf, as a float or as a string a factory's ``float()`` would read so
    (``"nan"``, ``"-inf"``: plain YAML reads ``x=nan`` as a string)."""
    if isinstance(item, float):
        return not math.isfinite(item)
    if isinstance(item, str) and item.strip().lower().lstrip("+-") in ("nan", "inf", "infinity"):
        return True
    return False


def check_finite_data(value: Any, name: str) -> None:
    """Refuse NaN or ±inf anywhere in keyword-argument data (numbers, lists, mappings), in
    one line naming ``name`` and the key path (``cutoff``, ``params.sigma``)."""

    def walk(item: Any, path: str) -> None:
        if _non_finite(item):
            raise InputError(f"{name} {path}: expected a finite number, got {item!r}")
        if isinstance(item, dict):
            for key, sub in item.items():
                walk(sub, f"{path}.{key}" if path else str(key))
        elif isinstance(item, list | tuple):
            for i, sub in enumerate(item):
                walk(sub, f"{path}[{i}]")

    walk(value, "")


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
        check_finite_data({key: value}, flag)
        out[key] = value
    return out
