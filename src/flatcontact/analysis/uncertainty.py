"""Uncertainty of the load laws and its propagation to the contact outputs (pure functions).

Four independent sources set the uncertainty of each law coefficient
c ∈ {k, τ0, μ, σ0} (τ = k·P + τ0, σ = μ·P + σ0, the paper's linear laws):

* the fit: its standard error ``se_fit`` (``laws.json``);
* the numerical convergence: the change ``δ_conv`` of the coefficient under one more
  refinement of the scan settings (``docs/convergence.md``);
* the potential: the spread ``δ_model`` of the coefficient over models that the
  surrogate stands for: half the max − min range over the SNAP and every teacher
  compared (:func:`model_spread`, :func:`committee_spread`).

* the lateral grid: the run's own estimate ``δ_grid`` of its discretisation error
  (:mod:`flatcontact.analysis.grid_error`: the same analysis on a coarser grid from the same
  samples, Richardson-scaled), carried into the coefficients by fitting the law to the
  per-load signed estimates δτ(P), δσ(P) (:func:`grid_law_components`; the fit is linear in
  the data, so this is the coefficients' own Richardson estimate). Every run has it, with or
  without a study. (A convergence study whose ladder refines ``scan.grid`` measures the same
  error again: counted twice, on the safe side.)

They are combined in quadrature, ``h_c = m·sqrt(se_fit² + δ_conv² + δ_model² + δ_grid²)``
(:func:`law_half_widths`, ``m`` the coverage multiple; m = 2 ≈ 95 % for Gaussian errors).

:func:`propagate_box` carries the box ``c ± h_c`` through any output function
(effective shear strength Q_peak/πa², collapse stress, knee amplitude, ...): it evaluates
the function at the central point and at every corner of the box and returns per output
``(low, central, high)`` = (min, central, max). This is exact for outputs monotone in each
coefficient (the Mindlin outputs are monotone in τ0, k, σ0, μ separately) and a lower
bound of the true range otherwise. Coefficients the contact model requires to be ≥ 0 can
be clipped at 0 (``nonnegative``), as the run does for fitted negatives within two
standard errors (docs/run.md).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from flatcontact.foundation.errors import InputError, require

#: Law coefficients and their standard-error keys in ``laws.json``.
LAW_COEFFICIENTS: dict[str, str] = {
    "k_mpa_per_gpa": "k_stderr_mpa_per_gpa",
    "tau0_mpa": "tau0_stderr_mpa",
    "mu_mpa_per_gpa": "mu_stderr_mpa_per_gpa",
    "sigma0_mpa": "sigma0_stderr_mpa",
}
#: Largest number of varied inputs of :func:`propagate_box` (2**n corner evaluations).
MAX_BOX_INPUTS = 8


def _num(value, what: str) -> float:
    if value is None:
        return 0.0
    v = float(value)
    require(math.isfinite(v) and v >= 0, f"{what}: expected a finite value >= 0, got {value!r}")
    return v


def model_spread(per_model_laws: Mapping[str, Mapping]) -> dict[str, float]:
    """Half the range of each law coefficient over ALL models compared (SNAP and every teacher).

    Rule: ``δ_model(c) = (max_m c_m − min_m c_m) / 2`` over every model ``m`` whose law
    has the coefficient ``c``, i.e. the radius of the smallest interval holding every
    model's value. It is used, rather than the standard deviation over models, because a
    committee here has two to four members of which several may agree: the half-range
    does not change when a model that repeats another's numbers is added (a standard
    deviation shrinks, although an identical member says nothing new about the potential's
    error); with two models it equals their (population) standard deviation.

    Parameters
    ----------
    per_model_laws
        Model label -> ``laws.json`` document (at least two models); coefficients in the
        units of ``laws.json`` (MPa, MPa/GPa).

    Returns
    -------
    dict
        Coefficient -> (max − min)/2 over the models where it was fitted (0 with fewer
        than two fitted values).
    """
    require(len(per_model_laws) >= 2, "per_model_laws: expected laws of at least two models")
    out = {}
    for key in LAW_COEFFICIENTS:
        vals = [float(d[key]) for d in per_model_laws.values() if d.get(key) is not None]
        out[key] = (max(vals) - min(vals)) / 2 if len(vals) >= 2 else 0.0
    return out


def committee_spread(per_model_results: Mapping[str, Mapping]) -> dict[str, float]:
    """:func:`model_spread` over every model of an ISPES comparison.

    ``per_model_results``: label -> the per-model result of
    :func:`flatcontact.training.ispes_check.compare_ispes` (its ``results`` dict, also the
    ``ispes_compare_<form>.json`` of the teacher benchmark), each with a ``laws`` block.
    The result is the ``uncertainty.model_spread_<form>`` of a run configuration for the
    energy form the comparison was analysed in.
    """
    laws = {}
    for label, result in per_model_results.items():
        block = result.get("laws") if isinstance(result, Mapping) else None
        require(
            isinstance(block, Mapping),
            f"per_model_results.{label}: expected a result with a 'laws' block",
        )
        laws[label] = block
    return model_spread(laws)


def grid_law_components(
    p_gpa: Sequence[float] | None,
    tau_mpa: Sequence[float] | None,
    sigma_mss_mpa: Sequence[float] | None,
    tau_grid_error_mpa: Sequence[float] | None,
    sigma_mss_grid_error_mpa: Sequence[float] | None,
    threshold_gpa: float,
) -> dict[str, float | None]:
    """``δ_grid`` of each law coefficient: |slope| and |intercept| of the least-squares line
    through the per-load signed grid estimates on the loads the law is fitted on
    (``P <= threshold_gpa`` where τ, resp. σ, is finite; :func:`flatcontact.analysis.laws.
    fit_linear_law`'s points). None for a coefficient whose law has fewer than two such loads
    or a fitted load without an estimate (not estimated, unlike 0: estimated and zero)."""
    out: dict[str, float | None] = dict.fromkeys(LAW_COEFFICIENTS)
    if p_gpa is None:
        return out
    p = np.asarray(p_gpa, float)
    pairs = (
        (("k_mpa_per_gpa", "tau0_mpa"), tau_mpa, tau_grid_error_mpa),
        (("mu_mpa_per_gpa", "sigma0_mpa"), sigma_mss_mpa, sigma_mss_grid_error_mpa),
    )
    for (slope_key, intercept_key), values, errors in pairs:
        if errors is None or values is None:
            continue
        y, e = np.asarray(values, float), np.asarray(errors, float)
        fitted = np.isfinite(p) & np.isfinite(y) & (p <= threshold_gpa)
        if np.unique(p[fitted]).size < 2 or not np.all(np.isfinite(e[fitted])):
            continue
        slope, intercept = np.polyfit(p[fitted], e[fitted], 1)
        out[slope_key], out[intercept_key] = abs(float(slope)), abs(float(intercept))
    return out


def law_half_widths(
    laws: Mapping,
    *,
    convergence: Mapping[str, float] | None = None,
    model: Mapping[str, float] | None = None,
    grid: Mapping[str, float | None] | None = None,
    coverage: float = 1.0,
) -> dict[str, float]:
    """Half-width of each law coefficient from the fit, the convergence, the model spread and
    the grid.

    ``h_c = coverage · sqrt(se_fit² + δ_conv² + δ_model² + δ_grid²)`` (module docstring).
    Missing entries count as 0. Returns coefficient -> half-width in the coefficient's unit.
    """
    require(coverage >= 0 and math.isfinite(coverage), f"coverage={coverage}: expected >= 0")
    out = {}
    for key, parts in law_components(laws, convergence=convergence, model=model, grid=grid).items():
        out[key] = coverage * float(np.sqrt(sum((v or 0.0) ** 2 for v in parts.values())))
    return out


def law_components(
    laws: Mapping,
    *,
    convergence: Mapping[str, float] | None = None,
    model: Mapping[str, float] | None = None,
    grid: Mapping[str, float | None] | None = None,
) -> dict[str, dict[str, float | None]]:
    """The four parts of each coefficient's uncertainty, before the coverage multiple.

    ``{coefficient: {"fit": se_fit, "convergence": δ_conv, "models": δ_model, "grid":
    δ_grid}}`` (units of the coefficient; ``grid`` None when the run could not estimate it,
    :func:`grid_law_components`); :func:`law_half_widths` is
    ``coverage · sqrt(fit² + convergence² + models² + grid²)`` of these.
    """
    convergence = convergence or {}
    model = model or {}
    grid = grid or {}
    return {
        key: {
            "fit": _num(laws.get(err), f"laws.{err}"),
            "convergence": abs(float(convergence.get(key) or 0.0)),
            "models": _num(model.get(key), f"model.{key}"),
            "grid": None if grid.get(key) is None else _num(grid.get(key), f"grid.{key}"),
        }
        for key, err in LAW_COEFFICIENTS.items()
    }


def law_intervals(
    laws: Mapping,
    half_widths: Mapping[str, float],
    components: Mapping[str, Mapping[str, float]] | None = None,
) -> dict[str, dict]:
    """``{coefficient: {"value", "low", "high", "half_width"[, "components"]}}`` for ``laws.json``.

    ``components`` (:func:`law_components`) are stored beside each interval, so a reader
    sees how much of the half-width is the fit, the convergence, the model spread and the
    grid."""
    out = {}
    for key in LAW_COEFFICIENTS:
        if laws.get(key) is None:
            continue
        v, h = float(laws[key]), float(half_widths.get(key, 0.0))
        out[key] = {"value": v, "low": v - h, "high": v + h, "half_width": h}
        if components is not None:
            out[key]["components"] = dict(components[key])
    return out


def propagate_box(
    fn: Callable[[dict[str, float]], Mapping[str, float]],
    central: Mapping[str, float],
    half_widths: Mapping[str, float],
    *,
    nonnegative: Sequence[str] = (),
) -> dict[str, tuple[float, float, float]]:
    """Interval of every output of ``fn`` over the box ``central ± half_widths``.

    Parameters
    ----------
    fn
        ``fn(inputs) -> {output: value}``; ``inputs`` has the keys of ``central``.
    central
        The central inputs (e.g. the fitted k, τ0, μ, σ0 and any fixed parameter).
    half_widths
        Input -> half-width (≥ 0); inputs not listed, or with 0, are not varied.
    nonnegative
        Inputs clipped at 0 at the box corners (the central value is used as given).

    Returns
    -------
    dict
        Output -> ``(low, central, high)``: min and max over the central point and the
        box corners. Zero half-widths give ``low == central == high``.
    """
    for key, h in half_widths.items():
        require(
            key in central,
            f"half_widths: {key!r} is not an input (expected one of {sorted(central)})",
        )
        _num(h, f"half_widths.{key}")
    varied = [k for k, h in half_widths.items() if float(h) > 0]
    if len(varied) > MAX_BOX_INPUTS:
        raise InputError(
            f"half_widths: {len(varied)} varied inputs, expected at most {MAX_BOX_INPUTS} "
            f"(2**n corner evaluations)"
        )
    base = {k: float(v) for k, v in central.items()}
    mid = {k: float(v) for k, v in fn(dict(base)).items()}
    low, high = dict(mid), dict(mid)
    for signs in itertools.product((-1.0, 1.0), repeat=len(varied)):
        point = dict(base)
        for key, s in zip(varied, signs, strict=True):
            point[key] = base[key] + s * float(half_widths[key])
            if key in nonnegative:
                point[key] = max(point[key], 0.0)
        values = fn(point)
        for name, v in values.items():
            v = float(v)
            low[name] = min(low[name], v)
            high[name] = max(high[name], v)
    return {name: (low[name], mid[name], high[name]) for name in mid}
