"""The ``contact`` section: the modified Mindlin contact, with its sub-sections.

At the top: the loads (``p0_gpa``), the tip (``radius_um``), the moduli, the law overrides
(k, τ0, μ, σ0), the work of adhesion and the stiffness-curve fractions. Below:

- ``cycle``: the steady load-controlled oscillation cycle per p0;
- ``fit``: the multi-load least-squares fit of measured stiffness curves;
- ``experiment``: one measured stiffness curve overlaid on Fig. 6.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field, field_validator

from flatcontact.config.messages import show
from flatcontact.config.section import Section
from flatcontact.foundation import limits
from flatcontact.foundation.numbers import physical
from flatcontact.foundation.reference import DEFAULT_P0_GPA, PAPER, PAPER_EXPERIMENT_P0_GPA

#: Force amplitudes of the cycle as fractions of the gross-sliding force
#: (:data:`flatcontact.contact.cycle.DEFAULT_AMPLITUDE_FRACTIONS`; a test keeps them equal).
CYCLE_AMPLITUDE_FRACTIONS: tuple[float, ...] = (0.2, 0.4, 0.6, 0.8, 0.9, 0.95)

#: The validity gates (:data:`flatcontact.analysis.gates.GATES`; a test keeps them equal).
GATE_NAMES: tuple[str, ...] = (
    "in_slab_slip",
    "broken_symmetry",
    "load_fold",
    "negative_slope",
    "degenerate_minima",
)
Gate = Literal[GATE_NAMES]

#: Peak Hertz pressure p0 (1 kPa .. 1 TPa).
PressureGPa = physical(1e-6, 1e3, "GPa")
#: A fraction strictly inside (0, 1), kept off both ends.
Fraction = physical(1e-3, 0.999)
#: Contact moduli E*, G* (from soft polymers to beyond diamond).
ModulusGPa = physical(0.01, 1e4, "GPa")
#: Stresses of the laws (τ0, σ0): 1 Pa to 100 GPa, or 0.
StressMPa = physical(1e-6, 1e5, "MPa", or_zero=True)
#: Slopes of the laws (k, μ), either sign.
SlopeMPaPerGPa = physical(-1e5, 1e5, "MPa/GPa")


class CycleConfig(Section):
    """The steady load-controlled oscillation cycle per p0 (``contact.cycle``)."""

    enabled: bool = Field(
        False,
        description="steady load-controlled cycle per p0: loops, dissipated energy per cycle, "
        "lock-in stiffness Q_amp/u'_1 and quadrature u''_1 (summary.json 'cycle', contact.nc)",
    )
    model: Literal["modified", "classical"] = Field(
        "modified",
        description="model of the cycle: modified (the paper's Mindlin model) or classical "
        "(Cattaneo-Mindlin, friction coefficient mu = k, Johnson's G*_J = G*/4)",
    )
    amplitude_fractions: list[Fraction] = Field(
        list(CYCLE_AMPLITUDE_FRACTIONS),
        description="force amplitudes of the cycle as fractions of the gross-sliding force, "
        "each in (0, 1)",
    )
    amplitudes_un: list[physical(1e-6, 1e6, "µN")] | None = Field(
        None,
        description="force amplitudes of the cycle in uN (each below gross sliding at every "
        "p0); null: amplitude_fractions",
    )

    @field_validator("amplitude_fractions")
    @classmethod
    def _fractions(cls, value: list[float]) -> list[float]:
        if not value or any(not 0.0 < v < 1.0 for v in value):
            raise ValueError(
                f"expected fractions of the gross-sliding force in (0, 1), got {show(value)}"
            )
        return [float(v) for v in value]

    @field_validator("amplitudes_un")
    @classmethod
    def _amplitudes(cls, value: list[float] | None) -> list[float] | None:
        if value is not None and (not value or any(not v > 0 for v in value)):
            raise ValueError(f"expected positive force amplitudes in uN, got {show(value)}")
        return value


class FitConfig(Section):
    """The multi-load fit of measured stiffness curves (``contact.fit``)."""

    csv: list[str] = Field(
        [],
        description="measured stiffness CSVs to fit at several loads at once (one per load, "
        "or with a load column 'p0 [GPa]'/'normal load [uN]'; relative to the config file)",
    )
    p0_gpa: list[PressureGPa] | None = Field(
        None, description="p0 (GPa) of each fit.csv file without a load column, one per file"
    )
    free: list[str] = Field(
        ["tau0_mpa"],
        description="parameters the fit frees (tau0_mpa, k_mpa_per_gpa, mu_mpa_per_gpa, "
        "sigma0_mpa, shear_modulus_gpa); the rest are held at their values",
    )
    fixed: list[str] = Field(
        [], description="parameters the fit must hold (checked against fit.free)"
    )
    stiffness: Literal["lockin", "paper"] = Field(
        "lockin",
        description="model stiffness the fit compares with the data: lockin (Q_amp/u'_1, "
        "what a lock-in amplifier reads) or paper (d<Q>/d<u>)",
    )


class ExperimentConfig(Section):
    """One measured stiffness curve overlaid on Fig. 6 (``contact.experiment``)."""

    csv: str | None = Field(
        None,
        description="measured stiffness CSV ('mean shear stress [MPa],lateral stiffness [N/m]') "
        "for the Fig. 6 overlay (relative to the config file)",
    )
    p0_gpa: PressureGPa = Field(
        PAPER_EXPERIMENT_P0_GPA, description="p0 of the measured data (GPa)"
    )
    stress_measure: Literal["amplitude", "rms"] = Field(
        "amplitude", description="stress of the data: amplitude Q_max/πa² or rms ⟨Q⟩/πa²"
    )
    compare: Literal["passivated-tip"] | None = Field(
        None,
        description="the run models an interface of the paper's oscillatory-shear experiment "
        "(passivated-tip: diamond tip on few-layer graphene over SiOx): the report sets the "
        "run's collapse stress at experiment.p0_gpa against the measured collapses and the "
        "quartz laws' (summary.json 'experiment_comparison'); null: no such table",
    )


class ContactConfig(Section):
    """The modified Mindlin contact (stage ``contact``)."""

    p0_gpa: list[PressureGPa] = Field(
        list(DEFAULT_P0_GPA), description="peak Hertz pressures p0 (GPa)"
    )
    radius_um: physical(1e-3, 1e4, "µm") = Field(
        PAPER["radius_um"], description="tip radius R (µm; 1 nm to 1 cm)"
    )
    contact_modulus_gpa: ModulusGPa = Field(
        PAPER["contact_modulus_gpa"],
        description="Hertz contact modulus E* (GPa; the paper's DFT value)",
    )
    shear_modulus_gpa: ModulusGPa = Field(
        PAPER["shear_modulus_gpa"],
        description="effective shear modulus G* (GPa) in the paper's q0 = G*·u/(π a) (= 4 × Johnson's G*_J)",
    )
    k_mpa_per_gpa: SlopeMPaPerGPa | None = Field(
        None,
        description="override k of τ = k·P + τ0 (MPa/GPa; may be < 0, then p0 < τ0/|k|); "
        "null: the fitted law",
    )
    tau0_mpa: StressMPa | None = Field(None, description="override τ0 (MPa); null: fitted")
    mu_mpa_per_gpa: SlopeMPaPerGPa | None = Field(
        None,
        description="override μ of σ = μ·P + σ0 (MPa/GPa; may be < 0, then p0 <= σ0/|μ|); "
        "null: fitted",
    )
    sigma0_mpa: StressMPa | None = Field(None, description="override σ0 (MPa); null: fitted")
    work_of_adhesion_j_per_m2: physical(1e-6, 100.0, "J/m²", or_zero=True) | None = Field(
        None,
        description="work of adhesion w (J/m²) of the contact for DMT/JKR radii (measured or "
        "chosen); null: the ideal work of separation W of the scan's slabs, a distinct "
        "quantity taken in its place",
    )
    maugis_lambda: physical(1e-3, 1e3) | None = Field(
        None,
        description="Maugis parameter λ: adds the Maugis–Dugdale radius and pull-off force "
        "(needs a work of adhesion > 0); null: none",
    )
    equilibrium_separation_angstrom: physical(0.5, 20.0, "Å") | None = Field(
        None,
        description="equilibrium separation z0 of the interface for the Tabor parameter "
        "(Å); null: the gap between the facing atomic planes of the built interface",
    )
    contact_radius: Literal["adhesive", "hertz"] = Field(
        "adhesive",
        description="adhesive: the radius of the model the Tabor parameter names (DMT, "
        "Maugis–Dugdale, JKR; Hertz at w = 0) in Q_peak/πa² and the modified Mindlin model; "
        "hertz: the paper's Hertz radius (adhesion only reported)",
    )
    slip_regime: Literal["auto", "concurrent", "size-limited"] = Field(
        "auto",
        description="auto: the size-limited strength where the contact radius exceeds the "
        "critical size of concurrent slip (docs/contact.md); concurrent: the modified Mindlin "
        "number everywhere (the box still says where it exceeds that size); size-limited: "
        "the size-limited estimate everywhere",
    )
    knee_fraction: Fraction = Field(
        0.5, description="knee: stiffness falls to this fraction of its initial value"
    )
    collapse_fraction: Fraction = Field(
        0.2, description="collapse: stiffness first below this fraction of the plateau"
    )
    accept_untrusted: list[Gate] = Field(
        [],
        description="validity gates to pass although they fired (in_slab_slip, "
        "broken_symmetry, load_fold, negative_slope, degenerate_minima): the contact stage "
        "then runs on the numbers and the report says above its figures which are not to be "
        "trusted and why; empty: a gate that fires stops the run before the contact stage",
    )
    cycle: CycleConfig = Field(
        default_factory=CycleConfig, description="the oscillation cycle per p0 (off by default)"
    )
    fit: FitConfig = Field(
        default_factory=FitConfig,
        description="the multi-load fit of measured stiffness curves (off without fit.csv)",
    )
    experiment: ExperimentConfig = Field(
        default_factory=ExperimentConfig,
        description="a measured stiffness curve for the Fig. 6 overlay (off without "
        "experiment.csv)",
    )

    @field_validator("accept_untrusted")
    @classmethod
    def _accepted(cls, value: list[str]) -> list[str]:
        return list(dict.fromkeys(value))

    @field_validator("p0_gpa")
    @classmethod
    def _p0(cls, value: list[float]) -> list[float]:
        if not value or any(not v > 0 for v in value):
            raise ValueError(f"expected positive peak pressures in GPa, got {show(value)}")
        if len(value) > limits.bound("loads"):
            raise ValueError(limits.message("loads", len(value), "peak pressures"))
        return [float(v) for v in value]
