"""The run configuration: pydantic models, presets, YAML in and out.

A configuration is a YAML mapping with the sections of :class:`RunConfig`
(``structure``, ``potential``, ``calculator``, ``scan``, ``analysis``, ``elastic``,
``contact``, ``report``) and an optional ``preset`` key. Values not given come from the
preset (``quick`` by default, or ``paper``), so a file only lists what it changes::

    preset: quick
    scan:
      grid: [8, 8]
    contact:
      p0_gpa: [0.5, 1.0, 2.0]

Every field carries its unit in its name (``radius_um``, ``p0_gpa``,
``fmax_ev_per_angstrom``) and a description (``flatcontact config --show-default``
prints them as comments). Unknown keys are refused. :func:`load_config` turns every
problem into one :class:`~flatcontact.errors.InputError` line that names the file and
the dotted path of the field, e.g.
``config.yaml: scan.grid: expected two positive integers, got [0, 4]``.

Units follow ``DESIGN.md``: atomistic quantities in eV and Å, loads in GPa, laws in MPa
and MPa/GPa, contact geometry in µm/nm.
"""

from __future__ import annotations

import copy
import json
import typing
from pathlib import Path
from typing import Any, Literal

import yaml
from pydantic import (
    BaseModel,
    ConfigDict,
    Field,
    ValidationError,
    field_validator,
    model_validator,
)

from flatcontact import limits
from flatcontact.contact.cycle import DEFAULT_AMPLITUDE_FRACTIONS as CYCLE_AMPLITUDE_FRACTIONS
from flatcontact.errors import InputError
from flatcontact.fileio import read_text_file
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.order import PREFERENCES
from flatcontact.ispes.relax import OPTIMIZERS, RelaxSettings
from flatcontact.potentials.files import BUNDLED_DIR
from flatcontact.potentials.model import InteractionModel
from flatcontact.reference import (
    DEFAULT_P0_GPA,
    PAPER,
    PAPER_EXPERIMENT_P0_GPA,
    PAPER_THRESHOLD_GPA,
    QUARTZ_HAMAKER_ZJ,
)
from flatcontact.structures.recipe import FILE_FIELDS as _RECIPE_FILE_FIELDS
from flatcontact.structures.recipe import QuartzDenseRecipe, StructureRecipe

#: The bundled SNAP the default run uses when it is present.
BUNDLED_SNAP = "sio2-snap"


class _Section(BaseModel):
    # every float of a run is finite: NaN or inf in the YAML is refused naming its path
    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)


def _positive_pair(value: Any, what: str) -> tuple[int, int]:
    ok = (
        isinstance(value, list | tuple)
        and len(value) == 2
        and all(isinstance(v, int) and not isinstance(v, bool) and v > 0 for v in value)
    )
    if not ok:
        raise ValueError(f"expected two positive integers, got {_show(value)}")
    for v in value:
        if v > limits.bound("grid_axis"):
            raise ValueError(
                limits.message("grid_axis", v, f"points along one axis of {_show(value)}")
            )
    return (int(value[0]), int(value[1]))


def _show(value: Any) -> str:
    if isinstance(value, tuple):
        value = list(value)
    try:
        return json.dumps(value)
    except TypeError:
        return repr(value)


#: Flat keys of the earlier one-model ``structure`` section that a recipe kind may lack:
#: dropped when the chosen kind has no such field (``file: null`` of a quartz run, the
#: preset's ``layers``/``source`` under ``kind: file``). ``face_depth_angstrom`` goes too:
#: the slab recipe finds the layers from the structure instead of a depth.
_LEGACY_STRUCTURE_KEYS = (
    "layers",
    "source",
    "file",
    "gap_angstrom",
    "fmax_ev_per_angstrom",
    "normal_axis",
    "face_depth_angstrom",
)


def _structure_section(value: Any) -> Any:
    """The ``structure`` mapping as a recipe model (:data:`flatcontact.structures.recipe.StructureRecipe`).

    Earlier flat keys that the chosen kind does not have are dropped; ``normal_axis`` other
    than 2 is refused (the slab recipe takes the normal along cell vector 3).
    """
    from flatcontact.structures.recipe import KINDS, StructureRecipe, parse_recipe

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
    if kind in KINDS:
        models = typing.get_args(typing.get_args(StructureRecipe)[0])
        fields = {m.model_fields["kind"].default: m.model_fields for m in models}[kind]
        for key in _LEGACY_STRUCTURE_KEYS:
            if key in data and key not in fields:
                data.pop(key)
    layers = data.get("layers")
    if isinstance(layers, int | float) and not isinstance(layers, bool):
        limits.check("layers", layers, "structure.layers", "layers per slab")
    return parse_recipe(data)


class CalculatorConfig(_Section):
    """A whole-interface ASE calculator (the earlier top-level ``calculator:`` section).

    Still read from YAML and turned into ``potential: {calculator: {target, kwargs}}``;
    ``RunConfig.calculator`` gives this view of such a model.
    """

    target: str = Field(
        description="'module:callable'; callable(atoms, **kwargs) returns an ASE calculator "
        "for the whole interface"
    )
    kwargs: dict[str, Any] = Field(
        default_factory=dict, description="keyword arguments of the callable (JSON values)"
    )


class PressureRange(_Section):
    """n loads evenly spaced from lo_gpa to hi_gpa at the probe stacking."""

    lo_gpa: float = Field(description="lowest target load (GPa; negative = tension)")
    hi_gpa: float = Field(gt=0, description="highest target load (GPa, compressive)")
    n: int = Field(ge=2, description="number of thicknesses")

    @model_validator(mode="after")
    def _order(self) -> PressureRange:
        if not self.lo_gpa < self.hi_gpa:
            raise ValueError(f"expected lo_gpa < hi_gpa, got {self.lo_gpa} and {self.hi_gpa}")
        if self.n > limits.bound("thicknesses"):
            raise ValueError("n: " + limits.message("thicknesses", self.n, "thicknesses"))
        return self


class ScanConfig(_Section):
    """The ISPES grid (stage ``scan``)."""

    grid: tuple[int, int] = Field(
        (12, 12), description="lateral points along a1 and a2 over the primitive cell"
    )
    p_range_gpa: PressureRange | None = Field(
        None,
        description="choose the thicknesses z so that the loads at the probe stacking span "
        "lo_gpa..hi_gpa (n values); exclusive with thickness_angstrom",
    )
    thickness_angstrom: list[float] | None = Field(
        None, description="explicit thicknesses z (Å, surface 1 to surface 4)"
    )
    fmax_ev_per_angstrom: float = Field(
        0.005, gt=0, description="force tolerance on the free atoms at each point (eV/Å)"
    )
    optimizer: str = Field(
        RelaxSettings().optimizer,
        description="ASE optimiser of each point: " + ", ".join(OPTIMIZERS),
    )
    max_steps: int = Field(2000, ge=1, description="optimiser step cap per point")
    relax_mode: Literal["full", "normal", "rigid-layers", "rigid"] = Field(
        "full",
        # left out of the dumped config while default, so existing run fingerprints are unchanged
        exclude_if=lambda value: value == "full",
        description="relaxation of each point: full (free atoms in 3D, the paper's), normal "
        "(along z only: the generalized-stacking-fault convention), rigid-layers (each free "
        "layer a rigid body along z), rigid (none)",
    )
    bracket_all_stackings: bool = Field(
        True,
        exclude_if=lambda value: value is True,
        description="p_range_gpa: probe the extreme columns so that every stacking spans the "
        "loads (default); false: only the lowest-energy column decides the thicknesses",
    )
    order: str = Field(
        "columns",
        description="warm-start tree: columns (walk each column along z), planes, cold",
    )
    executor: Literal["serial", "processes", "dask"] = Field(
        "processes", description="serial, local processes, or Dask"
    )
    workers: int | None = Field(None, ge=1, description="worker processes (default: one per core)")
    dask_address: str | None = Field(None, description="address of a running Dask scheduler")
    jobqueue: dict[str, Any] | None = Field(
        None,
        # left out of the dumped config while unset, so existing run fingerprints are unchanged
        exclude_if=lambda value: value is None,
        description="a dask-jobqueue cluster instead of local workers: {kind: slurm|pbs|sge|lsf|"
        "htcondor|oar|moab, jobs: N, ...keyword arguments of the cluster class}",
    )

    @field_validator("optimizer")
    @classmethod
    def _optimizer(cls, value: str) -> str:
        if value not in OPTIMIZERS:
            raise ValueError(f"expected one of {', '.join(OPTIMIZERS)}, got {_show(value)}")
        return value

    @field_validator("order")
    @classmethod
    def _order(cls, value: str) -> str:
        if value not in PREFERENCES:
            raise ValueError(f"expected one of {', '.join(PREFERENCES)}, got {_show(value)}")
        return value

    @field_validator("grid", mode="before")
    @classmethod
    def _grid(cls, value: Any) -> tuple[int, int]:
        return _positive_pair(value, "grid")

    @model_validator(mode="after")
    def _one_of(self) -> ScanConfig:
        if (self.p_range_gpa is None) == (self.thickness_angstrom is None):
            raise ValueError("give exactly one of p_range_gpa and thickness_angstrom")
        if self.thickness_angstrom is not None:
            z = self.thickness_angstrom
            if not z or any(not v > 0 for v in z):
                raise ValueError(f"thickness_angstrom: expected positive values in Å, got {z}")
            if len(set(z)) != len(z):
                repeated = sorted({v for v in z if z.count(v) > 1})
                raise ValueError(
                    f"thickness_angstrom: expected distinct values in Å, {_show(repeated)} repeated"
                )
        n_z = len(self.thickness_angstrom) if self.thickness_angstrom else self.p_range_gpa.n
        if n_z > limits.bound("thicknesses"):
            raise ValueError(
                "thickness_angstrom: " + limits.message("thicknesses", n_z, "thicknesses")
            )
        points = self.grid[0] * self.grid[1] * n_z
        if points > limits.bound("scan_points"):
            raise ValueError(
                "grid: "
                + limits.message(
                    "scan_points",
                    points,
                    f"{self.grid[0]}x{self.grid[1]} points x {n_z} thicknesses",
                )
            )
        if self.workers is not None and self.workers > limits.bound("workers"):
            raise ValueError(
                "workers: " + limits.message("workers", self.workers, "worker processes")
            )
        return self

    def grid_spec(self) -> GridSpec:
        """The scan grid of these settings (:class:`flatcontact.ispes.grid.GridSpec`)."""
        r = self.p_range_gpa
        return GridSpec(
            self.grid[0],
            self.grid[1],
            thickness_angstrom=tuple(self.thickness_angstrom) if self.thickness_angstrom else None,
            p_range_gpa=(r.lo_gpa, r.hi_gpa, r.n) if r else None,
            bracket_all_stackings=self.bracket_all_stackings,
        )

    def relax_settings(self) -> RelaxSettings:
        """The per-point relaxation of these settings."""
        return RelaxSettings(
            self.fmax_ev_per_angstrom, self.optimizer, self.max_steps, mode=self.relax_mode
        )

    def executor_options(self) -> dict[str, Any]:
        """How the points are run (:func:`flatcontact.ispes.scan.run_scan`'s ``executor_options``)."""
        return {
            "kind": self.executor,
            "workers": self.workers,
            "dask_address": self.dask_address,
            "jobqueue": self.jobqueue,
        }


class AnalysisConfig(_Section):
    """Constant-pressure ISPES, sliding paths, τ, σ and the load laws (stages ``analyze``, ``laws``)."""

    p_gpa: list[float] = Field(
        [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0],
        description="target normal pressures P (GPa) at which the constant-pressure ISPES is analysed",
    )
    direction_deg: float | Literal["auto"] = Field(
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
    threshold_gpa: float = Field(
        PAPER_THRESHOLD_GPA,
        gt=0,
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
            raise ValueError(f"expected at least two distinct pressures in GPa, got {_show(value)}")
        if len(value) > limits.bound("loads"):
            raise ValueError(limits.message("loads", len(value), "pressures"))
        return sorted(float(v) for v in value)


class ElasticConfig(_Section):
    """Self-consistent contact moduli E*, G* from the potential (stage ``elastic``, optional)."""

    strain: float = Field(
        0.005, gt=0, lt=0.05, description="finite strain of the central differences for C_ij"
    )
    enabled: bool = Field(
        False,
        description="compute E* and G* (paper's convention) of the slabs' bulk crystal (alpha-"
        "quartz, the fcc metal, the crystal file, the layered bulk of sheets) with the run's "
        "interaction model; otherwise contact.contact_modulus_gpa/shear_modulus_gpa (required "
        "for any material but alpha-quartz)",
    )


class ContactConfig(_Section):
    """The modified Mindlin contact (stage ``contact``)."""

    p0_gpa: list[float] = Field(list(DEFAULT_P0_GPA), description="peak Hertz pressures p0 (GPa)")
    radius_um: float = Field(
        PAPER["radius_um"], gt=0, le=1e4, description="tip radius R (µm; at most 1 cm)"
    )
    contact_modulus_gpa: float = Field(
        PAPER["contact_modulus_gpa"],
        gt=0,
        description="Hertz contact modulus E* (GPa; the paper's DFT value)",
    )
    shear_modulus_gpa: float = Field(
        PAPER["shear_modulus_gpa"],
        gt=0,
        description="effective shear modulus G* (GPa) in the paper's q0 = G*·u/(π a) (= 4 × Johnson's G*_J)",
    )
    k_mpa_per_gpa: float | None = Field(
        None,
        description="override k of τ = k·P + τ0 (MPa/GPa; may be < 0, then p0 < τ0/|k|); "
        "null: the fitted law",
    )
    tau0_mpa: float | None = Field(None, ge=0, description="override τ0 (MPa); null: fitted")
    mu_mpa_per_gpa: float | None = Field(
        None,
        description="override μ of σ = μ·P + σ0 (MPa/GPa; may be < 0, then p0 <= σ0/|μ|); "
        "null: fitted",
    )
    sigma0_mpa: float | None = Field(None, ge=0, description="override σ0 (MPa); null: fitted")
    work_of_adhesion_j_m2: float | None = Field(
        None,
        ge=0,
        description="work of adhesion w (J/m²) for DMT/JKR radii; null: the work of separation "
        "measured by the scan",
    )
    maugis_lambda: float | None = Field(
        None,
        gt=0,
        # left out of the dumped config while unset, so existing run fingerprints are unchanged
        exclude_if=lambda value: value is None,
        description="Maugis parameter λ: adds the Maugis–Dugdale radius and pull-off force "
        "(needs a work of adhesion > 0); null: none",
    )
    knee_fraction: float = Field(
        0.5, gt=0, lt=1, description="knee: stiffness falls to this fraction of its initial value"
    )
    experiment_csv: str | None = Field(
        None,
        description="measured stiffness CSV ('mean shear stress [MPa],lateral stiffness [N/m]') "
        "for the Fig. 6 overlay (relative to the config file)",
    )
    experiment_p0_gpa: float = Field(
        PAPER_EXPERIMENT_P0_GPA, gt=0, description="p0 of the measured data (GPa)"
    )
    experiment_stress_measure: Literal["amplitude", "rms"] = Field(
        "amplitude", description="stress of the data: amplitude Q_max/πa² or rms ⟨Q⟩/πa²"
    )
    collapse_fraction: float = Field(
        0.2, gt=0, lt=1, description="collapse: stiffness first below this fraction of the plateau"
    )
    # issue 13: the oscillation cycle and the multi-load fit. Each field is left out of the
    # dumped config at its default, so the fingerprints of existing runs are unchanged.
    cycle: bool = Field(
        False,
        exclude_if=lambda value: value is False,
        description="steady load-controlled cycle per p0: loops, dissipated energy per cycle, "
        "lock-in stiffness Q_amp/u'_1 and quadrature u''_1 (summary.json 'cycle', contact.nc)",
    )
    model: Literal["modified", "classical"] = Field(
        "modified",
        exclude_if=lambda value: value == "modified",
        description="model of the cycle: modified (the paper's Mindlin model) or classical "
        "(Cattaneo-Mindlin, friction coefficient mu = k, Johnson's G*_J = G*/4)",
    )
    cycle_amplitude_fractions: list[float] = Field(
        list(CYCLE_AMPLITUDE_FRACTIONS),
        exclude_if=lambda value: list(value) == list(CYCLE_AMPLITUDE_FRACTIONS),
        description="force amplitudes of the cycle as fractions of the gross-sliding force, "
        "each in (0, 1)",
    )
    cycle_amplitudes_un: list[float] | None = Field(
        None,
        exclude_if=lambda value: value is None,
        description="force amplitudes of the cycle in uN (each below gross sliding at every "
        "p0); null: cycle_amplitude_fractions",
    )
    fit_csv: list[str] = Field(
        [],
        exclude_if=lambda value: not value,
        description="measured stiffness CSVs to fit at several loads at once (one per load, "
        "or with a load column 'p0 [GPa]'/'normal load [uN]'; relative to the config file)",
    )
    fit_p0_gpa: list[float] | None = Field(
        None,
        exclude_if=lambda value: value is None,
        description="p0 (GPa) of each fit_csv file without a load column, one per file",
    )
    fit_free: list[str] = Field(
        ["tau0_mpa"],
        exclude_if=lambda value: list(value) == ["tau0_mpa"],
        description="parameters the fit frees (tau0_mpa, k_mpa_per_gpa, mu_mpa_per_gpa, "
        "sigma0_mpa, shear_modulus_gpa); the rest are held at their values",
    )
    fit_fixed: list[str] = Field(
        [],
        exclude_if=lambda value: not value,
        description="parameters the fit must hold (checked against fit_free)",
    )
    fit_stiffness: Literal["lockin", "paper"] = Field(
        "lockin",
        exclude_if=lambda value: value == "lockin",
        description="model stiffness the fit compares with the data: lockin (Q_amp/u'_1, "
        "what a lock-in amplifier reads) or paper (d<Q>/d<u>)",
    )

    @field_validator("cycle_amplitude_fractions")
    @classmethod
    def _fractions(cls, value: list[float]) -> list[float]:
        if not value or any(not 0.0 < v < 1.0 for v in value):
            raise ValueError(
                f"expected fractions of the gross-sliding force in (0, 1), got {_show(value)}"
            )
        return [float(v) for v in value]

    @field_validator("cycle_amplitudes_un")
    @classmethod
    def _amplitudes(cls, value: list[float] | None) -> list[float] | None:
        if value is not None and (not value or any(not v > 0 for v in value)):
            raise ValueError(f"expected positive force amplitudes in uN, got {_show(value)}")
        return value

    @field_validator("p0_gpa")
    @classmethod
    def _p0(cls, value: list[float]) -> list[float]:
        if not value or any(not v > 0 for v in value):
            raise ValueError(f"expected positive peak pressures in GPa, got {_show(value)}")
        return [float(v) for v in value]


_LAW_KEYS = ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa")
#: Measured for the bundled sio2-snap + Hamaker-calibrated LJ on the α-quartz (0001) dense
#: interface (docs/convergence.md, docs/teachers.md): per form, the largest change of each law
#: coefficient under one refinement (grid 8→12 at 6 layers, 12→16 and 16→20 at 9 layers,
#: thicknesses 20→30, fmax 0.005→0.0025 at 6 and at 9 layers, LJ cutoff 14→18 Å, slab layers
#: 9→12) and half the max − min range over the two
#: bundled SNAPs (sio2-snap, sio2-snap-mf0) and their teachers CHGNet r2SCAN and SevenNet-MF-0
#: r2SCAN (4×4 grid, an upper bound). Regenerated from benchmarks/convergence/results by
#: ``python -m benchmarks.convergence.uncertainty`` (tests/convergence/test_measured_uncertainty.py).
MEASURED_LAW_UNCERTAINTY = {
    "convergence_internal": {
        "k_mpa_per_gpa": 11.5,
        "tau0_mpa": 8.45,
        "mu_mpa_per_gpa": 1.37,
        "sigma0_mpa": 0.888,
    },
    "convergence_enthalpy": {
        "k_mpa_per_gpa": 2.45,
        "tau0_mpa": 2.15,
        "mu_mpa_per_gpa": 0.115,
        "sigma0_mpa": 0.227,
    },
    "model_spread_internal": {
        "k_mpa_per_gpa": 2.38,
        "tau0_mpa": 2.34,
        "mu_mpa_per_gpa": 0.90,
        "sigma0_mpa": 1.05,
    },
    "model_spread_enthalpy": {
        "k_mpa_per_gpa": 2.75,
        "tau0_mpa": 2.76,
        "mu_mpa_per_gpa": 0.82,
        "sigma0_mpa": 0.829,
    },
    "source": "measured for the bundled sio2-snap + Hamaker LJ, alpha-quartz (0001) dense, "
    "paper-preset settings (docs/convergence.md, docs/teachers.md); a lower bound for coarser "
    "grids, not a measurement for another model or surface",
}


class UncertaintyConfig(_Section):
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
    coverage: float = Field(1.0, gt=0, description="multiple of the combined standard error")
    source: str = Field("", description="where the δ_conv and δ_model numbers come from")

    @field_validator(
        "convergence_internal",
        "convergence_enthalpy",
        "model_spread_internal",
        "model_spread_enthalpy",
    )
    @classmethod
    def _coefficients(cls, value: dict[str, float]) -> dict[str, float]:
        for key, v in value.items():
            if key not in _LAW_KEYS:
                raise ValueError(f"{key!r}: expected law coefficients among {', '.join(_LAW_KEYS)}")
            if not (v == v and 0.0 <= float(v) < float("inf")):
                raise ValueError(f"{key} = {_show(v)}: expected a finite value >= 0")
        return {k: float(v) for k, v in value.items()}


class ReportConfig(_Section):
    """The HTML report (stage ``report``)."""

    title: str = Field("flatcontact run", description="report title")
    fig2_p_gpa: list[float] | None = Field(
        None,
        description="pressures (GPa, among analysis.p_gpa) with a Fig. 2 panel; null: lowest, "
        "middle and highest",
    )
    svg: bool = Field(True, description="also write SVG figures next to the PNGs")


class RunConfig(_Section):
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
    report: ReportConfig = Field(
        default_factory=ReportConfig, description="the HTML report and figures (stage report)"
    )

    @field_validator("structure", mode="before")
    @classmethod
    def _structure(cls, value: Any) -> Any:
        return _structure_section(value)

    @model_validator(mode="before")
    @classmethod
    def _calculator_section(cls, data: Any) -> Any:
        """The earlier top-level ``calculator: {target, kwargs}`` becomes the model's."""
        if isinstance(data, dict) and "calculator" in data:
            data = dict(data)
            calc = data.pop("calculator")
            if calc is not None:
                if not isinstance(calc, dict):
                    raise ValueError(f"calculator: expected a mapping, got {_show(calc)}")
                data["potential"] = {"calculator": {**calc, "scope": "interface"}}
        return data

    @property
    def calculator(self) -> CalculatorConfig | None:
        """The whole-interface ASE calculator of the model, if it is one (earlier section)."""
        calc = self.potential.calculator
        if calc is None or calc.scope != "interface":
            return None
        return CalculatorConfig(target=calc.target, kwargs=calc.kwargs)

    @model_validator(mode="after")
    def _cross(self) -> RunConfig:
        if self.structure.kind == "toy-lj" and self.calculator is None:
            raise ValueError(
                "structure.kind 'toy-lj' needs calculator.target: flatcontact.ispes.toy:toy_calculator"
            )
        fig = self.report.fig2_p_gpa
        if fig is not None and any(p not in self.analysis.p_gpa for p in fig):
            raise ValueError(
                f"report.fig2_p_gpa {_show(fig)} must be among analysis.p_gpa {_show(self.analysis.p_gpa)}"
            )
        return self

    def section(self, name: str) -> dict:
        """JSON-ready dict of one section (``None`` sections as ``None``)."""
        value = getattr(self, name)
        return None if value is None else json.loads(value.model_dump_json())

    def to_dict(self) -> dict:
        """The whole configuration as plain JSON-ready data."""
        return json.loads(self.model_dump_json())


# --------------------------------------------------------------------------- presets


def default_potential() -> dict:
    """The default interaction model: the bundled SiO₂ SNAP if present, else Vashishta 1990.

    Vashishta is the best validated silica model shipped with LAMMPS here: relaxed
    α-quartz a = 4.829 Å (exp. 4.916) and it keeps the dense (0001) reconstruction
    defect-free through the interface relaxation (verified by the builder).

    The cross-interface LJ takes the Tkatchenko–Scheffler C6 and radii, with every C6 scaled
    so that its pairwise Hamaker constant equals Lifshitz theory's for α-quartz
    (:data:`QUARTZ_HAMAKER_ZJ`): free-atom C6 give 411 zJ, 4.7× too much, because Si in SiO₂
    is far less polarisable than a free Si atom. The paper took in-solid C6 from vdW-DFT, which
    we cannot run here; this calibration is the measured-data stand-in. Measured on the quick
    preset: free-atom C6 give τ0 = 191 ± 12 MPa and W = 0.29 J/m², the calibrated LJ
    τ0 = 29 ± 25 MPa (paper: 26.7). ``potential.lj.hamaker_zj: null`` restores free atoms.
    """
    from flatcontact.potentials.lj import ALPHA_QUARTZ_NUMBER_DENSITY_PER_NM3

    snap = BUNDLED_DIR / BUNDLED_SNAP / f"{BUNDLED_SNAP}.snapcoeff"
    intra = f"snap:{BUNDLED_SNAP}" if snap.is_file() else "vashishta"
    densities = {k: round(float(v), 3) for k, v in ALPHA_QUARTZ_NUMBER_DENSITY_PER_NM3.items()}
    return {
        "intra": intra,
        "lj": {
            "c6_source": "ts",
            "hamaker_zj": QUARTZ_HAMAKER_ZJ,
            "number_density_per_nm3": densities,
            "cutoff_angstrom": 10.0,
        },
    }


def _dense_slab_source() -> str:
    """``shipped`` if the CHGNet-relaxed 6-layer dense slab is installed, else ``seed``.

    Both presets start from the shipped slab: the bundled SNAP keeps that dense surface but
    does not reach it from a seeded cut on its own (measured), and 6 layers is the paper's
    slab.
    """
    from flatcontact.structures.build import SHIPPED_DENSE_SLAB

    return "shipped" if SHIPPED_DENSE_SLAB.is_file() else "seed"


def preset(name: str) -> dict:
    """The raw data of preset ``name`` (``quick`` or ``paper``) as a nested dict."""
    if name == "quick":
        return {
            "preset": "quick",
            "structure": {"kind": "quartz-dense", "layers": 6, "source": _dense_slab_source()},
            "potential": default_potential(),
            "scan": {
                "grid": [12, 12],
                "p_range_gpa": {"lo_gpa": -0.3, "hi_gpa": 4.5, "n": 12},
                "fmax_ev_per_angstrom": 0.005,
            },
            "analysis": {"p_gpa": [0.0, 0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5]},
            "contact": {"p0_gpa": [0.5, 1.0, 1.77, 2.0, 3.0]},
            "report": {"title": "flatcontact run (quick preset)"},
        }
    if name == "paper":
        # Measured in docs/convergence.md: one refinement of the 12x12 grid or the 20
        # thicknesses moves every per-load τ and σ_MSS by < 3 % (enthalpy form); the LJ tail
        # beyond 10 Å adds 16 % to W, beyond 18 Å 2.8 %, so the cutoff is 18 Å here. Slabs:
        # 6 -> 9 O-Si-O layers lowers every enthalpy-form τ by 11-24 % and σ by 3-18 %, 9 -> 12
        # moves them by <= 2.6 % (at fmax 0.0025, where the 12-layer stack's relaxation noise
        # is resolved; halving fmax at 9 layers moves them by <= 2.1 %), so 9 layers (the paper
        # used 6). Thicknesses: loads to 5.19 GPa at the 0.305 GPa spacing of 20 thicknesses
        # over -0.3 ... 5.5 (the range of the convergence study's 9-layer runs).
        potential = default_potential()
        potential["lj"] = {**potential["lj"], "cutoff_angstrom": 18.0}
        return {
            "preset": "paper",
            "structure": {"kind": "quartz-dense", "layers": 9, "source": _dense_slab_source()},
            "potential": potential,
            "scan": {
                "grid": [12, 12],
                "p_range_gpa": {"lo_gpa": -0.3, "hi_gpa": round(-0.3 + 18 * 5.8 / 19, 6), "n": 19},
                "fmax_ev_per_angstrom": 0.005,
            },
            "analysis": {"p_gpa": [0.0, 0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 4.5]},
            "contact": {"p0_gpa": [0.5, 1.0, 1.5, 1.77, 2.0, 2.5, 3.0]},
            "uncertainty": copy.deepcopy(MEASURED_LAW_UNCERTAINTY),
            "report": {"title": "flatcontact run (paper preset)", "fig2_p_gpa": [0.5, 1.0, 3.0]},
        }
    raise InputError(f"preset: expected quick or paper, got {name!r}")


def merge_config(base: dict, over: dict) -> dict:
    """``over`` laid over ``base`` (nested mappings merged, everything else replaced).

    Top-level sections that start afresh instead of merging: a ``structure`` of another
    ``kind`` (none of the old recipe's fields apply) and a ``potential`` that defines a whole
    model (:func:`_replaces_model`: a preset, a calculator, a coupling, LAMMPS styles).
    """
    out = copy.deepcopy(base)
    for key, value in over.items():
        if isinstance(value, dict) and isinstance(out.get(key), dict):
            old = out[key]
            if key == "structure" and value.get("kind", old.get("kind")) != old.get("kind"):
                out[key] = {}
            elif key == "potential" and "preset" in old and _replaces_model(value):
                out[key] = {}
        if isinstance(value, dict) and isinstance(out.get(key), dict) and key != "kwargs":
            # an explicit pressure range or thickness list replaces the other
            if key == "scan":
                if "thickness_angstrom" in value:
                    out[key].pop("p_range_gpa", None)
                if "p_range_gpa" in value:
                    out[key].pop("thickness_angstrom", None)
            out[key] = merge_config(out[key], value)
        else:
            out[key] = copy.deepcopy(value)
    return out


_MESSAGES = {
    "greater_than": "expected a value > {gt}",
    "greater_than_equal": "expected a value >= {ge}",
    "less_than": "expected a value < {lt}",
    "less_than_equal": "expected a value <= {le}",
    "float_parsing": "expected a number",
    "float_type": "expected a number",
    "finite_number": "expected a finite number",
    "int_parsing": "expected an integer",
    "int_type": "expected an integer",
    "int_from_float": "expected an integer",
    "bool_parsing": "expected true or false",
    "bool_type": "expected true or false",
    "string_type": "expected a string",
    "list_type": "expected a list",
    "tuple_type": "expected a list",
    "dict_type": "expected a mapping",
    "model_type": "expected a mapping",
    "model_attributes_type": "expected a mapping",
    "literal_error": "expected {expected}",
    "extra_forbidden": "unknown field",
    "missing": "required field missing",
}


def _one_line(exc: ValidationError, source: str) -> InputError:
    """The first pydantic error as ``<source>: <dotted.path>: expected ..., got <value>``."""
    first = exc.errors()[0]
    # union members (direction_deg: float | 'auto') name their type in the path: drop them
    loc = [
        str(p)
        for p in first.get("loc", ())
        if not str(p).startswith(("function-", "literal[")) and str(p) not in ("float", "int")
    ]
    where = ".".join(loc)
    kind = first.get("type", "")
    if kind in _MESSAGES:
        try:
            msg = _MESSAGES[kind].format(**first.get("ctx", {}))
        except (KeyError, IndexError):
            msg = str(first.get("msg", "invalid"))
        if kind not in ("extra_forbidden", "missing"):
            msg += f", got {_show(first.get('input'))}"
    else:
        msg = str(first.get("msg", "invalid")).removeprefix("Value error, ")
        field, sep, rest = msg.partition(": ")
        if sep and field.isidentifier() and field.islower() and where:
            where, msg = f"{where}.{field}", rest  # a model check naming its field
        if where == "potential" and msg.startswith("potential "):  # PotentialSpec's InputError
            return InputError(f"{source}: potential.{msg.removeprefix('potential ')}")
    return InputError(f"{source}: {where}: {msg}" if where else f"{source}: {msg}")


def build_config(
    data: dict | None = None, preset_name: str | None = None, source: str = "config"
) -> RunConfig:
    """A validated :class:`RunConfig` from ``data`` laid over a preset.

    Parameters
    ----------
    data
        Nested mapping as read from YAML (may be empty or ``None``).
    preset_name
        ``quick`` or ``paper``; overrides ``data['preset']``; default ``quick``.
    source
        Name used in error messages (the file path).
    """
    data = dict(data or {})
    name = preset_name or data.pop("preset", None) or "quick"
    data.pop("preset", None)
    if name not in ("quick", "paper"):
        raise InputError(f"{source}: preset: expected quick or paper, got {_show(name)}")
    base = preset(name)
    if _replaces_model(data.get("potential")):
        base.pop("potential")  # a preset, a calculator or new styles: not the default's LJ
    merged = merge_config(base, data)
    try:
        return RunConfig.model_validate(merged)
    except ValidationError as exc:
        raise _one_line(exc, source) from None
    except InputError as exc:  # PotentialSpec's own one-line errors ("potential intra: ...")
        text = str(exc)
        if text.startswith("potential "):
            text = "potential." + text.removeprefix("potential ")
        raise InputError(f"{source}: {text}") from None


def _replaces_model(section: Any) -> bool:
    """Whether a ``potential`` section defines a whole model rather than editing the default.

    A preset (``preset:`` or a preset name as ``intra``), a calculator, a coupling or
    LAMMPS styles replace the default model; ``intra: vashishta`` or ``lj: {...}`` alone
    edit it (they keep the quartz default's Hamaker-calibrated LJ).
    """
    from flatcontact.potentials.presets import PRESETS

    if not isinstance(section, dict):
        return False
    intra = section.get("intra")
    return (
        any(section.get(k) is not None for k in ("preset", "calculator", "coupling", "interlayer"))
        or (isinstance(intra, str) and intra.strip() in PRESETS)
        or (intra is not None and not isinstance(intra, str))
    )


#: Largest configuration file read (bytes): a run configuration is a few kB.
MAX_CONFIG_BYTES = 1_000_000
#: Deepest nesting of a configuration (sections are 3 levels deep; kwargs a few more).
MAX_CONFIG_DEPTH = 32


class _StrictLoader(yaml.SafeLoader):
    """``yaml.SafeLoader`` that refuses a key given twice in one mapping.

    Plain YAML keeps the last value, so a second ``scan:`` silently replaced the first.
    """

    def construct_mapping(self, node, deep=False):
        seen: dict[Any, int] = {}
        for key_node, _ in node.value:
            key = self.construct_object(key_node, deep=deep)
            try:
                hash(key)
            except TypeError:
                continue  # SafeLoader refuses it itself, with its own message
            if key in seen:
                raise _DuplicateKey(key, key_node.start_mark.line + 1, seen[key])
            seen[key] = key_node.start_mark.line + 1
        return super().construct_mapping(node, deep=deep)


_StrictLoader.add_constructor(
    yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _StrictLoader.construct_mapping
)


class _DuplicateKey(Exception):
    def __init__(self, key: Any, line: int, first: int):
        super().__init__(key, line, first)
        self.key, self.line, self.first = key, line, first


def _depth(value: Any, limit: int, level: int = 0) -> int:
    """Nesting depth of ``value`` (lists and mappings), stopping once past ``limit``."""
    if level > limit:
        return level
    if isinstance(value, dict):
        items = list(value.values())
    elif isinstance(value, list):
        items = value
    else:
        return level
    return max([_depth(v, limit, level + 1) for v in items], default=level + 1)


def parse_yaml(text: str, source: str) -> Any:
    """YAML ``text`` as data; duplicate keys, bad syntax and deep nesting are one-line errors."""
    try:
        data = yaml.load(text, Loader=_StrictLoader)
    except _DuplicateKey as dup:
        raise InputError(
            f"{source}: key {_show(dup.key)} given twice (lines {dup.first} and {dup.line}); "
            "expected each key once"
        ) from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" (line {mark.line + 1})" if mark is not None else ""
        problem = getattr(exc, "problem", None)
        raise InputError(
            f"{source}: not valid YAML{where}" + (f": {problem}" if problem else "")
        ) from None
    except RecursionError:
        raise InputError(
            f"{source}: nested deeper than {MAX_CONFIG_DEPTH} levels; expected a mapping of sections"
        ) from None
    if _depth(data, MAX_CONFIG_DEPTH) > MAX_CONFIG_DEPTH:
        raise InputError(
            f"{source}: nested deeper than {MAX_CONFIG_DEPTH} levels; expected a mapping of sections"
        )
    return data


def load_config(path: str | Path | None = None, preset_name: str | None = None) -> RunConfig:
    """Read and validate a run configuration (YAML); ``None`` gives the preset alone.

    Relative paths inside the file (``structure.file``, ``contact.experiment_csv``) are
    resolved against the file's directory. Every problem is one :class:`InputError` line
    naming the file and the field path: a file that is missing, a directory, unreadable,
    larger than :data:`MAX_CONFIG_BYTES`, not UTF-8, not YAML, nested deeper than
    :data:`MAX_CONFIG_DEPTH` or with a key given twice; a field out of range or above a size
    bound (:mod:`flatcontact.limits`); a file field naming no readable file.
    """
    if path is None:
        return build_config({}, preset_name, "default config")
    path = Path(path)
    data = parse_yaml(read_text_file(path, "config file", MAX_CONFIG_BYTES), str(path))
    if data is None:
        data = {}
    if not isinstance(data, dict):
        raise InputError(f"{path}: expected a mapping of sections, got {type(data).__name__}")
    for section, key in _FILE_FIELDS:
        block = data.get(section)
        if isinstance(block, dict) and isinstance(block.get(key), str):
            block[key] = _resolved(block[key], path.parent)
    structure = data.get("structure")
    if isinstance(structure, dict):
        _resolve_recipe_files(structure, path.parent)
    _resolve_file_lists(data, path)
    try:
        cfg = build_config(data, preset_name, str(path))
    except RecursionError:
        raise InputError(f"{path}: nested too deeply; expected a mapping of sections") from None
    for section, key in _FILE_FIELDS:
        value = getattr(getattr(cfg, section), key)
        if value is None:
            continue
        target = Path(value)
        if not target.exists():
            raise InputError(f"{path}: {section}.{key}: file {value} not found")
        if not target.is_file():
            raise InputError(f"{path}: {section}.{key}: {value} is not a regular file")
    for dotted, value in recipe_files(cfg.structure):
        if not Path(value).exists():
            raise InputError(f"{path}: structure.{dotted}: file {value} not found")
        if not Path(value).is_file():
            raise InputError(f"{path}: structure.{dotted}: {value} is not a regular file")
    for section, key in _FILE_LIST_FIELDS:
        for value in getattr(getattr(cfg, section), key):
            if not Path(value).is_file():
                raise InputError(f"{path}: {section}.{key}: file {value} not found")
    return cfg


def _resolved(value: str, base: Path) -> str:
    target = Path(value).expanduser()
    return str(target if target.is_absolute() else (base / target).resolve())


def _resolve_recipe_files(structure: dict, base: Path) -> None:
    """Make the recipe's file fields (``file``, ``bulk``, ``sheet``, ``slab2.*``) relative to
    ``base``, in place; built-in sheet names (graphene, h-BN, MoS2) stay names."""
    from flatcontact.structures.sheets import BUILTIN_SHEETS

    for dotted in _RECIPE_FILE_FIELDS:
        *parents, leaf = dotted.split(".")
        holder: Any = structure
        for part in parents:
            holder = holder.get(part) if isinstance(holder, dict) else None
        if isinstance(holder, dict) and isinstance(holder.get(leaf), str):
            if holder[leaf] not in BUILTIN_SHEETS:
                holder[leaf] = _resolved(holder[leaf], base)


def recipe_files(recipe: Any) -> list[tuple[str, str]]:
    """(dotted field, path) of every file the recipe reads (built-in sheets excluded)."""
    from flatcontact.structures.sheets import BUILTIN_SHEETS

    out = []
    for dotted in _RECIPE_FILE_FIELDS:
        obj = recipe
        for part in dotted.split("."):
            obj = getattr(obj, part, None)
        if isinstance(obj, str) and obj not in BUILTIN_SHEETS:
            out.append((dotted, obj))
    return out


def check_inputs(cfg: RunConfig, source: str = "config") -> None:
    """Every check of ``cfg`` that needs its files or imports, before any stage runs.

    ``flatcontact config --check`` and :class:`flatcontact.pipeline.Pipeline` both call it,
    so the check refuses what a run would refuse before its first stage: an interface file
    that does not follow the contract (or has more atoms than the ``atoms`` bound), a
    measured stiffness CSV that does not parse, a calculator that does not import, a model
    that cannot compute the elastic stage's crystal.

    Raises
    ------
    InputError
        One line naming ``source``'s field and the file.
    """
    from flatcontact.stages import _calculator

    if cfg.structure.kind in ("file", "slab") and getattr(cfg.structure, "file", None) is not None:
        _check_structure_file(cfg, source)
    if cfg.contact.experiment_csv is not None:
        from flatcontact.contact.experiment import load_stiffness_csv

        try:
            load_stiffness_csv(cfg.contact.experiment_csv)
        except InputError as exc:
            raise InputError(f"{source}: contact.experiment_csv: {exc}") from None
    if cfg.contact.fit_csv:
        from flatcontact.stages.contact import check_fit_settings

        check_fit_settings(cfg)
    calc = cfg.potential.calculator
    if calc is not None:
        try:
            from flatcontact.potentials.loader import load_callable

            cfg.potential.calculator_factory()
            load_callable(calc.target)
        except InputError as exc:
            raise InputError(f"{source}: potential.calculator.target: {exc}") from None
    from flatcontact.stages.build import structure_elements
    from flatcontact.stages.contact import check_moduli_source

    if cfg.structure.kind == "file":
        from flatcontact.structures.interface_io import read_interface

        _calculator.check_atoms(cfg, read_interface(cfg.structure.file))
    check_moduli_source(cfg, structure_elements(cfg.structure))
    if cfg.elastic.enabled:
        from flatcontact.stages.elastic import bulk_crystal

        bulk, _ = bulk_crystal(cfg.structure)
        if bulk is None:
            _calculator.check(cfg)
        else:
            _calculator.check_atoms(cfg, bulk)


def _check_structure_file(cfg: RunConfig, source: str) -> None:
    """structure.file: readable, within the ``atoms`` bound, and (kind file) an interface."""
    from flatcontact.structures.interface_io import read_interface

    file = Path(cfg.structure.file)
    field = f"{source}: structure.file"
    try:
        with file.open("rb") as handle:
            handle.read(1)
    except OSError as exc:
        raise InputError(f"{field}: {file}: cannot read ({exc.strerror})") from None
    if cfg.structure.kind == "file":
        try:
            atoms = read_interface(file)
        except InputError as exc:
            raise InputError(f"{field}: {exc}") from None
        except Exception as exc:  # ASE readers raise anything on garbage
            raise InputError(
                f"{field}: {file}: not a readable interface.extxyz ({type(exc).__name__})"
            ) from None
        n = len(atoms)
    else:
        import ase.io

        try:
            n = len(ase.io.read(file))
        except Exception as exc:  # ASE readers raise anything on garbage
            raise InputError(
                f"{field}: {file}: not a structure file ASE can read ({type(exc).__name__})"
            ) from None
    if n > limits.bound("atoms"):
        raise InputError(f"{field}: {limits.message('atoms', n, f'atoms in {file.name}')}")


def _resolve_file_lists(data: dict, path: Path) -> None:
    """Relative entries of the list-of-files fields, against the config file's directory."""
    for section, key in _FILE_LIST_FIELDS:
        block = data.get(section)
        if isinstance(block, dict) and isinstance(block.get(key), list):
            block[key] = [
                str((path.parent / Path(v).expanduser()).resolve()) if isinstance(v, str) else v
                for v in block[key]
            ]


#: Fields naming an input file (relative to the config file); they must exist.
_FILE_FIELDS = (("contact", "experiment_csv"),)
#: Fields naming a list of input files (each relative to the config file).
_FILE_LIST_FIELDS = (("contact", "fit_csv"),)


# --------------------------------------------------------------------------- YAML out


def _descriptions(model: type[BaseModel]) -> dict[str, str]:
    return {name: (f.description or "") for name, f in model.model_fields.items()}


def _section_model(name: str) -> type[BaseModel] | None:
    ann = RunConfig.model_fields[name].annotation
    for cand in (
        InteractionModel,
        ScanConfig,
        AnalysisConfig,
        ElasticConfig,
        ContactConfig,
        ReportConfig,
    ):
        if ann is cand or (hasattr(ann, "__args__") and cand in ann.__args__):
            return cand
    return None


def _yaml_value(value: Any) -> str:
    return (
        yaml.safe_dump(value, default_flow_style=True, allow_unicode=True, width=1000)
        .strip()
        .removesuffix("\n...")
        .removesuffix("...")
        .strip()
    )


def _with_defaults_shown(config: RunConfig) -> dict:
    """``config.to_dict()`` with the fields a section leaves out of its dump at their default
    (``exclude_if``, to keep fingerprints) put back, so the YAML shows every setting."""
    data = config.to_dict()
    out: dict = {}
    for name in type(config).model_fields:
        section = getattr(config, name)
        if not isinstance(section, _Section):
            if name in data:
                out[name] = data[name]
            continue
        dumped = data.get(name, {})
        out[name] = {
            field: dumped[field]
            if field in dumped
            else json.loads(json.dumps(getattr(section, field), default=str))
            for field in type(section).model_fields
        }
    return out


def to_yaml(config: RunConfig, comments: bool = True) -> str:
    """The configuration as YAML, with each field's description as a comment above it."""
    # the commented YAML documents every setting; the bare one is exactly to_dict()
    data = _with_defaults_shown(config) if comments else config.to_dict()
    lines = [
        "# flatcontact run configuration (units in the names: GPa, MPa, Å, eV, µm, J/m²)",
        "# values not given in a file come from the preset",
    ]
    top = _descriptions(RunConfig)
    for key, value in data.items():
        if comments and top.get(key):
            lines.append(f"# {top[key]}")
        if not isinstance(value, dict):
            lines.append(f"{key}: {_yaml_value(value)}")
            continue
        lines.append(f"{key}:")
        obj = getattr(config, key, None)
        model = type(obj) if key == "structure" else _section_model(key)
        desc = _descriptions(model) if model is not None else {}
        for sub, subval in value.items():
            if comments and desc.get(sub):
                lines.append(f"  # {desc[sub]}")
            if isinstance(subval, dict) and subval:
                lines.append(f"  {sub}:")
                for k2, v2 in subval.items():
                    lines.append(f"    {k2}: {_yaml_value(v2)}")
            else:
                lines.append(f"  {sub}: {_yaml_value(subval)}")
    return "\n".join(lines) + "\n"
