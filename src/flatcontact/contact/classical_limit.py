"""How far the paper's modified Mindlin model is from Cattaneo–Mindlin in the classical limit.

In the limit k = μ, τ0 = σ0 = 0 (Coulomb friction with coefficient μ everywhere) and
G* = 4 G*_J (:mod:`flatcontact.contact.moduli`), the paper's model
(:mod:`flatcontact.contact.mindlin`) keeps the full-stick traction q0/s in the stick zone
(no Cattaneo corrective traction), so with x = u/δ*, δ* = 3μP/(16 G*_J a):

- paper:           Q/μP = 3s² − 2s³ with s² = x/2 (full slip at x = 2);
- Cattaneo–Mindlin: Q/μP = 1 − (1 − x)^(3/2) (full slip at x = 1; Johnson 1985, Eq. 7.47,
  :mod:`flatcontact.contact.cattaneo_mindlin`).

They agree in the initial stiffness 8 G*_J a and at full slip (Q = μP), not in between; at
the same stick radius the paper's displacement is exactly twice Cattaneo–Mindlin's. The
comparison is dimensionless, on a grid.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class ClassicalLimitComparison:
    """The paper's model in the classical limit against Cattaneo–Mindlin.

    Closed forms, x = u/δ* with δ* = 3μP/(16 G*_J a) (CM's full-slip displacement):
    paper Q/μP = 3(x/2) − 2(x/2)^(3/2) for x <= 2 (then 1); CM Q/μP = 1 − (1 − x)^(3/2)
    for x <= 1 (then 1).

    Attributes
    ----------
    max_force_deviation : max over u of |Q_paper − Q_CM|/μP
    displacement_of_max_deviation : x at that maximum
    max_stick_radius_deviation : max over Q of |c_paper − c_CM|/a at equal Q
    displacement_ratio_at_equal_stick_radius : u_paper/δ_CM at equal c (exactly 2)
    """

    max_force_deviation: float
    displacement_of_max_deviation: float
    max_stick_radius_deviation: float
    displacement_ratio_at_equal_stick_radius: float


def classical_limit_of_paper_model(n: int = 200_001) -> ClassicalLimitComparison:
    """Quantify how far the paper's model is from Cattaneo–Mindlin in the classical limit
    (k = μ, τ0 = σ0 = 0, G* = 4 G*_J), on a grid of ``n`` points (dimensionless)."""
    x = np.linspace(0.0, 2.0, n)
    s = np.sqrt(np.clip(x / 2.0, 0.0, 1.0))
    q_paper = 3.0 * s**2 - 2.0 * s**3
    q_cm = 1.0 - (1.0 - np.clip(x, 0.0, 1.0)) ** 1.5
    dev = np.abs(q_paper - q_cm)
    i = int(np.argmax(dev))
    ss = np.linspace(0.0, 1.0, n)
    qr = 3.0 * ss**2 - 2.0 * ss**3
    c_paper = np.sqrt(1.0 - ss**2)
    c_cm = np.cbrt(1.0 - qr)
    # at equal c: paper u/δ* = 2 s², CM δ/δ* = 1 − (c/a)² = s²
    c_over_a = np.linspace(0.01, 0.99, 99)
    u_paper = 2.0 * (1.0 - c_over_a**2)  # u/δ* = 2 s²
    d_cm = 1.0 - np.cbrt(1.0 - (1.0 - c_over_a**3)) ** 2  # δ/δ* at Q/μP = 1 − (c/a)³
    ratio = float(np.max(u_paper / d_cm))
    return ClassicalLimitComparison(
        max_force_deviation=float(dev[i]),
        displacement_of_max_deviation=float(x[i]),
        max_stick_radius_deviation=float(np.max(np.abs(c_paper - c_cm))),
        displacement_ratio_at_equal_stick_radius=ratio,
    )
