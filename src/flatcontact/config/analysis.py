"""The ``analysis`` section: constant-pressure ISPES, sliding paths, τ, σ and the load-law fit."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, field_validator

from flatcontact.config.messages import show
from flatcontact.config.section import Section
from flatcontact.foundation import limits
from flatcontact.foundation.numbers import physical
from flatcontact.foundation.reference import PAPER_THRESHOLD_GPA


class AnalysisConfig(Section):
    """Constant-pressure ISPES, sliding paths, τ, σ and the load laws (stages ``analyze``, ``laws``)."""

    p_gpa: list[physical(-1e3, 1e3, "GPa")] = Field(
        [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0],
        description="target normal pressures P (GPa) at which the constant-pressure ISPES is analysed",
    )
    direction_deg: physical(-360.0, 360.0, "deg") | Literal["auto"] = Field(
        90.0,
        description="pulling direction, degrees from x (90 = y, the paper's), or auto: the "
        "lowest-barrier direction of the landscape at the lowest load (stated in the outputs)",
    )
    energy_form: Literal["internal", "enthalpy"] = Field(
        "internal", description="internal: U at z*(P) (the paper's); enthalpy: U + P·A·z*"
    )
    load_source: Literal["energy", "stress"] = Field(
        "energy",
        description="normal load from -(1/A) dU/dz of each column's energy spline (energy: "
        "consistent with U to second order in the relaxation residuals) or the stored "
        "normal_stress (stress: first order)",
    )
    energy_zero: Literal["lowest-p", "each", "none"] = Field(
        "lowest-p",
        description="energy zero of the maps: global minimum at the lowest P, each, none",
    )
    threshold_gpa: physical(1e-6, 1e3, "GPa") = Field(
        PAPER_THRESHOLD_GPA,
        description="fit the linear load laws on P <= this (GPa; the paper's 3 GPa)",
    )
    allow_missing: bool = Field(
        False, description="interpolate columns with unconverged/missing points instead of refusing"
    )
    with_mep: bool = Field(False, description="also compute the string-method minimum-energy path")

    @field_validator("p_gpa")
    @classmethod
    def _pressures(cls, value: list[float]) -> list[float]:
        if len(value) < 2 or len(set(value)) != len(value):
            raise ValueError(f"expected at least two distinct pressures in GPa, got {show(value)}")
        if len(value) > limits.bound("loads"):
            raise ValueError(limits.message("loads", len(value), "pressures"))
        return sorted(float(v) for v in value)
