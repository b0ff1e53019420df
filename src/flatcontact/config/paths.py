"""The dotted paths of the run settings (``contact.fit.csv``) and the field each one names.

One walk over :class:`~flatcontact.config.run.RunConfig`'s pydantic fields, descending into
every sub-model (a section, the interaction model's ``lj``, each structure recipe: a field
several recipes have is the first one's, the default ``quartz-dense`` recipe first); what the command line derives
its options from (:mod:`flatcontact.cli.options`) and what an unknown key's message
suggests instead (:func:`suggestion`).
"""

from __future__ import annotations

import difflib
import functools
import types
import typing
from typing import Any

from pydantic import BaseModel
from pydantic.fields import FieldInfo

from flatcontact.config.run import RunConfig


def _sub_models(annotation: Any) -> list[type[BaseModel]]:
    """The pydantic models of a field typed ``Model``, ``Model | None`` or a union of models
    (the structure recipes, by ``kind``), else none."""
    if typing.get_origin(annotation) is typing.Annotated:
        return _sub_models(typing.get_args(annotation)[0])
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        members = [a for a in typing.get_args(annotation) if a is not type(None)]
        models = [m for a in members for m in _sub_models(a)]
        return models if len(models) == len(members) else []
    return []


def _walk(model: type[BaseModel], prefix: str, out: dict[str, tuple[type[BaseModel], str]]):
    for name, info in model.model_fields.items():
        path = f"{prefix}{name}"
        out.setdefault(path, (model, name))  # a field of several recipes: the first's
        for sub in _sub_models(info.annotation):
            _walk(sub, path + ".", out)


@functools.cache
def settings_paths() -> dict[str, tuple[type[BaseModel], str]]:
    """Every dotted settings path -> (the model that declares it, the field name)."""
    out: dict[str, tuple[type[BaseModel], str]] = {}
    _walk(RunConfig, "", out)
    return out


def field_at(path: str) -> tuple[type[BaseModel], FieldInfo]:
    """The model and the :class:`~pydantic.fields.FieldInfo` of the settings path ``path``.

    Raises
    ------
    KeyError
        ``path`` names no setting.
    """
    model, name = settings_paths()[path]
    return model, model.model_fields[name]


def suggestion(path: str) -> str | None:
    """The setting an unknown key ``path`` (``contact.fit_csv``) probably means: one spelled
    the same with dots as underscores (``contact.fit.csv``), one of the same name one level
    down (``calculator`` -> ``potential.calculator``), or a close spelling at its level
    (``contact.work_of_adhesion_j_m2`` -> ``contact.work_of_adhesion_j_per_m2``); None, also
    for a key of another structure recipe (``structure.layers`` under ``kind: slab``)."""
    if path in settings_paths():
        return None  # a setting of another variant (a recipe kind that has it): nothing closer
    parent, _, key = path.rpartition(".")
    prefix = f"{parent}." if parent else ""
    below = [p for p in settings_paths() if p.startswith(prefix) and p != path]
    for p in below:
        if p[len(prefix) :].replace(".", "_") == key:
            return p
    for p in below:
        if p[len(prefix) :].count(".") == 1 and p.rpartition(".")[2] == key:
            return p
    level = [p[len(prefix) :] for p in below if "." not in p[len(prefix) :]]
    close = difflib.get_close_matches(key, level, n=1, cutoff=0.75)
    return f"{prefix}{close[0]}" if close else None
