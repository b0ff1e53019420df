"""Classical Cattaneo–Mindlin contact with Mindlin–Deresiewicz unloading, in SI units.

One theory, plain-number functions (like :mod:`flatcontact.contact.hertz`): every
function takes and returns numbers or numpy arrays and broadcasts.

Conventions
-----------
Johnson, *Contact Mechanics* (1985), §7.2 and §7.4. A Hertz contact of radius a
under normal load P, Coulomb friction coefficient μ everywhere (static = kinetic),
tangential force Q along one axis, relative tangential displacement δ of distant
points. The shear modulus is **Johnson's** G*_J, 1/G*_J = (2−ν1)/G1 + (2−ν2)/G2; the
paper's G* (q0 = G*·u/(π a)) is 4 G*_J (:mod:`flatcontact.contact.moduli`).
``friction_limit_n`` is μP.

- loading from rest (Johnson Eqs. 7.43, 7.47), 0 <= Q <= μP:
  c/a = (1 − Q/μP)^(1/3),   δ = δ_s [1 − (1 − Q/μP)^(2/3)],   δ_s = 3μP/(16 G*_J a),
  Q(δ) = μP [1 − (1 − δ/δ_s)^(3/2)]; initial stiffness dQ/dδ = 8 G*_J a.
- unloading from (δ*, Q*) (Mindlin & Deresiewicz 1953; Johnson Eq. 7.58), Masing's rule:
  Q*−Q = 2 Q_load((δ*−δ)/2), i.e. δ = δ_s [2(1 − (Q*−Q)/(2μP))^(2/3) − (1 − Q*/μP)^(2/3) − 1];
  reloading from (−δ*, −Q*) is its mirror image; the loop closes (steady from the first
  reversal).
- energy dissipated per cycle of amplitude Q* (Johnson Eq. 7.59):
  W = 9μ²P²/(10 G*_J a)·[1 − (1 − Q*/μP)^(5/3) − (5Q*/(6μP))(1 + (1 − Q*/μP)^(2/3))],
  W → Q*³/(36 G*_J a μP) as Q* → 0 (cubic).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


def full_slip_displacement(
    friction_limit_n: ArrayLike, contact_radius_m: ArrayLike, johnson_shear_modulus_pa: ArrayLike
) -> FloatArray:
    """δ_s = 3μP/(16 G*_J a) (m): the displacement at which the contact slides (Q = μP)."""
    return (
        3.0
        * np.asarray(friction_limit_n, dtype=float)
        / (16.0 * np.asarray(johnson_shear_modulus_pa) * np.asarray(contact_radius_m))
    )


def stick_radius(
    lateral_force_n: ArrayLike, friction_limit_n: ArrayLike, contact_radius_m: ArrayLike
) -> FloatArray:
    """c = a (1 − Q/μP)^(1/3) (m), Johnson (1985) Eq. 7.43; ``friction_limit_n`` = μP."""
    ratio = np.clip(
        np.asarray(lateral_force_n, dtype=float) / np.asarray(friction_limit_n), 0.0, 1.0
    )
    return np.asarray(contact_radius_m, dtype=float) * np.cbrt(1.0 - ratio)


def displacement(
    lateral_force_n: ArrayLike,
    friction_limit_n: ArrayLike,
    contact_radius_m: ArrayLike,
    johnson_shear_modulus_pa: ArrayLike,
) -> FloatArray:
    """δ = 3μP/(16 G*_J a)·[1 − (1 − Q/μP)^(2/3)] (m) on loading, Johnson (1985) Eq. 7.47."""
    mup = np.asarray(friction_limit_n, dtype=float)
    ratio = np.clip(np.asarray(lateral_force_n, dtype=float) / mup, 0.0, 1.0)
    pref = full_slip_displacement(mup, contact_radius_m, johnson_shear_modulus_pa)
    return pref * (1.0 - np.cbrt(1.0 - ratio) ** 2)


def force(
    displacement_m: ArrayLike,
    friction_limit_n: ArrayLike,
    contact_radius_m: ArrayLike,
    johnson_shear_modulus_pa: ArrayLike,
) -> FloatArray:
    """Q(δ) = μP [1 − (1 − δ/δ_s)^(3/2)] for 0 <= δ <= δ_s, μP beyond (N), on loading."""
    mup = np.asarray(friction_limit_n, dtype=float)
    dstar = full_slip_displacement(mup, contact_radius_m, johnson_shear_modulus_pa)
    x = np.clip(np.asarray(displacement_m, dtype=float) / dstar, 0.0, 1.0)
    return mup * (1.0 - (1.0 - x) ** 1.5)


def unloading_displacement(
    lateral_force_n: ArrayLike,
    force_amplitude_n: ArrayLike,
    friction_limit_n: ArrayLike,
    contact_radius_m: ArrayLike,
    johnson_shear_modulus_pa: ArrayLike,
) -> FloatArray:
    """δ(Q) (m) on the unloading branch from (δ*, Q*) down to (−δ*, −Q*), Johnson Eq. 7.58:
    δ = δ_s [2(1 − (Q*−Q)/(2μP))^(2/3) − (1 − Q*/μP)^(2/3) − 1], −Q* <= Q <= Q* < μP.
    The reloading branch is −δ(−Q)."""
    mup = np.asarray(friction_limit_n, dtype=float)
    q = np.asarray(lateral_force_n, dtype=float)
    qa = np.asarray(force_amplitude_n, dtype=float)
    pref = full_slip_displacement(mup, contact_radius_m, johnson_shear_modulus_pa)
    back = np.clip((qa - q) / (2.0 * mup), 0.0, 1.0)
    return pref * (2.0 * np.cbrt(1.0 - back) ** 2 - np.cbrt(1.0 - qa / mup) ** 2 - 1.0)


def unloading_force(
    displacement_m: ArrayLike,
    force_amplitude_n: ArrayLike,
    friction_limit_n: ArrayLike,
    contact_radius_m: ArrayLike,
    johnson_shear_modulus_pa: ArrayLike,
) -> FloatArray:
    """Q(δ) (N) on the unloading branch from (δ*, Q*): Q = Q* − 2 Q_load((δ* − δ)/2)
    (Masing's rule, the inverse of :func:`unloading_displacement`)."""
    qa = np.asarray(force_amplitude_n, dtype=float)
    mup = np.asarray(friction_limit_n, dtype=float)
    d_top = displacement(qa, mup, contact_radius_m, johnson_shear_modulus_pa)
    back = (d_top - np.asarray(displacement_m, dtype=float)) / 2.0
    return qa - 2.0 * force(back, mup, contact_radius_m, johnson_shear_modulus_pa)


def dissipated_energy(
    force_amplitude_n: ArrayLike,
    friction_limit_n: ArrayLike,
    contact_radius_m: ArrayLike,
    johnson_shear_modulus_pa: ArrayLike,
) -> FloatArray:
    """Energy dissipated per cycle (J) at force amplitude Q* < μP, Johnson (1985) Eq. 7.59:
    W = 9μ²P²/(10 G*_J a)·[1 − (1 − x)^(5/3) − (5x/6)(1 + (1 − x)^(2/3))], x = Q*/μP."""
    mup = np.asarray(friction_limit_n, dtype=float)
    x = np.clip(np.asarray(force_amplitude_n, dtype=float) / mup, 0.0, 1.0)
    g = np.asarray(johnson_shear_modulus_pa, dtype=float)
    a = np.asarray(contact_radius_m, dtype=float)
    c = np.cbrt(1.0 - x)
    bracket = 1.0 - c**5 - (5.0 * x / 6.0) * (1.0 + c**2)
    # small x: the bracket is 5x³/162 + O(x⁴) and cancels; use the series there
    series = x**3 * (5.0 / 162.0 + x * (5.0 / 243.0 + x * (7.0 / 486.0 + x * 70.0 / 6561.0)))
    bracket = np.where(x < 1e-3, series, bracket)
    return 9.0 * mup**2 / (10.0 * g * a) * bracket


def initial_stiffness(
    contact_radius_m: ArrayLike, johnson_shear_modulus_pa: ArrayLike
) -> FloatArray:
    """dQ/dδ at δ = 0 and right after any reversal: 8 G*_J a (N/m)."""
    return 8.0 * np.asarray(johnson_shear_modulus_pa, dtype=float) * np.asarray(contact_radius_m)
