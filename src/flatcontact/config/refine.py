"""The ``refine`` section: which settings ``flatcontact study convergence`` refines, how far.

One setting is refined at a time from the run configuration (the base), one step per
round, until the step moves every per-load τ and σ_MSS by less than ``tolerance_pct``
(converged) or ``max_steps`` steps are spent (reported as not converged). A step is:

* ``grid``: both lateral grid counts times ``grid_factor`` (rounded up);
* ``thicknesses``: the number of thicknesses (``scan.p_range_gpa.n``, or midpoints inserted
  into an explicit ``scan.thickness_angstrom``) times ``thickness_factor`` over the same range;
* ``layers``: ``structure.layers`` + ``layers_step`` (recipes with a layer count);
* ``fmax``: ``scan.fmax_ev_per_angstrom`` times ``fmax_factor`` (< 1);
* ``cutoff``: the cross-interface cutoff + ``cutoff_step_angstrom``: the LJ's (``coupling:
  lj``) or the cutoff argument of each tapered interlayer style (``coupling: interlayer``:
  ``kolmogorov/crespi/full``, ``ilp/*``, ``coul/shield``; the taper takes the term to zero
  smoothly at every rung, and the ladder only lengthens it).

``settings: auto`` takes every one of these that the recipe and model have
(:func:`flatcontact.studies.variants.applicable_settings`). The section changes no stage's
numbers (no stage fingerprint reads it).
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, field_validator

from flatcontact.config.section import Section
from flatcontact.foundation.numbers import physical

#: The settings a refinement study can refine, in the order they are reported.
REFINABLE = ("grid", "thicknesses", "layers", "fmax", "cutoff")


class RefineConfig(Section):
    """Convergence study settings (``flatcontact study convergence``; docs/studies.md)."""

    settings: list[Literal["grid", "thicknesses", "layers", "fmax", "cutoff"]] | Literal["auto"] = (
        Field("auto", description=f"settings refined one at a time: auto or some of {REFINABLE}")
    )

    @field_validator("settings")
    @classmethod
    def _something_once(cls, value):
        """A list that refines nothing, or one setting twice (a variant compared with itself,
        called converged), is refused: neither measures a convergence width."""
        if isinstance(value, list):
            if not value:
                raise ValueError(
                    f"an empty list refines nothing; give some of {', '.join(REFINABLE)}, or auto for all"
                )
            twice = sorted({s for s in value if value.count(s) > 1})
            if twice:
                raise ValueError(f"{', '.join(twice)} given twice; give each setting once")
        return value

    tolerance_pct: physical(0.01, 100.0, "%") = Field(
        3.0,
        description="a step converges when it moves every per-load τ and σ_MSS by less than "
        "this (percent of the larger magnitude, or of tolerance_floor_mpa when larger)",
    )
    tolerance_floor_mpa: physical(0.0, 1e4, "MPa") = Field(
        1.0,
        description="absolute floor of the tolerance (a change below tolerance_pct of this "
        "counts as converged: values near zero)",
    )
    max_steps: int = Field(2, ge=1, le=6, description="refinement steps per setting (budget)")
    grid_factor: physical(1.1, 4.0) = Field(1.5, description="lateral grid counts times this")
    thickness_factor: physical(1.1, 4.0) = Field(
        1.5, description="number of thicknesses times this (same range)"
    )
    layers_step: int = Field(1, ge=1, le=20, description="layers per slab added per step")
    fmax_factor: physical(0.05, 0.9) = Field(0.5, description="force tolerance times this")
    cutoff_step_angstrom: physical(0.5, 50.0, "Å") = Field(
        4.0,
        description="cross-interface cutoff added per step (the LJ's, or each tapered "
        "interlayer style's: KC, ILP, coul/shield)",
    )
