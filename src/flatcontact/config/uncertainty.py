"""The ``uncertainty`` section: the law uncertainty beyond the fit (convergence, model spread)."""

from __future__ import annotations

from typing import Any

from pydantic import Field, field_validator

from flatcontact.config.messages import show
from flatcontact.config.section import Section
from flatcontact.foundation.numbers import Bounds, physical

#: The law coefficients an uncertainty block may name (τ = k·P + τ0, σ = μ·P + σ0).
LAW_KEYS = ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa")
#: A width δ_conv or δ_model (MPa, or MPa/GPa for k and μ): 0 or a normal double up to
#: 1e5 (a law coefficient of a solid is below 1e4; 1e200 went into laws.json as Infinity).
WIDTH_BOUNDS = Bounds(0.0, 1e5, "MPa or MPa/GPa")
#: The fingerprints of ``measured_on`` (:mod:`flatcontact.stages.measured_on`).
MEASURED_ON_KEYS = ("structure_sha256", "model_sha256")


class UncertaintyConfig(Section):
    """Uncertainty of the load laws beyond the fit (stage ``laws``; propagated by ``contact``).

    Per coefficient c the half-width is coverage·sqrt(se_fit² + δ_conv² + δ_model²)
    (:func:`flatcontact.analysis.uncertainty.law_half_widths`), per energy form.
    """

    convergence_internal: dict[str, float] = Field(
        {}, description="δ_conv per law coefficient, internal form (change under one refinement)"
    )
    convergence_enthalpy: dict[str, float] = Field(
        {}, description="δ_conv per law coefficient, enthalpy form"
    )
    model_spread_internal: dict[str, float] = Field(
        {}, description="δ_model per law coefficient, internal form (half the spread over models)"
    )
    model_spread_enthalpy: dict[str, float] = Field(
        {}, description="δ_model per law coefficient, enthalpy form"
    )
    coverage: physical(0.01, 100.0) = Field(
        1.0, description="multiple of the combined standard error"
    )
    source: str = Field("", description="where the δ_conv and δ_model numbers come from")
    measured_on: dict[str, str] = Field(
        {},
        description="fingerprints of what the numbers were measured on (structure_sha256, "
        "model_sha256; written by flatcontact study): a run whose structure or potential "
        "differs refuses the block",
    )
    provenance: dict[str, Any] = Field(
        {}, description="how the numbers were made (study, command, date, variants)"
    )

    @field_validator("measured_on")
    @classmethod
    def _measured_on(cls, value: dict[str, str]) -> dict[str, str]:
        for key, v in value.items():
            if key not in MEASURED_ON_KEYS:
                raise ValueError(f"{key!r}: expected keys among {', '.join(MEASURED_ON_KEYS)}")
            if not (
                isinstance(v, str) and len(v) == 64 and all(c in "0123456789abcdef" for c in v)
            ):
                raise ValueError(f"{key} = {show(v)}: expected a SHA-256 hex digest")
        return value

    @field_validator(
        "convergence_internal",
        "convergence_enthalpy",
        "model_spread_internal",
        "model_spread_enthalpy",
    )
    @classmethod
    def _coefficients(cls, value: dict[str, float]) -> dict[str, float]:
        for key, v in value.items():
            if key not in LAW_KEYS:
                raise ValueError(f"{key!r}: expected law coefficients among {', '.join(LAW_KEYS)}")
            try:
                WIDTH_BOUNDS.check(v)
            except (TypeError, ValueError) as exc:
                raise ValueError(f"{key} = {show(v)}: {exc}") from None
        return {k: float(v) for k, v in value.items()}
