"""Stage 4, laws: τ = k·P + τ0 and σ = μ·P + σ0 fitted on P ≤ ``analysis.threshold_gpa``.

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

from flatcontact.fileio import write_json_atomic
from flatcontact.stages._common import captured, save

LAWS_JSON = "laws.json"
FIGURE_STEM = "fig3_laws"
_COLUMNS = ("p_gpa", "tau_mpa", "sigma_mss_mpa")


@dataclass(frozen=True)
class LawsInputs:
    """τ and σ_MSS (MPa) per load P (GPa): the analyze stage's ``friction.csv``
    (:meth:`read`) or an analysis in memory (:meth:`from_analysis`)."""

    p_gpa: tuple[float, ...]
    tau_mpa: tuple[float, ...]
    sigma_mss_mpa: tuple[float, ...]

    @classmethod
    def read(cls, friction_csv: Path) -> LawsInputs:
        """The columns of ``friction.csv``."""
        import pandas as pd

        table = pd.read_csv(friction_csv)
        return cls(*(tuple(table[c].to_numpy(float)) for c in _COLUMNS))

    @classmethod
    def from_analysis(cls, analysis) -> LawsInputs:
        """The loads and columns of a :class:`flatcontact.analysis.pipeline.AnalysisResult`."""
        return cls(
            tuple(analysis.p_gpa),
            tuple(analysis.column("tau_mpa")),
            tuple(analysis.column("sigma_mss_mpa")),
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

    @property
    def warnings(self) -> list[str]:
        """The fit's warnings (messages), as ``laws.json`` stores them."""
        return [str(w.message) for w in self.caught]

    def to_json(self) -> dict:
        """``laws.json``: :meth:`LoadLaws.to_json` and ``warnings``."""
        return {**self.laws.to_json(), "warnings": self.warnings}


def run_laws(settings, inputs: LawsInputs, folder: Path | None, progress=None) -> LawsResult:
    """Fit the load laws to ``inputs`` on P ≤ ``settings.analysis.threshold_gpa``."""
    from flatcontact.analysis.diagnostics import AnalysisWarning
    from flatcontact.analysis.laws import fit_load_laws

    p, tau, sigma = (
        np.asarray(v, dtype=float) for v in (inputs.p_gpa, inputs.tau_mpa, inputs.sigma_mss_mpa)
    )
    with captured(AnalysisWarning) as caught:
        laws = fit_load_laws(p, tau, sigma, settings.analysis.threshold_gpa)
    result = LawsResult(laws, p, tau, sigma, list(caught))
    if folder is not None:
        from flatcontact.plots.analysis import figure_laws

        folder.mkdir(parents=True, exist_ok=True)
        result.files.append(write_json_atomic(folder / LAWS_JSON, result.to_json()))
        result.files += save(
            figure_laws(p, tau, sigma, laws), folder, FIGURE_STEM, settings.report.svg
        )
    return result
