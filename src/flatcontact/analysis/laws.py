"""Load laws τ(P) = k·P + τ0 and σ(P) = μ·P + σ0 (paper, Eqs. for τ and σ; Fig. 3).

Each law is an ordinary least-squares line through the points with
``P <= threshold`` (default 3 GPa, the paper's low-pressure regime), with the
standard errors of slope and intercept (``scipy.stats.linregress``; they need
at least 3 points).

**End of the linear regime** (precise definition used here): walking through
the points above the threshold in increasing ``P``, a point *departs* from the
law when its residual exceeds the half-width of the two-sided prediction
interval of the fit at that ``P``,

.. math:: t_{(1+c)/2,\\,n-2}\\; s\\,\\sqrt{1 + 1/n + (P - \\bar P)^2 / S_{PP}},

with ``c`` the confidence (default 0.95), ``s`` the residual standard error,
``n`` the number of fitted points, floored at ``rtol`` × ``|prediction|``
(default 1e-3) so that exactly linear data are not flagged by rounding. The
linear regime ends at the last pressure before the first departing point
(``linear_until_gpa``); ``departs_at_gpa`` is that point (``None`` if no point
departs within the data).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np
from scipy import stats

from flatcontact.analysis.diagnostics import LinearFitWarning
from flatcontact.foundation.errors import InputError


@dataclass(frozen=True)
class LinearLaw:
    """``y = slope·P + intercept`` fitted on ``P <= p_max_gpa`` (units of y: MPa)."""

    slope: float  #: MPa/GPa
    intercept: float  #: MPa
    slope_stderr: float
    intercept_stderr: float
    n_points: int
    p_max_gpa: float  #: largest P used in the fit
    linear_until_gpa: float  #: last P still on the law
    departs_at_gpa: float | None  #: first P off the law (None: none in the data)

    def __call__(self, p_gpa: np.ndarray | float) -> np.ndarray:
        """Evaluate the law (MPa)."""
        return self.slope * np.asarray(p_gpa, float) + self.intercept


def fit_linear_law(
    p_gpa: np.ndarray,
    y_mpa: np.ndarray,
    threshold_gpa: float = 3.0,
    confidence: float = 0.95,
    rtol: float = 1e-3,
    name: str = "law",
) -> LinearLaw | None:
    """Fit ``y = slope·P + intercept`` below ``threshold_gpa`` and find where it stops holding.

    Returns ``None`` (with a :class:`LinearFitWarning`) if fewer than 2 finite
    points lie below the threshold. With exactly 2 the standard errors are NaN.
    """
    if not threshold_gpa > 0 or not 0 < confidence < 1:
        raise InputError(f"{name}: threshold_gpa must be > 0 and confidence in (0, 1)")
    p = np.asarray(p_gpa, float)
    y = np.asarray(y_mpa, float)
    order = np.argsort(p, kind="stable")
    p, y = p[order], y[order]
    ok = np.isfinite(p) & np.isfinite(y)
    below = ok & (p <= threshold_gpa)
    n = int(below.sum())
    if n < 2 or np.unique(p[below]).size < 2:
        warnings.warn(
            f"{name}: {n} point(s) at P <= {threshold_gpa:g} GPa; a linear law needs at least 2 "
            "distinct pressures (3 for standard errors)",
            LinearFitWarning,
            stacklevel=2,
        )
        return None
    pf, yf = p[below], y[below]
    if n == 2:
        warnings.warn(
            f"{name}: only 2 points at P <= {threshold_gpa:g} GPa; no standard errors",
            LinearFitWarning,
            stacklevel=2,
        )
        slope = (yf[1] - yf[0]) / (pf[1] - pf[0])
        intercept = yf[0] - slope * pf[0]
        slope_se = intercept_se = float("nan")
        s = 0.0
    else:
        fit = stats.linregress(pf, yf)
        slope, intercept = float(fit.slope), float(fit.intercept)
        slope_se, intercept_se = float(fit.stderr), float(fit.intercept_stderr)
        resid = yf - (slope * pf + intercept)
        s = math.sqrt(float(resid @ resid) / (n - 2))
    t_crit = float(stats.t.ppf(0.5 * (1 + confidence), n - 2)) if n > 2 else 0.0
    p_mean = float(pf.mean())
    s_pp = float(((pf - p_mean) ** 2).sum())
    linear_until = float(pf[-1])
    departs = None
    for pk, yk in zip(p[ok & ~below], y[ok & ~below], strict=True):
        pred = slope * pk + intercept
        half = t_crit * s * math.sqrt(1 + 1 / n + (pk - p_mean) ** 2 / s_pp)
        if abs(yk - pred) > max(half, rtol * abs(pred)):
            departs = float(pk)
            break
        linear_until = float(pk)
    return LinearLaw(
        slope=float(slope),
        intercept=float(intercept),
        slope_stderr=slope_se,
        intercept_stderr=intercept_se,
        n_points=n,
        p_max_gpa=float(pf[-1]),
        linear_until_gpa=linear_until,
        departs_at_gpa=departs,
    )


@dataclass(frozen=True)
class LoadLaws:
    """τ(P) and σ(P) fits (either may be ``None`` if it could not be fitted)."""

    tau: LinearLaw | None
    sigma: LinearLaw | None
    threshold_gpa: float

    def to_json(self) -> dict:
        """The ``laws.json`` contract: ``k_mpa_per_gpa``, ``tau0_mpa``, ``mu_mpa_per_gpa``,
        ``sigma0_mpa``, their standard errors, ``p_max_gpa``, and the regime ends."""

        def val(law: LinearLaw | None, attr: str) -> float | None:
            if law is None:
                return None
            v = getattr(law, attr)
            return None if v is None or not math.isfinite(v) else float(v)

        p_max = [law.p_max_gpa for law in (self.tau, self.sigma) if law is not None]
        return {
            "k_mpa_per_gpa": val(self.tau, "slope"),
            "tau0_mpa": val(self.tau, "intercept"),
            "mu_mpa_per_gpa": val(self.sigma, "slope"),
            "sigma0_mpa": val(self.sigma, "intercept"),
            "k_stderr_mpa_per_gpa": val(self.tau, "slope_stderr"),
            "tau0_stderr_mpa": val(self.tau, "intercept_stderr"),
            "mu_stderr_mpa_per_gpa": val(self.sigma, "slope_stderr"),
            "sigma0_stderr_mpa": val(self.sigma, "intercept_stderr"),
            "p_max_gpa": max(p_max) if p_max else None,
            "threshold_gpa": self.threshold_gpa,
            "n_points_tau": self.tau.n_points if self.tau else 0,
            "n_points_sigma": self.sigma.n_points if self.sigma else 0,
            "tau_linear_until_gpa": val(self.tau, "linear_until_gpa"),
            "tau_departs_at_gpa": val(self.tau, "departs_at_gpa"),
            "sigma_linear_until_gpa": val(self.sigma, "linear_until_gpa"),
            "sigma_departs_at_gpa": val(self.sigma, "departs_at_gpa"),
        }


def fit_load_laws(
    p_gpa: np.ndarray,
    tau_mpa: np.ndarray,
    sigma_mpa: np.ndarray,
    threshold_gpa: float = 3.0,
    confidence: float = 0.95,
) -> LoadLaws:
    """Fit τ = k·P + τ0 and σ = μ·P + σ0 below ``threshold_gpa`` (see module docstring)."""
    return LoadLaws(
        tau=fit_linear_law(p_gpa, tau_mpa, threshold_gpa, confidence, name="tau(P)"),
        sigma=fit_linear_law(p_gpa, sigma_mpa, threshold_gpa, confidence, name="sigma(P)"),
        threshold_gpa=float(threshold_gpa),
    )
