"""Stage 4, laws: τ = k·P + τ0 and σ = μ·P + σ0 fitted on P ≤ ``analysis.threshold_gpa``.

Both energy forms side by side: the configured ``analysis.energy_form`` from the
analyze stage's table, the other from its ``other_form.json`` (when the inputs carry it: the
analyze stage analysed the ISPES in both forms, nothing is analysed here); each with
intervals c ± h_c, h_c = coverage·√(se_fit² + δ_conv² + δ_model² + δ_grid²) from the fit, the
``uncertainty`` section and the grid's own error estimate per load (``friction.csv``
``tau_grid_error_mpa``, ``sigma_mss_grid_error_mpa``, and the same columns of
``other_form.json``; :mod:`flatcontact.analysis.grid_error`,
:func:`flatcontact.analysis.uncertainty.grid_law_components`).

The one place the load laws are fitted (:func:`flatcontact.analysis.laws.fit_load_laws`),
from the analyze stage's ``friction.csv``. Files: ``laws.json``
(:meth:`LawsResult.to_json`: the coefficients, standard errors, fitted range, regime ends
and the fit's warnings) and ``fig3_laws.png`` (+ ``.svg``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from flatcontact.foundation.fileio import write_json_atomic
from flatcontact.foundation.layout import LAWS_FIGURE, LAWS_JSON
from flatcontact.stages._common import captured, save

_COLUMNS = ("p_gpa", "tau_mpa", "sigma_mss_mpa")
#: ``friction.csv``'s per-load grid estimates of τ and σ_MSS (absent in older files).
_GRID_COLUMNS = ("tau_grid_error_mpa", "sigma_mss_grid_error_mpa")
FORMS = ("internal", "enthalpy")


@dataclass(frozen=True)
class LawsInputs:
    """τ and σ_MSS (MPa) per load P (GPa): the analyze stage's ``friction.csv``
    (:meth:`read`) or an analysis in memory (:meth:`from_analysis`).

    ``other_form``: the analyze stage's ``other_form.json`` (the other energy form's per-load
    values, :func:`flatcontact.analysis.energy_forms.form_loads`); when given, its laws are
    fitted too (:func:`flatcontact.analysis.energy_forms.form_laws`), so ``laws.json`` has
    both forms side by side.
    """

    p_gpa: tuple[float, ...]
    tau_mpa: tuple[float, ...]
    sigma_mss_mpa: tuple[float, ...]
    other_form: Path | None = None
    tau_grid_error_mpa: tuple[float, ...] | None = None
    sigma_mss_grid_error_mpa: tuple[float, ...] | None = None

    @classmethod
    def read(cls, friction_csv: Path, other_form: Path | None = None) -> LawsInputs:
        """The columns of ``friction.csv`` (and the other energy form's ``other_form.json``);
        the grid estimates when the file has them (None otherwise: no grid part)."""
        import pandas as pd

        table = pd.read_csv(friction_csv)
        grid = [
            tuple(table[c].to_numpy(float)) if c in table.columns else None for c in _GRID_COLUMNS
        ]
        return cls(*(tuple(table[c].to_numpy(float)) for c in _COLUMNS), other_form, *grid)

    @classmethod
    def from_analysis(cls, analysis) -> LawsInputs:
        """The loads and columns of a :class:`flatcontact.analysis.analyze.AnalysisResult`."""
        grid = analysis.grid
        return cls(
            tuple(analysis.p_gpa),
            tuple(analysis.column("tau_mpa")),
            tuple(analysis.column("sigma_mss_mpa")),
            tau_grid_error_mpa=None if grid is None else tuple(grid.error["tau_mpa"]),
            sigma_mss_grid_error_mpa=None if grid is None else tuple(grid.error["sigma_mss_mpa"]),
        )


@dataclass
class LawsResult:
    """The fitted laws (:class:`flatcontact.analysis.laws.LoadLaws`), the data they were
    fitted to (P in GPa, τ and σ_MSS in MPa) and the fit's warnings."""

    laws: Any
    p_gpa: np.ndarray
    tau_mpa: np.ndarray
    sigma_mss_mpa: np.ndarray
    caught: list = field(default_factory=list)  # the fit's warnings.WarningMessage objects
    files: list[Path] = field(default_factory=list)
    form: str = "internal"  # the energy form of ``laws`` (analysis.energy_form)
    other: dict | None = None  # the other form: {"loads", "laws", "warnings"} (laws_both_forms)
    uncertainty: dict = field(default_factory=dict)  # settings.uncertainty as a dict
    grid: dict = field(default_factory=dict)  # form -> coefficient -> δ_grid (None: not estimated)

    @property
    def warnings(self) -> list[str]:
        """The fit's warnings (messages), as ``laws.json`` stores them."""
        return [str(w.message) for w in self.caught]

    def form_laws(self) -> dict[str, dict]:
        """Form -> its ``laws.json`` coefficients (the configured form first)."""
        out = {self.form: self.laws.to_json()}
        if self.other is not None:
            out[other_form(self.form)] = self.other["laws"]
        return out

    def half_widths(self, form: str) -> dict[str, float]:
        """Half-width of each coefficient of ``form``: fit, convergence and model spread in
        quadrature, times the coverage (:func:`flatcontact.analysis.uncertainty.law_half_widths`)."""
        from flatcontact.analysis.uncertainty import law_half_widths

        u = self.uncertainty
        return law_half_widths(
            self.form_laws()[form],
            convergence=u.get(f"convergence_{form}", {}),
            model=u.get(f"model_spread_{form}", {}),
            grid=self.grid.get(form),
            coverage=u.get("coverage", 1.0),
        )

    def to_json(self) -> dict:
        """``laws.json``: :meth:`LoadLaws.to_json` of the configured form and ``warnings`` at
        the top level (the contact stage reads these), ``energy_form``, ``intervals`` (the
        configured form's coefficients ± half-width), and one block per computed form
        (``internal``, ``enthalpy``: coefficients, standard errors, ``half_widths``,
        ``intervals``, per-load ``loads``, ``warnings``), with ``uncertainty`` stating the
        inputs (fit standard errors, ``convergence_<form>``, ``model_spread_<form>``,
        ``coverage``, ``source``) and ``grid`` the grid part of each form's coefficients
        (:func:`flatcontact.analysis.uncertainty.grid_law_components`)."""
        from flatcontact.analysis.uncertainty import law_components, law_intervals

        doc = {**self.laws.to_json(), "warnings": self.warnings, "energy_form": self.form}
        loads = {
            self.form: [
                {"p_gpa": float(p), "tau_mpa": float(t), "sigma_mss_mpa": float(s)}
                for p, t, s in zip(self.p_gpa, self.tau_mpa, self.sigma_mss_mpa, strict=True)
            ]
        }
        warns = {self.form: self.warnings}
        if self.other is not None:
            loads[other_form(self.form)] = self.other["loads"]
            warns[other_form(self.form)] = self.other["warnings"]
        for form, laws in self.form_laws().items():
            hw = self.half_widths(form)
            parts = law_components(
                laws,
                convergence=self.uncertainty.get(f"convergence_{form}", {}),
                model=self.uncertainty.get(f"model_spread_{form}", {}),
                grid=self.grid.get(form),
            )
            doc[form] = {
                **laws,
                "half_widths": hw,
                "intervals": law_intervals(laws, hw, parts),
                "loads": loads[form],
                "warnings": warns[form],
            }
        doc["intervals"] = doc[self.form]["intervals"]
        doc["uncertainty"] = {
            "combination": "half-width = coverage * sqrt(fit stderr^2 + convergence^2 + "
            "model_spread^2 + grid^2) per coefficient",
            **self.uncertainty,
            "grid": {
                "rule": "|slope| and |intercept| of the line through the per-load signed grid "
                "estimates (friction.csv tau_grid_error_mpa, sigma_mss_grid_error_mpa) on the "
                "fitted loads; null: not estimated",
                **{form: dict(parts) for form, parts in self.grid.items()},
            },
        }
        return doc


def other_form(form: str) -> str:
    """The energy form that is not ``form``."""
    return FORMS[1 - FORMS.index(form)]


def laws_stage(settings, inputs: LawsInputs, folder: Path | None, progress=None) -> LawsResult:
    """Fit the load laws to ``inputs`` on P ≤ ``settings.analysis.threshold_gpa``."""
    from flatcontact.analysis.diagnostics import AnalysisWarning
    from flatcontact.analysis.laws import fit_load_laws
    from flatcontact.analysis.uncertainty import grid_law_components

    p, tau, sigma = (
        np.asarray(v, dtype=float) for v in (inputs.p_gpa, inputs.tau_mpa, inputs.sigma_mss_mpa)
    )
    with captured(AnalysisWarning) as caught:
        laws = fit_load_laws(p, tau, sigma, settings.analysis.threshold_gpa)
    unc = getattr(settings, "uncertainty", None)
    result = LawsResult(
        laws,
        p,
        tau,
        sigma,
        list(caught),
        form=settings.analysis.energy_form,
        uncertainty=unc.model_dump() if unc is not None else {},
    )
    result.grid[result.form] = grid_law_components(
        p,
        tau,
        sigma,
        inputs.tau_grid_error_mpa,
        inputs.sigma_mss_grid_error_mpa,
        settings.analysis.threshold_gpa,
    )
    if inputs.other_form is not None:
        result.other = _other_form(settings, inputs.other_form)
        rows = result.other["loads"]

        def column(name: str):
            values = [r.get(name) for r in rows]
            return None if any(v is None for v in values) else [float(v) for v in values]

        result.grid[other_form(result.form)] = grid_law_components(
            column("p_gpa"),
            column("tau_mpa"),
            column("sigma_mss_mpa"),
            *(column(c) for c in _GRID_COLUMNS),
            settings.analysis.threshold_gpa,
        )
    if folder is not None:
        from flatcontact.plots.analysis import figure_laws

        folder.mkdir(parents=True, exist_ok=True)
        result.files.append(write_json_atomic(folder / LAWS_JSON, result.to_json()))
        fig = figure_laws(p, tau, sigma, laws, half_widths=result.half_widths(result.form))
        result.files += save(fig, folder, LAWS_FIGURE, settings.report.svg)
    return result


def _other_form(settings, other_form_json: Path) -> dict:
    """Per-load values (as the analyze stage stored them), laws fitted on P ≤
    ``analysis.threshold_gpa`` and warnings (the analysis's, then the fit's) of the energy form
    the analyze stage did not report."""
    import json

    from flatcontact.analysis.energy_forms import form_laws
    from flatcontact.foundation.errors import InputError

    stored = json.loads(Path(other_form_json).read_text())
    form = other_form(settings.analysis.energy_form)
    if stored.get("form") != form:
        raise InputError(
            f"{other_form_json}: holds the {stored.get('form')!r} energy form, expected {form!r} "
            f"(the form analysis.energy_form = {settings.analysis.energy_form!r} does not name); "
            "rerun the analyze stage"
        )
    laws, fit_warnings = form_laws(stored["loads"], settings.analysis.threshold_gpa)
    return {"loads": stored["loads"], "laws": laws, "warnings": stored["warnings"] + fit_warnings}
