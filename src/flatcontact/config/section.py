"""The base of every settings section: frozen, unknown keys refused, every float finite
and, where typed with bounds, within them."""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict

from flatcontact.config.messages import show
from flatcontact.foundation import limits
from flatcontact.foundation.numbers import state_bounds


class Section(BaseModel):
    """A section of the run settings (or a sub-section).

    Frozen, so a validated configuration cannot drift; ``extra="forbid"``, so a misspelt key
    is an error naming its path; ``allow_inf_nan=False``, so NaN or inf in the YAML is
    refused naming its path. A float field typed with
    :func:`~flatcontact.foundation.numbers.physical` is also refused when subnormal or out of
    its bounds, and the bounds are appended to its description.
    """

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)

    @classmethod
    def __pydantic_init_subclass__(cls, **kwargs: Any) -> None:
        """State the bounds of every :func:`~flatcontact.foundation.numbers.physical` field in its
        description (printed by ``flatcontact config --show-default``)."""
        super().__pydantic_init_subclass__(**kwargs)
        state_bounds(cls)


def positive_pair(value: Any, what: str) -> tuple[int, int]:
    """``value`` as two positive integers within the ``grid_axis`` bound (:mod:`flatcontact.foundation.limits`)."""
    ok = (
        isinstance(value, list | tuple)
        and len(value) == 2
        and all(isinstance(v, int) and not isinstance(v, bool) and v > 0 for v in value)
    )
    if not ok:
        raise ValueError(f"expected two positive integers, got {show(value)}")
    for v in value:
        if v > limits.bound("grid_axis"):
            raise ValueError(
                limits.message("grid_axis", v, f"points along one axis of {show(value)}")
            )
    return (int(value[0]), int(value[1]))
