"""Both constant-pressure energy forms from one ISPES: per-load friction and load laws side by side.

The paper (its constant-pressure ISPES, Ũ(x, y)|_P = U(x, y, z*(x, y; P))) analyses the
*internal* energy at the gap z* that carries the load P. The lateral force at constant
load is the gradient of the *enthalpy* h = U/A + P·z* instead: by the envelope theorem
∇h|_P = ∇U|_z (z* makes h stationary in z), while ∇Ũ|_P = ∇U|_z − P·∇z* leaves out the
work P·A·Δz done against the load when the gap changes along the path
(:mod:`flatcontact.analysis.constant_pressure`). The two give the same τ and σ_MSS at
P = 0 and differ by the load-dependent gap corrugation above it; their slopes k and μ
can differ by an order of magnitude.

:func:`form_loads` analyses one form (:func:`flatcontact.analysis.analyze.analyze_ispes`, no
fit): its per-load table and analysis warnings, what the run's analyze stage stores for the
form it does not report (``other_form.json``); :func:`form_laws` fits the load laws to such a
table, which the laws stage does. :func:`laws_both_forms` chains the two for both forms
(everything else equal) and adds a side-by-side table for the report.
"""

from __future__ import annotations

import io
import warnings
from collections.abc import Sequence
from dataclasses import replace

import numpy as np
import pandas as pd

from flatcontact.analysis.analyze import analyze_ispes
from flatcontact.analysis.diagnostics import AnalysisWarning
from flatcontact.analysis.laws import fit_load_laws
from flatcontact.analysis.options import AnalysisOptions
from flatcontact.analysis.outputs import friction_csv_text
from flatcontact.foundation.errors import require

FORMS = ("internal", "enthalpy")
#: Per-load columns kept for each form.
COLUMNS = (
    "tau_mpa",
    "sigma_mss_mpa",
    "shear_stiffness_gpa_per_nm",
    "tau_limited_by",
    "force_noise_mpa",
    "tau_grid_error_mpa",
    "sigma_mss_grid_error_mpa",
)


def _caught_text(caught) -> list[str]:
    """``"Category: message"`` of the analysis warnings among ``caught``."""
    return [
        f"{w.category.__name__}: {w.message}"
        for w in caught
        if issubclass(w.category, AnalysisWarning)
    ]


def form_loads(
    ds, p_gpa: Sequence[float], form: str, options: AnalysisOptions | None = None
) -> dict:
    """Per-load τ, σ_MSS, G_int, τ's limit and the force noise of one ISPES in one energy form.

    Parameters
    ----------
    ds
        An ISPES grid (``ispes.nc`` contract, :func:`flatcontact.ispes.contract.open_ispes`).
    p_gpa
        The loads (GPa).
    form
        ``"internal"`` or ``"enthalpy"`` (replaces ``options.form``).
    options
        The rest of the analysis (:class:`flatcontact.analysis.options.AnalysisOptions`;
        ``None``: the defaults); its symmetry report, MEP and fit are not computed here.

    Returns
    -------
    dict
        ``{"form": form, "loads": [one dict per load: p_gpa and :data:`COLUMNS`],
        "warnings": ["Category: message" of the analysis warnings]}``; the load laws of the
        table are :func:`form_laws`'s.
    """
    require(form in FORMS, f"form: {form!r}: expected internal or enthalpy")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", AnalysisWarning)
        one_form = replace(
            options or AnalysisOptions(),
            form=form,
            threshold_gpa=None,
            with_symmetry=False,
            with_mep=False,
        )
        result = analyze_ispes(ds, list(p_gpa), one_form)
    table = pd.read_csv(io.StringIO(friction_csv_text(result)))
    table = table[["p_gpa", *[c for c in COLUMNS if c in table.columns]]]
    return {
        "form": form,
        "loads": table.to_dict(orient="records"),
        "warnings": _caught_text(caught),
    }


def form_laws(loads: Sequence[dict], threshold_gpa: float) -> tuple[dict, list[str]]:
    """The load laws (``laws.json`` dict, :meth:`flatcontact.analysis.laws.LoadLaws.to_json`)
    fitted on P ≤ ``threshold_gpa`` (GPa) to the per-load rows ``loads`` of :func:`form_loads`,
    and the fit's warnings (``"Category: message"``)."""
    p, tau, sigma = (
        np.array([row[key] for row in loads], dtype=float)
        for key in ("p_gpa", "tau_mpa", "sigma_mss_mpa")
    )
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", AnalysisWarning)
        laws = fit_load_laws(p, tau, sigma, threshold_gpa)
    return laws.to_json(), _caught_text(caught)


def laws_both_forms(
    ds,
    p_gpa: Sequence[float],
    options: AnalysisOptions | None = None,
    forms: Sequence[str] = FORMS,
) -> dict:
    """Per-load τ, σ_MSS, G_int and the load laws of one ISPES in each energy form.

    Parameters
    ----------
    ds
        An ISPES grid (``ispes.nc`` contract, :func:`flatcontact.ispes.contract.open_ispes`).
    p_gpa
        The loads (GPa).
    options
        The analysis, the same for both forms (:class:`flatcontact.analysis.options.AnalysisOptions`,
        ``None``: the defaults); its ``threshold_gpa`` bounds the fits (``None``: 3 GPa).
    forms
        Which forms (default both, internal first).

    Returns
    -------
    dict
        ``{"forms": {form: {"loads": [per-load dict], "laws": laws.json dict,
        "warnings": [str]}}, "table": [per-load dict with <column>_<form> keys],
        "laws_table": [one dict per law coefficient with one value and stderr per form]}``;
        each form's warnings are its analysis's (:func:`form_loads`), then its fit's
        (:func:`form_laws`).
    """
    options = options or AnalysisOptions()
    threshold_gpa = 3.0 if options.threshold_gpa is None else options.threshold_gpa
    require(len(forms) >= 1, "forms: expected at least one of internal, enthalpy")
    for form in forms:
        require(form in FORMS, f"forms: {form!r}: expected internal or enthalpy")
    out: dict = {"forms": {}}
    tables = {}
    for form in forms:
        analysed = form_loads(ds, p_gpa, form, options)
        laws, fit_warnings = form_laws(analysed["loads"], threshold_gpa)
        tables[form] = pd.DataFrame.from_records(analysed["loads"])
        out["forms"][form] = {
            "loads": analysed["loads"],
            "laws": laws,
            "warnings": analysed["warnings"] + fit_warnings,
        }
    side = None
    for form, table in tables.items():
        renamed = table.rename(columns={c: f"{c}_{form}" for c in table.columns if c != "p_gpa"})
        side = renamed if side is None else side.merge(renamed, on="p_gpa")
    out["table"] = side.to_dict(orient="records")
    out["laws_table"] = [
        {
            "coefficient": key,
            **{f"{form}": out["forms"][form]["laws"][key] for form in forms},
            **{f"{form}_stderr": out["forms"][form]["laws"][err] for form in forms},
        }
        for key, err in (
            ("k_mpa_per_gpa", "k_stderr_mpa_per_gpa"),
            ("tau0_mpa", "tau0_stderr_mpa"),
            ("mu_mpa_per_gpa", "mu_stderr_mpa_per_gpa"),
            ("sigma0_mpa", "sigma0_stderr_mpa"),
        )
    ]
    return out
