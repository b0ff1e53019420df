"""Hertz contact of a sphere (radius R) on a flat, in SI units.

Johnson, *Contact Mechanics* (1985), §4.2; the paper's Eqs. for a, p(r), P:

- contact radius      a = π R p0 / (2 E*)        (equivalently a³ = 3 P R / (4 E*))
- pressure            p(r) = p0 √(1 − r²/a²),  r ≤ a
- load                P = (2/3) π a² p0,  mean pressure p̄ = 2 p0 / 3
- approach            δ = a² / R

E* is the contact modulus, 1/E* = (1−ν1²)/E1 + (1−ν2²)/E2. All functions
broadcast over numpy arrays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from flatcontact.foundation.errors import require

FloatArray = NDArray[np.float64]


def hertz_contact_radius(
    p0_pa: ArrayLike, radius_m: float, contact_modulus_pa: float
) -> FloatArray:
    """Contact radius a = π R p0 / (2 E*) (m) for a peak pressure p0 (Pa)."""
    return np.pi * radius_m * np.asarray(p0_pa, dtype=float) / (2.0 * contact_modulus_pa)


def hertz_peak_pressure(
    contact_radius_m: ArrayLike, radius_m: float, contact_modulus_pa: float
) -> FloatArray:
    """Peak pressure p0 = 2 E* a / (π R) (Pa), the inverse of :func:`hertz_contact_radius`."""
    return 2.0 * contact_modulus_pa * np.asarray(contact_radius_m, dtype=float) / (np.pi * radius_m)


def hertz_load(p0_pa: ArrayLike, contact_radius_m: ArrayLike) -> FloatArray:
    """Total normal load P = (2/3) π a² p0 (N)."""
    a = np.asarray(contact_radius_m, dtype=float)
    return 2.0 / 3.0 * np.pi * a**2 * np.asarray(p0_pa, dtype=float)


def hertz_radius_from_load(
    load_n: ArrayLike, radius_m: float, contact_modulus_pa: float
) -> FloatArray:
    """Contact radius a = (3 P R / (4 E*))^(1/3) (m) at a load P >= 0 (N)."""
    return np.cbrt(3.0 * np.asarray(load_n, dtype=float) * radius_m / (4.0 * contact_modulus_pa))


def hertz_pressure(r_m: ArrayLike, contact_radius_m: ArrayLike, p0_pa: ArrayLike) -> FloatArray:
    """Pressure p(r) = p0 √(1 − r²/a²) inside the contact, 0 outside (Pa)."""
    r = np.asarray(r_m, dtype=float)
    a = np.asarray(contact_radius_m, dtype=float)
    inside = 1.0 - (r / a) ** 2
    return np.asarray(p0_pa, dtype=float) * np.sqrt(np.clip(inside, 0.0, None))


@dataclass(frozen=True)
class HertzContact:
    """A solved Hertz contact (SI units; arrays broadcast over the inputs).

    Attributes
    ----------
    p0_pa : peak pressure (Pa)
    contact_radius_m : a (m)
    load_n : P (N)
    mean_pressure_pa : p̄ = 2 p0/3 = P/(π a²) (Pa)
    approach_m : δ = a²/R (m), the mutual approach of distant points
    """

    p0_pa: FloatArray
    contact_radius_m: FloatArray
    load_n: FloatArray
    mean_pressure_pa: FloatArray
    approach_m: FloatArray


def solve_hertz(
    radius_m: float,
    contact_modulus_pa: float,
    *,
    p0_pa: ArrayLike | None = None,
    load_n: ArrayLike | None = None,
    contact_radius_m: ArrayLike | None = None,
) -> HertzContact:
    """Solve the Hertz contact from exactly one of p0, P or a.

    Raises
    ------
    InputError
        Unless exactly one of ``p0_pa``, ``load_n``, ``contact_radius_m`` is
        given and all its values are finite and > 0, and R, E* are > 0.
    """
    require(np.isfinite(radius_m) and radius_m > 0, f"radius_m must be > 0, got {radius_m!r}")
    require(
        np.isfinite(contact_modulus_pa) and contact_modulus_pa > 0,
        f"contact_modulus_pa must be > 0, got {contact_modulus_pa!r}",
    )
    given = {"p0_pa": p0_pa, "load_n": load_n, "contact_radius_m": contact_radius_m}
    named = [k for k, v in given.items() if v is not None]
    require(len(named) == 1, f"give exactly one of p0_pa, load_n, contact_radius_m (got {named})")
    name = named[0]
    value = np.asarray(given[name], dtype=float)
    require(
        bool(np.all(np.isfinite(value)) and np.all(value > 0)),
        f"{name} must be finite and > 0, got {given[name]!r}",
    )
    if name == "p0_pa":
        a = hertz_contact_radius(value, radius_m, contact_modulus_pa)
    elif name == "load_n":
        a = hertz_radius_from_load(value, radius_m, contact_modulus_pa)
    else:
        a = value
    p0 = hertz_peak_pressure(a, radius_m, contact_modulus_pa)
    return HertzContact(
        p0_pa=p0,
        contact_radius_m=a,
        load_n=hertz_load(p0, a),
        mean_pressure_pa=2.0 / 3.0 * p0,
        approach_m=a**2 / radius_m,
    )
