"""The numeric domain of every float a user gives: finite, a normal double, within bounds.

A foundation module outside ``config`` so that the data models the settings hold (the
structure recipe, :mod:`flatcontact.structures.recipe`) can use it without importing the
settings package that imports them.

A float field of the settings is typed with :func:`physical`: ``radius_um: physical(1e-3,
1e4, "µm")``. The value must be finite (no NaN or inf), a normal double (no subnormal such as
``1e-320``, whose reciprocal overflows) and inside closed bounds that no physical use reaches
but that keep every quantity derived from it (areas, forces, energies, their ratios) far from
overflow and underflow. The bounds are part of the schema: :class:`~flatcontact.config.section.Section`
appends them to the field's description, so ``flatcontact config --show-default`` prints them,
and a value outside them is one line naming the field, the bounds and the value.

``or_zero=True`` also admits exactly 0 below a positive lower bound: "none" (no adhesion,
no offset) is physics, 1e-300 J/m² is not (it drives a cohesive-zone width to overflow).
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from typing import Annotated, Any, get_args

from pydantic import AfterValidator

#: The smallest positive normal double; nonzero magnitudes below it are subnormal.
NORMAL_MIN = sys.float_info.min


@dataclass(frozen=True)
class Bounds:
    """Closed bounds ``lo <= x <= hi`` (in ``unit``) of a float field; ``or_zero``: or x == 0."""

    lo: float
    hi: float
    unit: str = ""
    or_zero: bool = False

    def text(self) -> str:
        """The bounds as printed in descriptions and errors: ``1e-03..1e+04 µm``."""
        unit = f" {self.unit}" if self.unit else ""
        zero = " or 0" if self.or_zero else ""
        return f"{self.lo:g}..{self.hi:g}{unit}{zero}"

    def expected(self) -> str:
        """The bounds as an error states them: ``expected 0.001 <= value <= 10000 µm``."""
        unit = f" {self.unit}" if self.unit else ""
        zero = " (or 0)" if self.or_zero else ""
        return f"expected {self.lo:g} <= value <= {self.hi:g}{unit}{zero}"

    def check(self, value: float) -> float:
        """``value`` as a float if finite, normal and within bounds; else ValueError."""
        x = float(value)
        if not math.isfinite(x):
            raise ValueError(f"{self.expected()}, got {value!r}")
        if x != 0.0 and abs(x) < NORMAL_MIN:
            raise ValueError(
                f"{self.expected()}, got the subnormal {x!r} (magnitude below {NORMAL_MIN:.3g})"
            )
        if not (self.lo <= x <= self.hi or (self.or_zero and x == 0.0)):
            raise ValueError(f"{self.expected()}, got {x:g}")
        return x


def physical(lo: float, hi: float, unit: str = "", *, or_zero: bool = False) -> Any:
    """The annotated float type of a field with bounds ``lo..hi`` (``unit``): see the module."""
    bounds = Bounds(float(lo), float(hi), unit, or_zero)
    return Annotated[float, AfterValidator(bounds.check), bounds]


def bounds_in(annotation: Any) -> Bounds | None:
    """The :class:`Bounds` inside a field's annotation (``physical(...) | None``,
    ``list[physical(...)]``), or None."""
    for arg in get_args(annotation):
        if isinstance(arg, Bounds):
            return arg
        found = bounds_in(arg)
        if found is not None:
            return found
    return None


def field_bounds(field: Any) -> Bounds | None:
    """The :class:`Bounds` of a pydantic field (its metadata or its annotation), or None."""
    for item in field.metadata:
        if isinstance(item, Bounds):
            return item
    return bounds_in(field.annotation)


def state_bounds(model: Any) -> None:
    """Append the bounds of every :func:`physical` field of the pydantic class ``model`` to
    its description (``[0.5..20 Å]``), once: ``flatcontact config --show-default`` prints
    them as the field's comment. Called by the settings' and the recipe's base classes from
    ``__pydantic_init_subclass__``."""
    for field in model.model_fields.values():
        bounds = field_bounds(field)
        if bounds is not None and bounds.text() not in (field.description or ""):
            field.description = f"{field.description or ''} [{bounds.text()}]".strip()
