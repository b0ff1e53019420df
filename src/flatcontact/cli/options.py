"""Command-line options derived from the run settings: each setting is declared once.

A command lists the settings paths it exposes (``contact.radius_um``, ``contact.fit.csv``);
:func:`settings_command` gives it one typer option per path, named, typed and documented by
the pydantic field (:mod:`flatcontact.config`), and hands the command the values given as a
nested mapping of settings sections, ready to lay over a configuration. The rename of
settings paths to flags in error messages (:func:`flags_of`) follows from the same list.

The name of a flag is the settings path below its section with ``-`` for ``_`` and ``.``:
``contact.fit.csv`` -> ``--fit-csv``, ``analysis.energy_form`` -> ``--energy-form``,
``report.svg`` -> ``--svg``, ``potential.lj.cutoff_angstrom`` -> ``--lj-cutoff-angstrom``; a
sub-section's ``enabled`` is the sub-section's name (``contact.cycle.enabled`` ->
``--cycle``); a true/false setting has its ``--no-`` form (``--svg/--no-svg``).

Types: a number is a number flag (click refuses ``abc`` in one line); a list is given by
repeating the flag or comma-separating (:func:`~flatcontact.cli.app.split_list`); a fixed
pair is ``--grid 8 8``; a sub-section of numbers is its fields' values in order after one
flag, each shown by its name without the unit (``scan.p_range_gpa``, fields ``lo_gpa``,
``hi_gpa``, ``n``: ``--p-range-gpa LO HI N``, ``--p-range-gpa -0.5 3 6``); a choice or a
union (``direction_deg``: an angle or ``auto``) is text that the settings check. Bounds,
choices and defaults are the field's: a value is validated by the settings model, and an
error names the flag.

One option sets a setting and is declared by its command, not derived: ``analyze
--p-gpa`` (``analysis.p_gpa``, its help text is the field's). Its values may follow the flag
as separate words (``--p-gpa 0.5 1 2``): click gives an option one word, so the others
arrive among ``analyze``'s positional arguments, beside the ISPES file, and the command
sorts numbers from the file (:func:`flatcontact.cli.analyze._split_arguments`). A derived
list option would read only the words given to the flag itself (refusing ``--p-gpa
ispes.nc 1``, which ``analyze`` accepts) and hand the loads to the settings' validation,
which asks for two loads where ``analyze`` needs one. tests/cli/test_config_flags.py holds
it to the setting: what it parses is what the analysis runs with.
"""

from __future__ import annotations

import dataclasses
import functools
import inspect
import types
import typing
from collections.abc import Callable, Iterable
from typing import Annotated, Any, Literal

import typer

from flatcontact.cli.app import parse_floats, split_list
from flatcontact.foundation.errors import InputError

#: Kinds of option a field becomes.
_Kind = Literal[
    "bool", "int", "float", "text", "number-or-text", "floats", "texts", "pair", "record"
]


@dataclasses.dataclass(frozen=True)
class SettingOption:
    """One settings path as a command-line option."""

    path: str  #: the settings path (``contact.fit.csv``)
    flag: str  #: the flag (``--fit-csv``)
    kind: _Kind
    help: str
    unit: str = ""
    metavar: str | None = None
    #: a ``record``'s fields in order: (name, ``int`` or ``float``)
    parts: tuple[tuple[str, type], ...] = ()

    @property
    def name(self) -> str:
        """The Python parameter name of the option (``fit_csv``)."""
        return self.flag.removeprefix("--").replace("-", "_")

    def value(self, given: Any) -> Any:
        """The setting's value from what the flag parsed (a list flag split and read)."""
        if self.kind == "floats":
            return parse_floats(given, self.flag, self.unit)
        if self.kind == "texts":
            return split_list(given, self.flag, whitespace=not self.path.endswith("csv"))
        if self.kind == "pair":
            return list(given)
        if self.kind == "record":
            return {name: value for (name, _), value in zip(self.parts, given, strict=True)}
        if self.kind == "number-or-text":
            value = _number_or_text(given)
            words = (self.metavar or "").split("|")[1:]
            if isinstance(value, str) and value.strip().lower() in words:
                value = value.strip().lower()
            if isinstance(value, str) and value not in words:
                raise InputError(
                    f"{self.flag}: expected a number or {' or '.join(words)}, got {given!r}"
                )
            return value
        return given


def _number_or_text(text: str) -> Any:
    """A union of a number and a word (``direction_deg``: 90 or auto) as the settings read it."""
    try:
        return float(text)
    except ValueError:
        return text


def flag_name(path: str) -> str:
    """The flag of the settings path ``path``: the path below its section (see the module)."""
    parts = path.split(".")[1:]
    if len(parts) > 1 and parts[-1] == "enabled":
        parts = parts[:-1]
    return "--" + "-".join(parts).replace("_", "-")


def _strip(annotation: Any) -> Any:
    """``annotation`` without ``None`` in a union and without ``Annotated`` metadata."""
    if typing.get_origin(annotation) is Annotated:
        return _strip(typing.get_args(annotation)[0])
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(annotation) if a is not type(None)]
        if len(args) == 1:
            return _strip(args[0])
    return annotation


def _record(annotation: Any) -> tuple[tuple[str, type], ...]:
    """The fields (name, ``int`` or ``float``) of a sub-section whose fields are all numbers
    (``scan.p_range_gpa``), else ``()``."""
    from pydantic import BaseModel

    ann = _strip(annotation)
    if not (isinstance(ann, type) and issubclass(ann, BaseModel)):
        return ()
    parts = tuple((name, _strip(f.annotation)) for name, f in ann.model_fields.items())
    return parts if parts and all(t in (int, float) for _, t in parts) else ()


def _kind(annotation: Any) -> _Kind:
    ann = _strip(annotation)
    origin = typing.get_origin(ann)
    if _record(annotation):
        return "record"
    if ann is bool:
        return "bool"
    if ann is int:
        return "int"
    if ann is float:
        return "float"
    if origin is list:
        return "floats" if _strip(typing.get_args(ann)[0]) in (float, int) else "texts"
    if origin is tuple:
        return "pair"
    if origin in (typing.Union, types.UnionType):
        return "number-or-text"  # direction_deg: an angle or auto
    return "text"  # str, a Literal of words


def _metavar(annotation: Any) -> str | None:
    """What the help shows as the value: the words of a choice, NUMBERS / TEXTS for a list."""
    ann = _strip(annotation)
    kind = _kind(annotation)
    if typing.get_origin(ann) is Literal:
        return "|".join(str(a) for a in typing.get_args(ann))
    if kind == "number-or-text":
        words = [w for a in typing.get_args(ann) for w in typing.get_args(_strip(a))]
        return "|".join(["NUMBER", *map(str, words)])
    if kind == "record":
        return " ".join(_part_name(name, ann.model_fields[name]) for name, _ in _record(ann))
    return {
        "floats": "NUMBERS",
        "texts": "TEXTS",
        "float": "NUMBER",
        "int": "INTEGER",
        "text": "TEXT",
        "pair": "INTEGER INTEGER",
    }.get(kind)


def _part_name(name: str, info: Any) -> str:
    """A record field as the help shows it: its name without the unit (``lo_gpa`` -> ``LO``)."""
    from flatcontact.foundation.numbers import field_bounds

    if field_bounds(info) is not None and "_" in name:
        name = name.rpartition("_")[0]
    return name.upper()


def _default_text(default: Any) -> str:
    if isinstance(default, list | tuple):
        return ",".join(f"{v:g}" if isinstance(v, float) else str(v) for v in default) or "none"
    if isinstance(default, bool):
        return "yes" if default else "no"
    if default is None:
        return "none"
    return f"{default:g}" if isinstance(default, float) else str(default)


def setting_options(
    paths: Iterable[str], defaults: dict[str, Any] | None = None
) -> list[SettingOption]:
    """The options of the settings ``paths``.

    ``defaults``: the value each path takes when its flag is not given, for the help text;
    a path absent from it says ``default: the configuration's`` when ``defaults`` is None
    (a command laid over a configuration) and the field's default otherwise.
    """
    from flatcontact.config.paths import field_at
    from flatcontact.foundation.numbers import field_bounds

    out = []
    for path in paths:
        _, info = field_at(path)
        bounds = field_bounds(info)
        what = (info.description or "").rstrip(".")
        if defaults is None:
            said = "the configuration's"
        else:
            said = _default_text(defaults.get(path, info.get_default(call_default_factory=True)))
        text = f"{path}: {what}. Default: {said}."
        out.append(
            SettingOption(
                path,
                flag_name(path),
                _kind(info.annotation),
                text.replace("[", "(").replace("]", ")"),  # no rich markup in the help
                bounds.unit if bounds is not None else "",
                _metavar(info.annotation),
                _record(info.annotation),
            )
        )
    return out


def flags_of(options: Iterable[SettingOption]) -> dict[str, str]:
    """Settings path -> flag, to name the flag in an error about the path."""
    return {o.path: o.flag for o in options}


def _parameter(option: SettingOption) -> inspect.Parameter:
    py_type: Any = {
        "bool": bool | None,
        "int": int | None,
        "float": float | None,
        "text": str | None,
        "number-or-text": str | None,
        "floats": list[str] | None,
        "texts": list[str] | None,
        "pair": tuple[int, int] | None,
        "record": tuple[tuple(t for _, t in option.parts)] | None,
    }[option.kind]
    decls = (
        [f"{option.flag}/--no-{option.flag.removeprefix('--')}"]
        if option.kind == "bool"
        else [option.flag]
    )
    return inspect.Parameter(
        option.name,
        inspect.Parameter.KEYWORD_ONLY,
        default=None,
        annotation=Annotated[
            py_type,
            typer.Option(*decls, help=option.help, show_default=False, metavar=option.metavar),
        ],
    )


def given_settings(options: Iterable[SettingOption], values: dict[str, Any]) -> dict[str, Any]:
    """The options given (not None in ``values``, by parameter name) as a nested mapping of
    settings sections: ``{"contact": {"fit": {"csv": [...]}}}``."""
    out: dict[str, Any] = {}
    for option in options:
        given = values.get(option.name)
        if given is None:
            continue
        holder = out
        *parents, leaf = option.path.split(".")
        for part in parents:
            holder = holder.setdefault(part, {})
        holder[leaf] = option.value(given)
    return out


def settings_command(options: list[SettingOption]) -> Callable[[Callable], Callable]:
    """Decorate a command function taking ``settings`` (the mapping of
    :func:`given_settings`) and its own parameters: typer sees its own parameters and one
    option per entry of ``options`` (after the arguments, before its other options)."""

    def decorate(func: Callable) -> Callable:
        own = inspect.signature(func, eval_str=True)
        params = [p for p in own.parameters.values() if p.name != "settings"]
        names = {p.name for p in params}
        clash = [o.flag for o in options if o.name in names]
        if clash:
            raise TypeError(f"{func.__name__}: options {clash} clash with its own parameters")
        arguments = [p for p in params if p.default is inspect.Parameter.empty]
        rest = [
            p.replace(kind=inspect.Parameter.KEYWORD_ONLY)
            for p in params
            if p.default is not inspect.Parameter.empty
        ]

        @functools.wraps(func)
        def command(*args: Any, **kwargs: Any) -> Any:
            values = {o.name: kwargs.pop(o.name, None) for o in options}
            return func(*args, settings=given_settings(options, values), **kwargs)

        command.__signature__ = own.replace(
            parameters=[*arguments, *(_parameter(o) for o in options), *rest]
        )
        command.__annotations__ = {}
        del command.__wrapped__  # typer reads the signature above, not the function's
        return command

    return decorate
