"""Old forms of a run configuration, read into today's, each with a dated deprecation.

Every old form still loads; each raises a :class:`DeprecationWarning` naming the date it was
deprecated and the key that replaces it (the calculator section only has its date here: the
``--calculator`` flag of ``flatcontact scan`` still builds it):

==========================================  ==========  =====================================
old form                                    deprecated  today
==========================================  ==========  =====================================
``structure`` flat keys a recipe lacks      2026-11-22  the recipe of ``structure.kind``
(``layers``, ``source``, ``file``, ...)                 (dropped where the kind has no field)
``structure.normal_axis: 2``                2026-11-22  the normal along cell vector 3
top-level ``calculator: {target, kwargs}``  2026-11-22  ``potential.calculator``
flat ``contact`` keys (``fit_csv``, ...)    2026-11-25  ``contact.cycle``, ``contact.fit``,
                                                        ``contact.experiment`` (:data:`CONTACT_KEYS`)
==========================================  ==========  =====================================
"""

from __future__ import annotations

import typing
import warnings
from typing import Any

from flatcontact import limits
from flatcontact.config.messages import show
from flatcontact.errors import InputError
from flatcontact.structures.recipe import KINDS, StructureRecipe, parse_recipe

#: When the flat one-model ``structure`` keys gave way to the recipe of ``structure.kind``.
STRUCTURE_KEYS_DEPRECATED = "2026-11-22"
#: When the top-level ``calculator:`` section gave way to ``potential.calculator``.
CALCULATOR_SECTION_DEPRECATED = "2026-11-22"
#: When the flat ``contact`` keys moved into ``contact.cycle``, ``.fit`` and ``.experiment``.
CONTACT_KEYS_DEPRECATED = "2026-11-25"

#: Flat keys of the one-model ``structure`` section (deprecated 2026-11-22) that a recipe
#: kind may lack: dropped when the chosen kind has no such field (``file: null`` of a quartz
#: run, the preset's ``layers``/``source`` under ``kind: file``). ``face_depth_angstrom``
#: goes too: the slab recipe finds the layers from the structure instead of a depth.
STRUCTURE_KEYS = (
    "layers",
    "source",
    "file",
    "gap_angstrom",
    "fmax_ev_per_angstrom",
    "normal_axis",
    "face_depth_angstrom",
)

#: Flat ``contact`` key (deprecated 2026-11-25) -> (sub-section, key) that replaces it.
CONTACT_KEYS = {
    "cycle": ("cycle", "enabled"),
    "model": ("cycle", "model"),
    "cycle_amplitude_fractions": ("cycle", "amplitude_fractions"),
    "cycle_amplitudes_un": ("cycle", "amplitudes_un"),
    "fit_csv": ("fit", "csv"),
    "fit_p0_gpa": ("fit", "p0_gpa"),
    "fit_free": ("fit", "free"),
    "fit_fixed": ("fit", "fixed"),
    "fit_stiffness": ("fit", "stiffness"),
    "experiment_csv": ("experiment", "csv"),
    "experiment_p0_gpa": ("experiment", "p0_gpa"),
    "experiment_stress_measure": ("experiment", "stress_measure"),
}


def _deprecated(old: str, date: str, new: str) -> None:
    warnings.warn(f"{old} is deprecated since {date}: use {new}", DeprecationWarning, stacklevel=4)


def structure_section(value: Any) -> Any:
    """The ``structure`` mapping as a recipe model (:data:`flatcontact.structures.recipe.StructureRecipe`).

    Flat keys of the one-model section that the chosen kind does not have are dropped (a
    :class:`DeprecationWarning` for each); ``normal_axis`` other than 2 is refused (the slab
    recipe takes the normal along cell vector 3).
    """
    if not isinstance(value, dict):
        return value  # a model already, or pydantic's own type error
    data = dict(value)
    kind = data.get("kind", "quartz-dense")
    data["kind"] = kind
    axis = data.pop("normal_axis", None)
    if axis not in (None, 2):
        raise InputError(
            f"structure.normal_axis={axis}: the slab recipe takes the surface normal along cell "
            "vector 3; reorder the file's cell (e.g. ase.build.rotate) and drop normal_axis"
        )
    if axis is not None:
        _deprecated(
            "structure.normal_axis", STRUCTURE_KEYS_DEPRECATED, "the normal along cell vector 3"
        )
    if kind in KINDS:
        models = typing.get_args(typing.get_args(StructureRecipe)[0])
        fields = {m.model_fields["kind"].default: m.model_fields for m in models}[kind]
        for key in STRUCTURE_KEYS:
            if key in data and key not in fields:
                if data.pop(key) is not None:
                    _deprecated(
                        f"structure.{key}",
                        STRUCTURE_KEYS_DEPRECATED,
                        f"the fields of structure kind {kind!r} (dropped)",
                    )
    layers = data.get("layers")
    if isinstance(layers, int | float) and not isinstance(layers, bool):
        limits.check("layers", layers, "structure.layers", "layers per slab")
    return parse_recipe(data)


def calculator_section(data: Any) -> Any:
    """The top-level ``calculator: {target, kwargs}`` as ``potential.calculator`` (scope
    ``interface``); ``data`` unchanged without it.

    Deprecated since 2026-11-22 but not warned about: ``flatcontact scan --calculator`` still
    lays its flag over a configuration in this form.
    """
    if isinstance(data, dict) and "calculator" in data:
        data = dict(data)
        calc = data.pop("calculator")
        if calc is not None:
            if not isinstance(calc, dict):
                raise ValueError(f"calculator: expected a mapping, got {show(calc)}")
            data["potential"] = {"calculator": {**calc, "scope": "interface"}}
    return data


def contact_keys(data: dict, source: str) -> dict:
    """``data`` (a whole configuration mapping) with the flat ``contact`` keys moved into
    ``contact.cycle``, ``contact.fit`` and ``contact.experiment`` (a
    :class:`DeprecationWarning` naming each old key and its new path).

    A key given both flat and nested is refused, naming ``source``. Returns a new mapping; ``data`` is not changed.
    """
    contact = data.get("contact")
    if not isinstance(contact, dict):
        return data
    old = [key for key in contact if key in CONTACT_KEYS]
    if not old or (old == ["cycle"] and not _is_flag(contact["cycle"])):
        return data
    contact = dict(contact)
    for key in old:
        if key == "cycle" and not _is_flag(contact["cycle"]):
            continue  # already the sub-section
        sub, new = CONTACT_KEYS[key]
        value = contact.pop(key)
        block = contact.get(sub)
        if block is None:
            block = {}
        elif not isinstance(block, dict):
            continue  # pydantic names the bad sub-section
        else:
            block = dict(block)
        if new in block:
            raise InputError(
                f"{source}: contact.{key}: given beside contact.{sub}.{new}; "
                f"give contact.{sub}.{new} only"
            )
        block[new] = value
        contact[sub] = block
        _deprecated(f"contact.{key}", CONTACT_KEYS_DEPRECATED, f"contact.{sub}.{new}")
    return {**data, "contact": contact}


def _is_flag(value: Any) -> bool:
    """Whether ``contact.cycle`` is the old on/off flag rather than the sub-section."""
    return not isinstance(value, dict)
