"""Size scaling of a quantity over approximant cells: exponent and incommensurate limit.

Two models of a quantity y (τ0 in MPa, the ISPES corrugation in meV/Å²) against the atom
count N of the cell (the area of the contact per period grows like N):

- ``power_law``: ``y = c·N^−α`` (the incommensurate limit y∞ = 0 by assumption), fitted as a
  straight line ``ln y = ln c − α ln N`` (ordinary least squares; needs every y > 0 and at
  least 3 cells, so that one degree of freedom gives an interval);
- ``offset_power_law``: ``y = y∞ + c·N^−α`` (scipy ``curve_fit``, residuals relative to |y|,
  started from the power law), which extrapolates the limit y∞ itself; three parameters,
  so at least 4 cells.

Intervals are ``t(coverage, dof)·standard error`` from the fit covariance (dof = cells −
parameters). A model that cannot be fitted is not silently dropped: its entry is
``{"refused": reason}`` (fewer cells than it needs, a non-positive value, no convergence,
or, for ``power_law``, values that go up and down with N, which no power law to 0 does
(the offset model is left to its interval: near its limit noise may reorder values): τ0 of twisted h-BN, ILP,
0.0062, 0.020, 0.0015 MPa over 28, 76, 148 atoms, was fitted α = 0.69 ± 18; the refusal
keeps ``exponent`` and ``exponent_half_width`` for the record).
The fit says nothing about why y scales; a corrugation that falls faster than any power
(exp(−c√N), the Fourier components of a smooth interlayer potential at the coincidence
reciprocal vectors) shows up as an exponent that grows with the cells included.
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from scipy import stats
from scipy.optimize import OptimizeWarning, curve_fit

#: Cells a model needs: parameters + 1 degree of freedom for its interval.
MIN_CELLS = {"power_law": 3, "offset_power_law": 4}


def _t(coverage: float, dof: int) -> float:
    return float(stats.t.ppf(0.5 + coverage / 2.0, dof))


def _finite_pairs(n_atoms, values) -> tuple[np.ndarray, np.ndarray]:
    n = np.asarray(n_atoms, dtype=float)
    y = np.asarray(values, dtype=float)
    keep = np.isfinite(n) & np.isfinite(y) & (n > 0)
    return n[keep], y[keep]


def _not_monotonic(fit: dict, n: np.ndarray, y: np.ndarray) -> dict:
    """``fit`` refused when ``y`` does not change monotonically with ``n`` (module docstring):
    no power law ``c·N^−α`` goes up and down."""
    steps = np.sign(np.diff(y[np.argsort(n, kind="stable")]))
    if np.all(steps < 0) or np.all(steps > 0):
        return fit
    return {
        "model": fit["model"],
        "refused": "the values go up and down with the atom count: no power law "
        f"(it gave alpha {fit['exponent']:.3g} +- {fit['exponent_half_width']:.2g})",
        "cells": fit["cells"],
        "exponent": fit["exponent"],
        "exponent_half_width": fit["exponent_half_width"],
    }


def fit_power_law(n_atoms, values, coverage: float = 0.95) -> dict:
    """``y = c·N^−α`` by least squares on ``ln y`` against ``ln N`` (module docstring).

    Returns
    -------
    dict
        ``model``, ``cells``, ``exponent`` α, ``exponent_half_width``, ``prefactor`` c,
        ``limit`` 0 (assumed), ``coverage``; or ``{"model", "refused": reason}``.
    """
    n, y = _finite_pairs(n_atoms, values)
    model = "y = c*N^-alpha (limit 0 assumed)"
    if len(n) < MIN_CELLS["power_law"]:
        return {"model": model, "refused": f"{len(n)} cell(s) with a value; needs at least 3"}
    if np.any(y <= 0):
        return {"model": model, "refused": "a value is not positive: no logarithm"}
    x, ly = np.log(n), np.log(y)
    if np.ptp(x) == 0:
        return {"model": model, "refused": "every cell has the same atom count"}
    slope, intercept = np.polyfit(x, ly, 1)
    resid = ly - (slope * x + intercept)
    dof = len(n) - 2
    s2 = float(resid @ resid) / dof
    se = math.sqrt(s2 / float(((x - x.mean()) ** 2).sum()))
    return _not_monotonic(
        {
            "model": model,
            "cells": len(n),
            "exponent": float(-slope),
            "exponent_half_width": _t(coverage, dof) * se,
            "prefactor": float(math.exp(intercept)),
            "limit": 0.0,
            "limit_half_width": None,
            "rms_log_residual": math.sqrt(float(resid @ resid) / len(n)),
            "coverage": coverage,
        },
        n,
        y,
    )


def fit_offset_power_law(n_atoms, values, coverage: float = 0.95) -> dict:
    """``y = y∞ + c·N^−α`` (module docstring): the extrapolated limit y∞ with its interval.

    Returns
    -------
    dict
        ``model``, ``cells``, ``limit`` y∞, ``limit_half_width``, ``exponent`` α,
        ``exponent_half_width``, ``prefactor`` c, ``coverage``; or ``{"model", "refused"}``.
    """
    n, y = _finite_pairs(n_atoms, values)
    model = "y = y_inf + c*N^-alpha"
    if len(n) < MIN_CELLS["offset_power_law"]:
        return {
            "model": model,
            "refused": f"{len(n)} cell(s) with a value; three parameters need at least 4",
        }
    start = fit_power_law(n, y, coverage)
    alpha0 = start.get("exponent", 1.0)
    c0 = start.get("prefactor", float(y[np.argmin(n)] * n.min()))
    scale = np.maximum(np.abs(y), 1e-300)

    def f(nn, y_inf, c, alpha):
        return y_inf + c * nn ** (-alpha)

    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", OptimizeWarning)
            p, cov = curve_fit(f, n, y, p0=(0.0, c0, alpha0), sigma=scale, maxfev=20000)
    except (RuntimeError, OptimizeWarning, ValueError) as exc:
        return {"model": model, "refused": f"the fit did not converge ({exc})"}
    dof = len(n) - 3
    se = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    if not np.all(np.isfinite(se)):
        return {"model": model, "refused": "the fit covariance is not finite"}
    t = _t(coverage, dof)
    return {
        "model": model,
        "cells": len(n),
        "limit": float(p[0]),
        "limit_half_width": float(t * se[0]),
        "prefactor": float(p[1]),
        "exponent": float(p[2]),
        "exponent_half_width": float(t * se[2]),
        "coverage": coverage,
    }


def fit_scaling(n_atoms, values, coverage: float = 0.95) -> dict:
    """Both models of the module docstring: ``{"power_law": ..., "offset_power_law": ...}``."""
    return {
        "power_law": fit_power_law(n_atoms, values, coverage),
        "offset_power_law": fit_offset_power_law(n_atoms, values, coverage),
    }
