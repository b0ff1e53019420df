"""Measured lateral stiffness vs mean shear stress: collapse detection, inverse τ0.

The measured curve is read by :func:`flatcontact.contact.measured.load_stiffness_csv`
(the CSV format is described there).

Collapse from data
------------------
The points are sorted by stress; the low-stress plateau is the median stiffness
of the ``plateau_points`` (default 3) lowest-stress points; the collapse stress is
where the stiffness first falls below ``fraction`` (default 0.2) of the plateau,
linearly interpolated between the two bracketing points.

Model side and inverse problem
------------------------------
The same criterion is applied to the model: the stress (same measure as the
data: amplitude Q_max/(π a²) by default, or rms ⟨Q⟩/(π a²)) at which the model
stiffness falls to ``fraction`` of its zero-stress value k0. With the default
0.2 this lies within ~1 % below the model's gross-sliding collapse at Q_peak
(k falls to 0 only logarithmically as Q_max -> Q_peak). :func:`fit_tau0` finds the
τ0 (others fixed) for which model and data collapse coincide (brentq on the
admissible τ0, where τ > 0 on the contact; the criterion increases with τ0 once
the peak is an overshoot, and is the τ0-independent Q_sat/(π a²)-based value
below that).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq

from flatcontact.contact import mindlin
from flatcontact.contact.measured import MeasuredStiffness
from flatcontact.contact.oscillation import (
    STRESS_MEASURES,
    amplitude_at_stiffness_fraction,
    lateral_stiffness,
)
from flatcontact.contact.parameters import ContactParameters, check_positive
from flatcontact.foundation import units
from flatcontact.foundation.errors import require

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class CollapseEstimate:
    """Collapse of a measured stiffness curve.

    Attributes
    ----------
    stress_pa : interpolated stress where stiffness < fraction·plateau first (Pa)
    plateau_n_per_m : median stiffness of the lowest-stress points (N/m)
    fraction : the criterion's fraction
    """

    stress_pa: float
    plateau_n_per_m: float
    fraction: float


def collapse_stress(
    stress_pa: ArrayLike,
    stiffness_n_per_m: ArrayLike,
    *,
    fraction: float = 0.2,
    plateau_points: int = 3,
) -> CollapseEstimate:
    """Collapse stress of a stiffness curve (see module doc for the precise definition).

    Raises
    ------
    InputError
        If the fraction is not in (0, 1), there are too few points, the plateau is
        not positive, or the stiffness never falls below the threshold.
    """
    require(0.0 < fraction < 1.0, f"collapse fraction must be in (0, 1), got {fraction!r}")
    x = np.asarray(stress_pa, dtype=float)
    y = np.asarray(stiffness_n_per_m, dtype=float)
    require(
        x.shape == y.shape and x.ndim == 1,
        "stress and stiffness must be 1-D arrays of equal length",
    )
    require(
        x.size > plateau_points,
        f"need more than {plateau_points} points to find a collapse, got {x.size}",
    )
    order = np.argsort(x, kind="stable")
    x, y = x[order], y[order]
    plateau = float(np.median(y[:plateau_points]))
    require(plateau > 0.0, f"low-stress stiffness plateau must be > 0, got {plateau!r} N/m")
    thr = fraction * plateau
    below = np.nonzero(y[plateau_points:] < thr)[0]
    require(
        below.size > 0,
        f"no collapse: the stiffness never falls below {fraction:g} of its plateau ({plateau:.4g} N/m)",
    )
    i = int(below[0]) + plateau_points
    x0, x1, y0, y1 = x[i - 1], x[i], y[i - 1], y[i]
    t = (y0 - thr) / (y0 - y1) if y0 != y1 else 1.0
    return CollapseEstimate(
        stress_pa=float(x0 + t * (x1 - x0)), plateau_n_per_m=plateau, fraction=float(fraction)
    )


def measure_factor(measure: str) -> float:
    require(
        measure in STRESS_MEASURES,
        f"stress measure must be one of {STRESS_MEASURES}, got {measure!r}",
    )
    return 1.0 if measure == "amplitude" else 1.0 / np.sqrt(2.0)


def model_stiffness_at_stress(
    stress_pa: ArrayLike, p0_pa: float, params: ContactParameters, measure: str = "amplitude"
) -> FloatArray:
    """Model lateral stiffness (N/m) at mean shear stresses (Pa) of ``measure``; 0 beyond collapse."""
    factor = measure_factor(measure)
    s = np.asarray(stress_pa, dtype=float)
    a = float(mindlin.contact_radius(p0_pa, params))
    qmax = s * np.pi * a**2 / factor
    q_peak = float(mindlin.peak_force(p0_pa, params).force_n)
    inside = (qmax >= 0.0) & (qmax < q_peak)
    k = lateral_stiffness(np.where(inside, qmax, 0.0), p0_pa, params)
    return np.where(inside, k, 0.0)


def model_collapse_stress(
    p0_pa: float, params: ContactParameters, *, fraction: float = 0.2, measure: str = "amplitude"
) -> float:
    """The model's stress (Pa, ``measure``) where k falls to ``fraction``·k0 — the data criterion."""
    factor = measure_factor(measure)
    a = float(mindlin.contact_radius(p0_pa, params))
    return amplitude_at_stiffness_fraction(p0_pa, params, fraction) * factor / (np.pi * a**2)


def fit_tau0(
    measured_collapse_pa: float,
    p0_pa: float,
    params: ContactParameters,
    *,
    fraction: float = 0.2,
    measure: str = "amplitude",
    tau0_max_mpa: float = 1.0e5,
) -> float:
    """τ0 (MPa) for which the model collapse (same criterion and measure) equals the measured one.

    The search runs over the τ0 for which τ > 0 on the whole contact: τ0 >= 0 for
    k > 0, τ0 > 0 for k = 0, τ0 > |k|·p0 for k < 0. Where the model's peak is the
    saturated force (no overshoot) the collapse does not depend on τ0 (Q_sat is
    ∫σ dA); a measured collapse above that plateau has one τ0.

    Raises
    ------
    InputError
        If the measured collapse is below what the smallest admissible τ0 gives or
        above what ``tau0_max_mpa`` gives, or σ < 0 in the contact at p0 (μ < 0).
    """
    target = check_positive("measured collapse stress (Pa)", measured_collapse_pa)
    p0 = check_positive("p0_pa", p0_pa)
    # σ >= 0 at p0 does not depend on τ0: check it with a τ0 that keeps τ > 0
    tau0_min = max(0.0, -params.k_mpa_per_gpa * p0 / units.GPA_TO_PA)
    params.replace(tau0_mpa=max(params.tau0_mpa, 2.0 * tau0_min + 1.0)).check_p0_pa(p0)

    def resid(tau0_mpa: float) -> float:
        return (
            model_collapse_stress(
                p0, params.replace(tau0_mpa=tau0_mpa), fraction=fraction, measure=measure
            )
            - target
        )

    # τ > 0 on the contact: τ0 >= 0 (k > 0), τ0 > 0 (k = 0), τ0 > |k|·p0 (k < 0)
    lo = 0.0 if params.k_mpa_per_gpa > 0.0 else tau0_min * (1.0 + 1e-9) + 1e-9
    r_lo = resid(lo)
    require(
        r_lo <= 0.0,
        f"measured collapse {target / units.MPA_TO_PA:.4g} MPa is below the model's at tau0 = {lo:.4g} MPa "
        f"({(r_lo + target) / units.MPA_TO_PA:.4g} MPa): no tau0 "
        + (f"> |k|·p0 = {tau0_min:.4g} MPa" if tau0_min > 0.0 else ">= 0")
        + " fits",
    )
    hi = max(1.0, 2.0 * params.tau0_mpa, 2.0 * lo)
    while resid(hi) < 0.0:
        hi *= 2.0
        require(hi <= tau0_max_mpa, f"measured collapse needs tau0 > {tau0_max_mpa:g} MPa")
    return float(brentq(resid, lo, hi, xtol=1e-10, rtol=1e-10))


@dataclass(frozen=True)
class MeasurementComparison:
    """Measured stiffness data against the model at the data's p0, with the fitted τ0.

    Stresses are in the measure the data use (``stress_measure``), in MPa.
    ``fitted_params`` is ``params`` with τ0 replaced by the fitted value.
    """

    source: str
    p0_gpa: float
    stress_measure: str
    collapse_fraction: float
    plateau_stiffness_n_per_m: float
    measured_collapse_stress_mpa: float
    model_collapse_stress_mpa: float
    fitted_tau0_mpa: float
    fitted_params: ContactParameters

    def to_json(self) -> dict:
        """The summary as a JSON-ready dict (without ``fitted_params``)."""
        return {
            "source": self.source,
            "p0_gpa": self.p0_gpa,
            "stress_measure": self.stress_measure,
            "collapse_fraction": self.collapse_fraction,
            "plateau_stiffness_n_per_m": self.plateau_stiffness_n_per_m,
            "measured_collapse_stress_mpa": self.measured_collapse_stress_mpa,
            "model_collapse_stress_mpa": self.model_collapse_stress_mpa,
            "fitted_tau0_mpa": self.fitted_tau0_mpa,
        }


def compare_with_measurement(
    measured: MeasuredStiffness,
    p0_gpa: float,
    params: ContactParameters,
    *,
    fraction: float = 0.2,
    measure: str = "amplitude",
) -> MeasurementComparison:
    """Collapse of the data and of the model (same criterion), and the τ0 that matches them.

    The paper's inverse problem (Fig. 6): with every other parameter fixed, the τ0
    whose predicted stiffness collapse at ``p0_gpa`` equals the measured one.
    """
    p0_pa = params.check_p0_gpa(p0_gpa, "experiment_p0_gpa")[0] * units.GPA_TO_PA
    data = collapse_stress(measured.stress_pa, measured.stiffness_n_per_m, fraction=fraction)
    model = model_collapse_stress(p0_pa, params, fraction=fraction, measure=measure)
    tau0 = fit_tau0(data.stress_pa, p0_pa, params, fraction=fraction, measure=measure)
    return MeasurementComparison(
        source=measured.source,
        p0_gpa=float(p0_gpa),
        stress_measure=measure,
        collapse_fraction=fraction,
        plateau_stiffness_n_per_m=float(data.plateau_n_per_m),
        measured_collapse_stress_mpa=data.stress_pa / units.MPA_TO_PA,
        model_collapse_stress_mpa=model / units.MPA_TO_PA,
        fitted_tau0_mpa=tau0,
        fitted_params=params.replace(tau0_mpa=tau0),
    )
