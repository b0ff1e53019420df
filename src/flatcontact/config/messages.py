"""The wording of settings errors: one line ``<source>: <dotted.path>: expected ..., got <value>``.

Pydantic's validation errors are turned into that line by :func:`one_line`; every section
validator words its own messages with :func:`show` for the offending value.
"""

from __future__ import annotations

import json
from typing import Any

from pydantic import ValidationError

from flatcontact.foundation.errors import InputError


def show(value: Any) -> str:
    """``value`` as the user wrote it (JSON where possible: tuples as lists)."""
    if isinstance(value, tuple):
        value = list(value)
    try:
        return json.dumps(value)
    except TypeError:
        return repr(value)


#: Pydantic error type -> the message of the one-line error (``ctx`` fields formatted in).
_MESSAGES = {
    "greater_than": "expected a value > {gt}",
    "greater_than_equal": "expected a value >= {ge}",
    "less_than": "expected a value < {lt}",
    "less_than_equal": "expected a value <= {le}",
    "float_parsing": "expected a number",
    "float_type": "expected a number",
    "finite_number": "expected a finite number",
    "int_parsing": "expected an integer",
    "int_type": "expected an integer",
    "int_from_float": "expected an integer",
    "bool_parsing": "expected true or false",
    "bool_type": "expected true or false",
    "string_type": "expected a string",
    "list_type": "expected a list",
    "tuple_type": "expected a list",
    "dict_type": "expected a mapping",
    "model_type": "expected a mapping",
    "model_attributes_type": "expected a mapping",
    "literal_error": "expected {expected}",
    "extra_forbidden": "unknown field",
    "missing": "required field missing",
}


def one_line(exc: ValidationError, source: str, meant=None) -> InputError:
    """The first pydantic error as ``<source>: <dotted.path>: expected ..., got <value>``.

    ``meant``: for an unknown key, a function of its dotted path giving the setting it
    probably meant (:func:`flatcontact.config.paths.suggestion`), appended as
    ``(did you mean ...?)``.
    """

    def _meant(path: str) -> str:
        near = meant(path) if meant is not None else None
        return f" (did you mean {near}?)" if near else ""

    first = exc.errors()[0]
    # union members (direction_deg: float | 'auto'; refine.settings: 'auto' | list[...]) name
    # their type in the path: drop them
    loc = [
        str(p)
        for p in first.get("loc", ())
        if not str(p).startswith(("function-", "literal[", "list[", "tuple[", "dict["))
        and str(p) not in ("float", "int", "str", "bool")
    ]
    where = ".".join(loc)
    kind = first.get("type", "")
    if kind in _MESSAGES:
        try:
            msg = _MESSAGES[kind].format(**first.get("ctx", {}))
        except (KeyError, IndexError):
            msg = str(first.get("msg", "invalid"))
        if kind not in ("extra_forbidden", "missing"):
            msg += f", got {show(first.get('input'))}"
        if kind == "extra_forbidden":
            msg += _meant(where)
    else:
        msg = str(first.get("msg", "invalid")).removeprefix("Value error, ")
        field, sep, rest = msg.partition(": ")
        if sep and where and (field == where or field.startswith(f"{where}.")):
            where, msg = field, rest  # a sub-model's own one line naming its whole path
            if msg == "unknown field":
                msg += _meant(where)
        elif sep and field.isidentifier() and field.islower() and where:
            where, msg = f"{where}.{field}", rest  # a model check naming its field
        if where == "potential" and msg.startswith("potential "):  # InteractionModel's InputError
            return InputError(f"{source}: potential.{msg.removeprefix('potential ')}")
    return InputError(f"{source}: {where}: {msg}" if where else f"{source}: {msg}")
