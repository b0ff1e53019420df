"""The paper's modified Mindlin integrals evaluated numerically: the independent reference.

The closed forms of :mod:`flatcontact.contact.mindlin` are checked against, and
benchmarked against, this direct evaluation of the paper's equations: the stick
radius c from q(c) = τ(c) by brentq, then

    Q_stick = 2π ∫0^c q0/√(1 − r²/a²) r dr,   Q_slip = 2π ∫c^a (μ p0 √(1 − r²/a²) + σ0) r dr

by adaptive quadrature (scipy ``quad``). SI units; the paper's G* (q0 = G*·u/(π a)).
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq

from flatcontact.contact.mindlin import contact_radius
from flatcontact.contact.parameters import ContactParameters

#: scipy's default tolerances of ``quad``
QUAD_DEFAULT_EPSABS = 1.49e-8
QUAD_DEFAULT_EPSREL = 1.49e-8


def paper_integrals(
    u_m: float,
    p0_pa: float,
    params: ContactParameters,
    *,
    epsabs: float = QUAD_DEFAULT_EPSABS,
    epsrel: float = QUAD_DEFAULT_EPSREL,
    counter: list[int] | None = None,
) -> tuple[float, float, float]:
    """Stick radius c (m), Q_stick and Q_slip (N) at displacement ``u_m``, by quadrature.

    ``counter``, if given, is a two-item list incremented by the number of evaluations
    of the stick-boundary mismatch (index 0) and of the integrands (index 1).
    """
    calls = counter if counter is not None else [0, 0]
    a = float(contact_radius(p0_pa, params))
    q0 = params.shear_modulus_pa * u_m / (np.pi * a)
    edge = a * (1 - 1e-15)

    def mismatch(r: float) -> float:
        calls[0] += 1
        s = np.sqrt(1 - (r / a) ** 2)
        return q0 / s - (params.k * p0_pa * s + params.tau0_pa)

    if q0 == 0.0 or mismatch(edge) < 0:
        c = a
    elif mismatch(0.0) >= 0:
        c = 0.0
    else:
        c = brentq(mismatch, 0.0, edge, xtol=1e-16 * a)

    def stick(r: float) -> float:
        calls[1] += 1
        return 2 * np.pi * r * q0 / np.sqrt(1 - (r / a) ** 2)

    def slip(r: float) -> float:
        calls[1] += 1
        s = np.sqrt(max(1 - (r / a) ** 2, 0.0))
        return 2 * np.pi * r * (params.mu * p0_pa * s + params.sigma0_pa)

    q_stick = quad(stick, 0, c, epsabs=epsabs, epsrel=epsrel)[0]
    q_slip = quad(slip, c, a, epsabs=epsabs, epsrel=epsrel)[0]
    return float(c), float(q_stick), float(q_slip)
