"""The ``approximants`` section: which commensurate cells approximate an incommensurate contact.

A commensurate approximant is a periodic cell in which two slabs that are incommensurate in
nature (a twist of one lattice against itself, or two lattices of different constants) are
made to coincide: by a commensurate twist angle close to the target (same lattice), or by a
small strain (coincidence lattice of two materials, ZSL). The sequence of approximants of
increasing size converges to the incommensurate contact
(:func:`flatcontact.structures.approximants.approximant_sequence`; docs/incommensurate.md,
"Approximant cells").

* Same lattice (slab 2 of slab 1's material): with ``twist_deg`` the commensurate (m, n)
  cells whose angle error to the target decreases with size; without it the (n, n + 1)
  family (21.787°, 13.174°, 9.430°, ... toward the small-angle, moiré, limit).
* Two materials: the smallest coincidence cell within each strain bound of
  ``strain_percent`` (decreasing), the strain put on slab 2 or shared (``strain_on``); any
  rotation of slab 2, or with ``twist_deg`` one within ``angle_tolerance_deg`` of it.

The section changes no stage's numbers (no stage fingerprint reads it).
"""

from __future__ import annotations

import itertools
from typing import Literal

from pydantic import Field, ValidationError, field_validator

from flatcontact.config.messages import one_line
from flatcontact.config.section import Section
from flatcontact.foundation.numbers import physical

#: Strain bounds (%) of the coincidence-lattice ladder of two materials when none is given.
DEFAULT_STRAIN_LADDER_PERCENT = (3.0, 1.0, 0.3, 0.1)

#: A strain bound of the ladder: as ``structure.match.max_strain_percent``.
LadderPercent = physical(1e-3, 20.0, "%")


class ApproximantSettings(Section):
    """Commensurate approximant cells of an incommensurate contact (docs/incommensurate.md)."""

    twist_deg: physical(0.0, 60.0, "deg") | None = Field(
        None,
        description="target twist of slab 2 against slab 1, e.g. 1.1 or 30. Same hexagonal "
        "lattice: the commensurate (m, n) cells of decreasing angle error; none: the (n, n+1) "
        "family 21.787°, 13.174°, 9.430°, ... (angle and size change together). Two "
        "materials: only coincidence cells that rotate slab 2 within angle_tolerance_deg of "
        "it (modulo the lattice's rotation symmetry), e.g. 0 for an aligned pair; none: any "
        "rotation",
    )
    angle_tolerance_deg: physical(0.001, 30.0, "deg") = Field(
        0.5,
        description="two materials with twist_deg: largest deviation of slab 2's rotation "
        "from the target",
    )
    max_atoms: int = Field(
        2000, ge=2, le=100_000, description="largest interface (atoms) in the sequence"
    )
    max_cells: int = Field(6, ge=1, le=50, description="at most this many cells, smallest first")
    strain_percent: list[LadderPercent] | None = Field(
        None,
        description="two materials: decreasing bounds of the principal strain on either slab "
        "(%), one coincidence cell each (the smallest within the bound); none: "
        f"{list(DEFAULT_STRAIN_LADDER_PERCENT)}",
    )
    strain_on: Literal["slab2", "both"] = Field(
        "slab2",
        description="two materials: slab2: slab 1 keeps its lattice, slab 2 takes the strain; "
        "both: the common cell is the mean of the two",
    )

    @field_validator("strain_percent")
    @classmethod
    def _decreasing(cls, value: list[float] | None) -> list[float] | None:
        if value is None:
            return value
        if not value:
            raise ValueError("expected at least one strain bound, e.g. [3, 1, 0.3, 0.1]")
        if any(b >= a for a, b in itertools.pairwise(value)):
            raise ValueError(f"expected strictly decreasing bounds, got {value}")
        return value


def parse_approximants(data: dict | None, source: str = "approximants") -> ApproximantSettings:
    """The section from a mapping (None: the defaults); one-line InputError naming the field."""
    try:
        return ApproximantSettings.model_validate(data or {})
    except ValidationError as exc:
        raise one_line(exc, source) from None
