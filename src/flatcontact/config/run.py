"""The root of the run settings: :class:`RunConfig`, one field per section.

The section models live one per module (:mod:`.scan`, :mod:`.analysis`, :mod:`.elastic`,
:mod:`.uncertainty`, :mod:`.contact`, :mod:`.report`); the ``structure`` section is a recipe of
:mod:`flatcontact.structures.recipe` and the ``potential`` section an
:class:`~flatcontact.potentials.model.InteractionModel`, both data models.
"""

from __future__ import annotations

import json
from typing import Any, Literal

from pydantic import Field, field_validator, model_validator

from flatcontact.config.analysis import AnalysisConfig
from flatcontact.config.approximants import ApproximantSettings
from flatcontact.config.asperity import AsperityConfig
from flatcontact.config.contact import ContactConfig
from flatcontact.config.elastic import ElasticConfig
from flatcontact.config.messages import show
from flatcontact.config.refine import RefineConfig
from flatcontact.config.report import ReportConfig
from flatcontact.config.scan import PressureRange, ScanConfig
from flatcontact.config.section import Section
from flatcontact.config.uncertainty import UncertaintyConfig
from flatcontact.foundation import limits
from flatcontact.potentials.model import InteractionModel
from flatcontact.structures.recipe import QuartzDenseRecipe, StructureRecipe, parse_recipe


class CalculatorConfig(Section):
    """A whole-interface ASE calculator: :attr:`RunConfig.calculator`'s view of a model
    ``potential: {calculator: {target, kwargs, scope: interface}}``."""

    target: str = Field(
        description="'module:callable'; callable(atoms, **kwargs) returns an ASE calculator "
        "for the whole interface"
    )
    kwargs: dict[str, Any] = Field(
        default_factory=dict, description="keyword arguments of the callable (JSON values)"
    )


class RunConfig(Section):
    """A whole ``flatcontact run``."""

    preset: Literal["quick", "paper"] = Field(
        "quick", description="preset the values below were resolved from"
    )
    structure: StructureRecipe = Field(
        default_factory=QuartzDenseRecipe,
        description="the interface to build (stage build): a recipe of "
        "flatcontact.structures.recipe, by kind: quartz-dense, file, slab, toy-lj, sheets, "
        "crystal, fcc111 (docs/structures.md)",
    )
    potential: InteractionModel = Field(
        default_factory=InteractionModel,
        description="the interaction model (flatcontact.potentials.InteractionModel): a preset, "
        "LAMMPS pair styles inside the slabs with a coupling across (lj, same, interlayer, "
        "none), or an ASE calculator (potential.calculator)",
    )
    scan: ScanConfig = Field(
        default_factory=lambda: ScanConfig(
            p_range_gpa=PressureRange(lo_gpa=-1.2, hi_gpa=4.5, n=12)
        ),
        description="the ISPES grid (stage scan)",
    )
    analysis: AnalysisConfig = Field(
        default_factory=AnalysisConfig,
        description="constant-pressure ISPES, paths, τ, σ and load laws (stages analyze, laws)",
    )
    elastic: ElasticConfig = Field(
        default_factory=ElasticConfig, description="optional self-consistent E*, G* (stage elastic)"
    )
    uncertainty: UncertaintyConfig = Field(
        default_factory=UncertaintyConfig,
        # left out of the dump while empty, so the fingerprints of existing runs are unchanged
        exclude_if=lambda value: value == UncertaintyConfig(),
        description="uncertainty of the laws beyond the fit (convergence, model spread)",
    )
    contact: ContactConfig = Field(
        default_factory=ContactConfig, description="modified Mindlin contact (stage contact)"
    )
    asperity: AsperityConfig = Field(
        default_factory=AsperityConfig,
        # left out of the dump while default, so the fingerprints of existing runs are unchanged
        exclude_if=lambda value: value == AsperityConfig(),
        description="the asperity in atoms against the modified Mindlin model (docs/asperity.md)",
    )
    refine: RefineConfig = Field(
        default_factory=RefineConfig,
        description="what 'flatcontact study convergence' refines and how far (no stage reads it)",
    )
    approximants: ApproximantSettings = Field(
        default_factory=ApproximantSettings,
        exclude_if=lambda value: value == ApproximantSettings(),
        description="which approximant cells 'flatcontact study approximants' runs "
        "(no stage reads it)",
    )
    report: ReportConfig = Field(
        default_factory=ReportConfig, description="the HTML report and figures (stage report)"
    )

    @field_validator("structure", mode="before")
    @classmethod
    def _structure(cls, value: Any) -> Any:
        """The ``structure`` mapping as its recipe (``kind`` defaults to ``quartz-dense``);
        one line naming the first bad field (an unknown key included)."""
        if not isinstance(value, dict):
            return value  # a model already, or pydantic's own type error
        data = {"kind": "quartz-dense", **value}
        layers = data.get("layers")
        if isinstance(layers, int | float) and not isinstance(layers, bool):
            limits.check("layers", layers, "structure.layers", "layers per slab")
        return parse_recipe(data)

    @property
    def calculator(self) -> CalculatorConfig | None:
        """The whole-interface ASE calculator of the model, if it is one."""
        calc = self.potential.calculator
        if calc is None or calc.scope != "interface":
            return None
        return CalculatorConfig(target=calc.target, kwargs=calc.kwargs)

    @model_validator(mode="after")
    def _cross(self) -> RunConfig:
        if self.structure.kind == "toy-lj" and self.calculator is None:
            raise ValueError(
                "structure.kind 'toy-lj' needs potential.calculator.target: "
                "flatcontact.ispes.toy:toy_calculator"
            )
        fig = self.report.fig2_p_gpa
        if fig is not None and any(p not in self.analysis.p_gpa for p in fig):
            raise ValueError(
                f"report.fig2_p_gpa {show(fig)} must be among analysis.p_gpa {show(self.analysis.p_gpa)}"
            )
        return self

    def section(self, name: str) -> dict:
        """JSON-ready dict of one section (``None`` sections as ``None``)."""
        value = getattr(self, name)
        return None if value is None else json.loads(value.model_dump_json())

    def structure_section(self) -> dict:
        """The ``structure`` section as fingerprinted (build stage, ``uncertainty.measured_on``):
        ``lattice: file`` is left out, since it is what every recipe meant before the setting
        existed, so the runs and measured blocks of those recipes keep their fingerprints;
        ``lattice: potential`` (the default) is another structure and fingerprints as one."""
        out = self.section("structure")
        if isinstance(out, dict) and out.get("lattice") == "file":
            out.pop("lattice")
        return out

    def to_dict(self) -> dict:
        """The whole configuration as plain JSON-ready data."""
        return json.loads(self.model_dump_json())
