"""Least-squares fit of measured stiffness curves at several loads at once.

Data
----
Stiffness against mean shear stress at several loads, read by
:func:`flatcontact.contact.measured.load_fit_data` (one two-column CSV per load, or one CSV
with a load column) (:class:`~flatcontact.contact.measured.LoadCurve`, one per load).

Model
-----
At each measured stress the model stiffness is, per load p0, at the force amplitude
Q_amp = stress·π a² (``amplitude`` measure; ``rms``: ×√2):

* ``stiffness="lockin"`` (default; what a lock-in amplifier reads): k′ = Q_amp/u′₁ of the
  steady cycle (:mod:`flatcontact.contact.cycle`);
* ``stiffness="paper"``: the paper's d⟨Q⟩/d⟨u⟩ (:mod:`flatcontact.contact.oscillation`);

and 0 at and beyond gross sliding (Q_amp >= Q_peak, or μP for the classical model).
``model="modified"`` (the paper's laws τ = k p + τ0, σ = μ p + σ0, paper's G*) or
``"classical"`` (Cattaneo–Mindlin, friction coefficient μ = k, G*_J = G*/4: only
``k_mpa_per_gpa`` and ``shear_modulus_gpa`` enter).

Fit
---
The parameters named in ``free`` (any of :data:`FIT_PARAMETERS`) are fitted, every other
one is held at its value in ``params``, by ``scipy.optimize.least_squares`` (trust region,
bounds τ0, σ0 >= 0, G* > 0) on the residuals model − data of all points of all loads
(whole curves, not only the collapse). Standard errors: √diag(s² (JᵀJ)⁻¹) with
s² = RSS/(n − p); correlations from the same covariance. Information criteria for
Gaussian residuals of unknown variance: AIC = n ln(RSS/n) + 2p, AICc = AIC +
2p(p+1)/(n−p−1), BIC = n ln(RSS/n) + p ln n (the lower, the better; differences matter).
A trial outside the model's domain (τ <= 0, σ < 0, σ > τ somewhere) gets the residual the
data would have against a zero stiffness, times 10.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from flatcontact.contact import cycle, experiment, mindlin
from flatcontact.contact.measured import LoadCurve
from flatcontact.contact.parameters import ContactParameters
from flatcontact.foundation import units
from flatcontact.foundation.errors import InputError, require

FloatArray = NDArray[np.float64]

#: Parameters that can be freed, with their lower bounds.
FIT_PARAMETERS: dict[str, float] = {
    "tau0_mpa": 0.0,
    "k_mpa_per_gpa": -np.inf,
    "mu_mpa_per_gpa": -np.inf,
    "sigma0_mpa": 0.0,
    "shear_modulus_gpa": 1e-6,
}
#: The parameters the classical model depends on.
CLASSICAL_PARAMETERS = ("k_mpa_per_gpa", "shear_modulus_gpa")
STIFFNESS_KINDS = ("lockin", "paper")


def check_free_fixed(
    free: Sequence[str], fixed: Sequence[str] = (), model: str = "modified"
) -> tuple[str, ...]:
    """Validate the names to free and to fix; returns ``free`` as a tuple.

    Raises
    ------
    InputError
        An unknown name, a name both fixed and freed, nothing freed, or (classical) a freed
        parameter the classical model does not use.
    """
    cycle.check_model(model)
    allowed = ", ".join(FIT_PARAMETERS)
    for name in [*free, *fixed]:
        require(name in FIT_PARAMETERS, f"fit parameter {name!r} is unknown; use one of {allowed}")
    both = sorted(set(free) & set(fixed))
    require(not both, f"fit parameter {both[0]} is both fixed and freed" if both else "")
    require(len(free) > 0, f"fit: free at least one parameter ({allowed})")
    require(len(set(free)) == len(free), f"fit: a parameter is freed twice in {list(free)}")
    if model == "classical":
        for name in free:
            require(
                name in CLASSICAL_PARAMETERS,
                f"fit parameter {name} does not enter the classical model (friction "
                f"coefficient mu = k, G*); free only {', '.join(CLASSICAL_PARAMETERS)}",
            )
    return tuple(free)


def model_stiffness(
    curve: LoadCurve,
    params: ContactParameters,
    *,
    model: str = "modified",
    stiffness: str = "lockin",
    measure: str = "amplitude",
) -> FloatArray:
    """Model stiffness (N/m) at the curve's stresses: lock-in k′ or the paper's d⟨Q⟩/d⟨u⟩,
    0 at and beyond gross sliding."""
    require(stiffness in STIFFNESS_KINDS, f"stiffness must be one of {STIFFNESS_KINDS}")
    factor = experiment.measure_factor(measure)
    p0 = curve.p0_gpa * units.GPA_TO_PA
    mdl = cycle.CycleModel(model, p0, params)
    qa = curve.stress_pa * np.pi * mdl.a**2 / factor
    inside = (qa > 0.0) & (qa < mdl.gross * (1.0 - 1e-12))
    out = np.zeros_like(qa)
    out[qa <= 0.0] = mdl.k0
    if np.any(inside):
        if stiffness == "lockin":
            out[inside] = cycle.steady_cycle(qa[inside], p0, params, model).lockin_stiffness_n_per_m
        else:
            out[inside] = mdl.paper_stiffness(qa[inside])
    return out


@dataclass(frozen=True)
class FitResult:
    """A multi-load fit (see the module doc for the definitions)."""

    model: str
    stiffness: str
    measure: str
    free: tuple[str, ...]
    params: ContactParameters
    standard_errors: dict[str, float]
    correlation: FloatArray
    curves: tuple[LoadCurve, ...]
    residuals_n_per_m: tuple[FloatArray, ...]
    rss: float
    n_points: int
    aic: float
    aicc: float
    bic: float
    success: bool
    message: str
    evaluations: int

    @property
    def n_free(self) -> int:
        return len(self.free)

    @property
    def rms_residual_n_per_m(self) -> float:
        return math.sqrt(self.rss / self.n_points)

    def to_json(self) -> dict[str, Any]:
        """JSON-ready summary (unit-named keys)."""
        values = self.params.as_dict()
        return {
            "model": self.model,
            "stiffness": self.stiffness,
            "stress_measure": self.measure,
            "free": list(self.free),
            "fixed": {k: v for k, v in values.items() if k not in self.free},
            "fitted": {k: values[k] for k in self.free},
            "standard_errors": dict(self.standard_errors),
            "correlation": {
                a: {b: float(self.correlation[i, j]) for j, b in enumerate(self.free)}
                for i, a in enumerate(self.free)
            },
            "n_points": self.n_points,
            "loads_gpa": [c.p0_gpa for c in self.curves],
            "rss_n2_per_m2": self.rss,
            "rms_residual_n_per_m": self.rms_residual_n_per_m,
            "aic": self.aic,
            "aicc": self.aicc,
            "bic": self.bic,
            "success": self.success,
            "message": self.message,
            "evaluations": self.evaluations,
        }


def fit_stiffness_curves(
    curves: Sequence[LoadCurve],
    params: ContactParameters,
    free: Sequence[str] = ("tau0_mpa",),
    fixed: Sequence[str] = (),
    *,
    model: str = "modified",
    stiffness: str = "lockin",
    measure: str = "amplitude",
) -> FitResult:
    """Fit the ``free`` parameters to all curves at once (least squares on whole curves).

    ``fixed`` only names parameters the caller wants held (checked against ``free``); every
    parameter not freed is held at its value in ``params``, which is also the start.

    Raises
    ------
    InputError
        Bad names (:func:`check_free_fixed`), no curves, a stiffness kind or measure unknown,
        or the starting parameters outside the model's domain at a curve's load.
    """
    free = check_free_fixed(free, fixed, model)
    require(len(curves) > 0, "fit: no stiffness curves")
    require(stiffness in STIFFNESS_KINDS, f"stiffness must be one of {STIFFNESS_KINDS}")
    experiment.measure_factor(measure)
    for c in curves:
        cycle.check_cycle_domain(c.p0_gpa * units.GPA_TO_PA, params, model)
    y = np.concatenate([c.stiffness_n_per_m for c in curves])
    n = y.size
    p = len(free)
    require(n > p + 1, f"fit: {n} data points are too few for {p} free parameters")
    start = np.array([getattr(params, k) for k in free], dtype=float)
    lower = np.array([FIT_PARAMETERS[k] for k in free])
    start = np.maximum(start, lower + 1e-9 * np.maximum(1.0, np.abs(start)))
    penalty = 10.0 * np.abs(y) + 10.0 * np.max(np.abs(y))

    def residuals(x: FloatArray) -> FloatArray:
        try:
            prm = params.replace(**dict(zip(free, map(float, x), strict=True)))
            got = [
                model_stiffness(c, prm, model=model, stiffness=stiffness, measure=measure)
                for c in curves
            ]
        except InputError:
            return penalty
        return np.concatenate(got) - y

    res = least_squares(
        residuals,
        start,
        bounds=(lower, np.full(p, np.inf)),
        x_scale=np.maximum(np.abs(start), 1.0),
        diff_step=1e-5,
        method="trf",
        ftol=1e-10,
        xtol=1e-10,
    )
    best = params.replace(**dict(zip(free, map(float, res.x), strict=True)))
    r = residuals(res.x)
    rss = float(r @ r)
    jac = np.asarray(res.jac, dtype=float)
    cov = np.linalg.pinv(jac.T @ jac) * rss / max(n - p, 1)
    err = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    with np.errstate(divide="ignore", invalid="ignore"):
        corr = cov / np.outer(err, err)
    corr = np.where(np.isfinite(corr), corr, 0.0)
    sizes = np.cumsum([c.stiffness_n_per_m.size for c in curves])[:-1]
    ll = n * math.log(max(rss, 1e-300) / n)
    aic = ll + 2 * p
    return FitResult(
        model=model,
        stiffness=stiffness,
        measure=measure,
        free=free,
        params=best,
        standard_errors={k: float(e) for k, e in zip(free, err, strict=True)},
        correlation=corr,
        curves=tuple(curves),
        residuals_n_per_m=tuple(np.split(r, sizes)),
        rss=rss,
        n_points=n,
        aic=aic,
        aicc=aic + 2 * p * (p + 1) / (n - p - 1) if n - p - 1 > 0 else math.inf,
        bic=ll + p * math.log(n),
        success=bool(res.success),
        message=str(res.message),
        evaluations=int(res.nfev),
    )


@dataclass(frozen=True)
class ModelComparison:
    """The modified and the classical model fitted to the same curves."""

    modified: FitResult
    classical: FitResult

    @property
    def preferred(self) -> str:
        """The model with the lower AICc."""
        return "modified" if self.modified.aicc <= self.classical.aicc else "classical"

    def to_json(self) -> dict[str, Any]:
        return {
            "modified": self.modified.to_json(),
            "classical": self.classical.to_json(),
            "delta_aicc_classical_minus_modified": self.classical.aicc - self.modified.aicc,
            "delta_bic_classical_minus_modified": self.classical.bic - self.modified.bic,
            "preferred_model": self.preferred,
        }


def fit_and_compare(
    curves: Sequence[LoadCurve],
    params: ContactParameters,
    free: Sequence[str] = ("tau0_mpa",),
    fixed: Sequence[str] = (),
    *,
    stiffness: str = "lockin",
    measure: str = "amplitude",
    classical_free: Sequence[str] | None = None,
) -> ModelComparison:
    """Fit the modified model (``free``) and the classical one (``classical_free``; default
    the freed parameters it uses, or μ = k alone) to the same curves."""
    check_free_fixed(free, fixed, "modified")
    if classical_free is None:
        classical_free = tuple(k for k in free if k in CLASSICAL_PARAMETERS) or ("k_mpa_per_gpa",)
    mod = fit_stiffness_curves(
        curves, params, free, fixed, model="modified", stiffness=stiffness, measure=measure
    )
    start = params
    if "k_mpa_per_gpa" in classical_free:
        # start from the friction coefficient whose μP is the modified fit's collapse force
        ratios = []
        for c in curves:
            p0 = c.p0_gpa * units.GPA_TO_PA
            a = float(mindlin.contact_radius(p0, mod.params))
            q_peak = float(mindlin.peak_force(p0, mod.params).force_n)
            ratios.append(q_peak / (2.0 / 3.0 * np.pi * a**2 * p0))
        start = params.replace(k_mpa_per_gpa=float(np.mean(ratios)) / units.MPA_PER_GPA_TO_RATIO)
    cla = fit_stiffness_curves(
        curves,
        start,
        classical_free,
        tuple(k for k in fixed if k in CLASSICAL_PARAMETERS and k not in classical_free),
        model="classical",
        stiffness=stiffness,
        measure=measure,
    )
    return ModelComparison(modified=mod, classical=cla)


def initial_stiffness_n_per_m(curve: LoadCurve, params: ContactParameters) -> float:
    """2 G* a at the curve's load (N/m), for plots and starting values."""
    return float(mindlin.initial_lateral_stiffness(curve.p0_gpa * units.GPA_TO_PA, params))
