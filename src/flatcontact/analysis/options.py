"""How an ISPES grid is analysed: the choices of :func:`flatcontact.analysis.analyze.analyze_ispes`.

:class:`AnalysisOptions` is a frozen dataclass validated on construction (and on
:func:`dataclasses.replace`): a bad value raises one :class:`~flatcontact.foundation.errors.InputError`
line naming the field (``form: expected one of internal, enthalpy, got 'gibbs'``), which the
run's analyze stage renames to its settings path (``analysis.energy_form``). The loads are not
an option: they are the analysis's subject (``analyze_ispes(ds, p_gpa, options)``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flatcontact.analysis.constant_pressure import DEFAULT_LOAD_SOURCE, FORMS, LOAD_SOURCES
from flatcontact.foundation.errors import InputError

#: Where each load's landscape is zeroed (:attr:`AnalysisOptions.energy_zero`).
ENERGY_ZEROS = ("lowest-p", "each", "none")
#: ``direction_deg`` value that asks for the lowest-barrier direction.
AUTO_DIRECTION = "auto"


@dataclass(frozen=True)
class AnalysisOptions:
    """The analysis's choices, each with its unit; the defaults are the paper's analysis.

    Attributes
    ----------
    direction_deg
        Pulling direction, degrees from x (90 = y, the paper's), or ``"auto"``: the
        lowest-barrier direction of the landscape at the lowest load (needs
        ``with_stackings``; :data:`flatcontact.analysis.analyze.AUTO_DIRECTION_RULE`).
    form
        Constant-pressure energy form: ``"internal"`` (the paper's Ũ = U(z*)) or
        ``"enthalpy"`` (U/A + P·z*) (:mod:`flatcontact.analysis.energy_forms`).
    energy_zero
        Energy zero of the landscapes: ``"lowest-p"`` (the global minimum at the lowest load,
        for all loads), ``"each"`` (each load's own minimum) or ``"none"`` (absolute).
    load_source
        ``"energy"``: the load is ``-(1/A) dU/dz`` of the energy spline per column;
        ``"stress"``: the stored ``normal_stress`` (:mod:`flatcontact.analysis.noise`).
    allow_missing
        Interpolate columns with missing thickness points instead of refusing them.
    threshold_gpa
        Upper end (GPa) of the load range of the linear fits τ = k·P + τ0, σ = μ·P + σ0;
        ``None``: no fit (``AnalysisResult.laws`` is ``None``; the run's laws stage fits them).
    max_length_angstrom
        Tracking limit of the sliding path (Å); ``None``:
        :func:`flatcontact.analysis.path.default_max_length`.
    with_mep
        Also compute the string-method minimum-energy path per load.
    with_symmetry
        Also compute the symmetry report per load (:mod:`flatcontact.analysis.symmetry`).
    with_stackings
        Find, classify and name the stationary points of each landscape and the MEP barrier
        (:mod:`flatcontact.analysis.stackings`); equivalent minima become starts
        (:mod:`flatcontact.analysis.starts`).
    symmetrise
        Average each load's interpolant over the shift-space group the grid stores
        (:func:`flatcontact.ispes.contract.symmetry_operations`); a grid without one is
        interpolated as it is.
    with_grid_error
        Estimate the grid's discretisation error of τ, σ_MSS and G_int from the same samples
        (:func:`flatcontact.analysis.grid_error.estimate_grid_error`).
    """

    direction_deg: float | str = 90.0
    form: str = "internal"
    energy_zero: str = "lowest-p"
    load_source: str = DEFAULT_LOAD_SOURCE
    allow_missing: bool = False
    threshold_gpa: float | None = 3.0
    max_length_angstrom: float | None = None
    with_mep: bool = False
    with_symmetry: bool = True
    with_stackings: bool = True
    symmetrise: bool = True
    with_grid_error: bool = True

    def __post_init__(self) -> None:
        direction = self.direction_deg
        auto = isinstance(direction, str)
        if auto and direction != AUTO_DIRECTION:
            raise InputError(
                f"direction_deg: expected an angle in degrees or {AUTO_DIRECTION!r}, got {direction!r}"
            )
        if auto and not self.with_stackings:
            raise InputError(
                "direction_deg auto: needs the stackings analysis (the lowest-barrier direction)"
            )
        if not auto and not np.isfinite(direction):
            raise InputError(f"direction_deg: expected a finite angle, got {direction}")
        if self.form not in FORMS:
            raise InputError(f"form: expected one of {', '.join(FORMS)}, got {self.form!r}")
        if self.energy_zero not in ENERGY_ZEROS:
            raise InputError(
                f"energy_zero: expected one of {', '.join(ENERGY_ZEROS)}, got {self.energy_zero!r}"
            )
        if self.threshold_gpa is not None and not self.threshold_gpa > 0:
            raise InputError(
                f"threshold_gpa: expected a positive pressure, got {self.threshold_gpa}"
            )
        if self.load_source not in LOAD_SOURCES:
            raise InputError(
                f"load_source: expected one of {', '.join(LOAD_SOURCES)}, got {self.load_source!r}"
            )

    @property
    def auto_direction(self) -> bool:
        """Is the direction the lowest-barrier one (``direction_deg="auto"``)?"""
        return isinstance(self.direction_deg, str)
