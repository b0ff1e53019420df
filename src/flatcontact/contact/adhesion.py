"""Adhesive sphere-on-flat contact: DMT, JKR and Maugis–Dugdale, in SI units.

w is the work of adhesion (J/m²), not a surface energy. Loads are positive
compressive; the pull-off force is returned as a positive magnitude (the load at
separation is its negative). Load control throughout.

- DMT (Derjaguin, Muller, Toporov 1975):  a³ = 3R (P + 2πwR)/(4E*), pull-off 2πwR.
- JKR (Johnson, Kendall, Roberts 1971):  a³ = 3R/(4E*)·[P + 3πwR + √(6πwRP + (3πwR)²)],
  pull-off 1.5πwR.
- Maugis–Dugdale (Maugis 1992, J. Colloid Interface Sci. 150, 243; notation of
  Johnson & Greenwood 1997): with K = 4E*/3, Ā = a (K/(πwR²))^(1/3),
  P̄ = P/(πwR), m = c/a (c: edge of the Dugdale cohesive zone) and the Maugis
  parameter λ = 2σ_D (R/(πwK²))^(1/3) = σ_D (9R/(2πwE*²))^(1/3):

      (λĀ²/2)[√(m²−1) + (m²−2) arctan√(m²−1)]
        + (4λ²Ā/3)[√(m²−1) arctan√(m²−1) − m + 1] = 1,
      P̄ = Ā³ − λĀ²[√(m²−1) + m² arctan√(m²−1)].

  λ -> 0 gives DMT, λ -> ∞ gives JKR.

"Relative to Hertz at a given p0": the Hertz load of that p0 is applied to the
adhesive model and the radii are compared at equal load.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq, minimize_scalar

from flatcontact.contact.hertz import hertz_contact_radius, hertz_load
from flatcontact.contact.parameters import check_non_negative, check_positive
from flatcontact.foundation.errors import require

FloatArray = NDArray[np.float64]

MODELS = ("hertz", "dmt", "jkr", "maugis-dugdale")


def dmt_pull_off_force(work_of_adhesion_j_per_m2: ArrayLike, radius_m: float) -> FloatArray:
    """DMT pull-off force 2πwR (N)."""
    return 2.0 * np.pi * np.asarray(work_of_adhesion_j_per_m2, dtype=float) * radius_m


def jkr_pull_off_force(work_of_adhesion_j_per_m2: ArrayLike, radius_m: float) -> FloatArray:
    """JKR pull-off force 1.5πwR (N) under load control."""
    return 1.5 * np.pi * np.asarray(work_of_adhesion_j_per_m2, dtype=float) * radius_m


def dmt_contact_radius(
    load_n: ArrayLike, work_of_adhesion_j_per_m2: float, radius_m: float, contact_modulus_pa: float
) -> FloatArray:
    """DMT contact radius a = [3R(P + 2πwR)/(4E*)]^(1/3) (m); nan below pull-off."""
    total = np.asarray(load_n, dtype=float) + 2.0 * np.pi * work_of_adhesion_j_per_m2 * radius_m
    return np.cbrt(
        np.where(total >= 0.0, 3.0 * radius_m * total / (4.0 * contact_modulus_pa), np.nan)
    )


def jkr_contact_radius(
    load_n: ArrayLike, work_of_adhesion_j_per_m2: float, radius_m: float, contact_modulus_pa: float
) -> FloatArray:
    """JKR contact radius (m) on the stable branch; nan below the pull-off load −1.5πwR."""
    p = np.asarray(load_n, dtype=float)
    x = 3.0 * np.pi * work_of_adhesion_j_per_m2 * radius_m
    disc = 2.0 * x * p + x**2
    with np.errstate(invalid="ignore"):
        total = p + x + np.sqrt(np.where(disc >= 0.0, disc, np.nan))
    return np.cbrt(3.0 * radius_m * total / (4.0 * contact_modulus_pa))


def maugis_parameter(
    dugdale_stress_pa: float,
    work_of_adhesion_j_per_m2: float,
    radius_m: float,
    contact_modulus_pa: float,
) -> float:
    """λ = σ_D (9R/(2πwE*²))^(1/3) from the Dugdale (cohesive) stress σ_D (Pa)."""
    return dugdale_stress_pa * (
        9.0 * radius_m / (2.0 * np.pi * work_of_adhesion_j_per_m2 * contact_modulus_pa**2)
    ) ** (1.0 / 3.0)


def _md_cohesive_equation(m: float, abar: float, lam: float) -> float:
    t = np.sqrt(max(m * m - 1.0, 0.0))
    at = np.arctan(t)
    return (
        0.5 * lam * abar**2 * (t + (m * m - 2.0) * at)
        + 4.0 * lam**2 * abar / 3.0 * (t * at - m + 1.0)
        - 1.0
    )


def _md_m(abar: float, lam: float) -> float:
    """m = c/a solving the Maugis cohesive-zone equation at Ā (bracketed, the LHS rises with m)."""
    hi = 2.0
    while _md_cohesive_equation(hi, abar, lam) < 0.0:
        hi *= 2.0
        if hi > 1e12:
            raise ArithmeticError("Maugis–Dugdale: no cohesive-zone width found")
    return brentq(_md_cohesive_equation, 1.0, hi, args=(abar, lam), xtol=1e-14, rtol=1e-13)


def _md_load(abar: float, lam: float) -> float:
    m = _md_m(abar, lam)
    t = np.sqrt(m * m - 1.0)
    return abar**3 - lam * abar**2 * (t + m * m * np.arctan(t))


def _md_pull_off(lam: float) -> tuple[float, float]:
    """(Ā, P̄) at the minimum of P̄(Ā): the load-controlled pull-off."""
    # P̄(Ā) falls then rises; the minimum lies below the JKR/DMT scale Ā ~ 1.
    grid = np.geomspace(1e-4, 3.0, 60)
    vals = np.array([_md_load(x, lam) for x in grid])
    i = int(np.argmin(vals))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    res = minimize_scalar(
        lambda x: _md_load(x, lam), bounds=(lo, hi), method="bounded", options={"xatol": 1e-10}
    )
    return float(res.x), float(res.fun)


def maugis_dugdale_pull_off_force(
    work_of_adhesion_j_per_m2: float, radius_m: float, maugis_lambda: float
) -> float:
    """Pull-off force (N, magnitude) of the Maugis–Dugdale model under load control.

    Tends to 2πwR as λ -> 0 (DMT) and to 1.5πwR as λ -> ∞ (JKR).
    """
    lam = check_positive("maugis_lambda", maugis_lambda)
    _, pbar = _md_pull_off(lam)
    return -pbar * np.pi * work_of_adhesion_j_per_m2 * radius_m


def maugis_dugdale_contact_radius(
    load_n: ArrayLike,
    work_of_adhesion_j_per_m2: float,
    radius_m: float,
    contact_modulus_pa: float,
    maugis_lambda: float,
) -> FloatArray:
    """Maugis–Dugdale contact radius a (m) at load P (N), stable (load-controlled) branch.

    Solves P̄(Ā) = P/(πwR) for Ā above the pull-off point; nan below pull-off.
    """
    lam = check_positive("maugis_lambda", maugis_lambda)
    w = check_positive("work_of_adhesion_j_per_m2", work_of_adhesion_j_per_m2)
    kmod = 4.0 * contact_modulus_pa / 3.0
    length = (np.pi * w * radius_m**2 / kmod) ** (1.0 / 3.0)  # a = Ā · length
    a_min, p_min = _md_pull_off(lam)
    loads = np.atleast_1d(np.asarray(load_n, dtype=float)) / (np.pi * w * radius_m)
    out = np.full(loads.shape, np.nan)
    for i, pbar in enumerate(loads.ravel()):
        if not np.isfinite(pbar) or pbar < p_min:
            continue
        hi = max(2.0 * a_min, 1.0)
        while _md_load(hi, lam) < pbar:
            hi *= 2.0
        out.flat[i] = brentq(
            lambda x, pb=pbar: _md_load(x, lam) - pb, a_min, hi, xtol=1e-14, rtol=1e-13
        )
    return np.reshape(out * length, np.shape(load_n))


def contact_radius_at_p0(
    model: str,
    p0_pa: ArrayLike,
    radius_m: float,
    contact_modulus_pa: float,
    work_of_adhesion_j_per_m2: float = 0.0,
    maugis_lambda: float | None = None,
) -> FloatArray:
    """Contact radius (m) of ``model`` at the Hertz load of peak pressure p0 (Pa)."""
    require(model in MODELS, f"adhesion model must be one of {MODELS}, got {model!r}")
    w = check_non_negative("work_of_adhesion_j_per_m2", work_of_adhesion_j_per_m2)
    p0 = np.asarray(p0_pa, dtype=float)
    a_h = hertz_contact_radius(p0, radius_m, contact_modulus_pa)
    load = hertz_load(p0, a_h)
    if model == "hertz" or w == 0.0:
        return a_h
    if model == "dmt":
        return dmt_contact_radius(load, w, radius_m, contact_modulus_pa)
    if model == "jkr":
        return jkr_contact_radius(load, w, radius_m, contact_modulus_pa)
    require(maugis_lambda is not None, "maugis_lambda is required for the Maugis–Dugdale model")
    return maugis_dugdale_contact_radius(
        load, w, radius_m, contact_modulus_pa, float(maugis_lambda)
    )


def radius_change_relative_to_hertz(
    model: str,
    p0_pa: ArrayLike,
    radius_m: float,
    contact_modulus_pa: float,
    work_of_adhesion_j_per_m2: float,
    maugis_lambda: float | None = None,
) -> FloatArray:
    """a_model/a_Hertz − 1 at the Hertz load of p0 (dimensionless, 0.3 = 30% larger)."""
    a_h = hertz_contact_radius(p0_pa, radius_m, contact_modulus_pa)
    a_m = contact_radius_at_p0(
        model, p0_pa, radius_m, contact_modulus_pa, work_of_adhesion_j_per_m2, maugis_lambda
    )
    return a_m / a_h - 1.0


def dmt_work_of_adhesion_for_radius_ratio(
    ratio: float, p0_pa: float, radius_m: float, contact_modulus_pa: float
) -> float:
    """w (J/m²) for which a_DMT/a_Hertz = ``ratio`` at the Hertz load of p0 (closed form):
    (1 + 2πwR/P)^(1/3) = ratio  ->  w = P (ratio³ − 1)/(2πR)."""
    r = check_positive("ratio", ratio)
    require(r >= 1.0, f"ratio must be >= 1 (DMT only enlarges the contact), got {ratio!r}")
    load = float(hertz_load(p0_pa, hertz_contact_radius(p0_pa, radius_m, contact_modulus_pa)))
    return load * (r**3 - 1.0) / (2.0 * np.pi * radius_m)


def dmt_p0_for_radius_ratio(
    ratio: float, work_of_adhesion_j_per_m2: float, radius_m: float, contact_modulus_pa: float
) -> float:
    """p0 (Pa) above which a_DMT/a_Hertz < ``ratio`` (closed form; P ∝ p0³)."""
    r = check_positive("ratio", ratio)
    require(r > 1.0, f"ratio must be > 1, got {ratio!r}")
    # P(p0) = (2/3)π a² p0 with a = πRp0/(2E*): P = c p0³
    c = float(hertz_load(1.0, hertz_contact_radius(1.0, radius_m, contact_modulus_pa)))
    load = 2.0 * np.pi * work_of_adhesion_j_per_m2 * radius_m / (r**3 - 1.0)
    return (load / c) ** (1.0 / 3.0)
