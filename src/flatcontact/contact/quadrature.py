"""The paper's modified Mindlin integrals evaluated numerically: the independent reference.

The closed forms of :mod:`flatcontact.contact.mindlin` are checked against, and
benchmarked against, this direct evaluation of the paper's rule "stick where the
full-stick traction is below the local shear strength": the stick zone is the set
of r where m(r) = q(r) − τ(r) < 0, its boundaries are found by root finding
(brentq) on m, and then

    Q_stick = 2π ∫_stick q0/√(1 − r²/a²) r dr,   Q_slip = 2π ∫_slip (μ p0 √(1 − r²/a²) + σ0) r dr

by adaptive quadrature (scipy ``quad``; the stick integral as ∫_{c_in}^a − ∫_c^a with
the edge singularity (a − r)^(−1/2) as quad's algebraic weight). For k >= 0, m increases with r (a stick disc
r < c, the paper's case); for k < 0, m(r) = q0/s + |k| p0 s − τ0 is convex in
s = √(1 − r²/a²), so it has one minimum (found by ``minimize_scalar``) and at most
two roots: the stick zone is a disc or, once the centre slips, an annulus.
SI units; the paper's G* (q0 = G*·u/(π a)).
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq, minimize_scalar

from flatcontact.contact.mindlin import contact_radius
from flatcontact.contact.parameters import ContactParameters

#: scipy's default tolerances of ``quad``
QUAD_DEFAULT_EPSABS = 1.49e-8
QUAD_DEFAULT_EPSREL = 1.49e-8


def stick_zone_by_root_finding(
    u_m: float, p0_pa: float, params: ContactParameters, counter: list[int] | None = None
) -> tuple[float, float]:
    """Inner and outer radius (m) of the stick zone {r : q(r) < τ(r)} by brentq.

    (0, c) for a stick disc, (c_in, c) for an annulus, (0, 0) at full slip, (0, a)
    at u = 0. ``counter[0]`` is incremented per evaluation of q − τ.
    """
    calls = counter if counter is not None else [0, 0]
    a = float(contact_radius(p0_pa, params))
    q0 = params.shear_modulus_pa * u_m / (np.pi * a)
    edge = a * (1 - 1e-15)

    def mismatch(r: float) -> float:
        calls[0] += 1
        s = np.sqrt(1 - (r / a) ** 2)
        return q0 / s - (params.k * p0_pa * s + params.tau0_pa)

    if q0 == 0.0:
        return 0.0, a
    m_centre = mismatch(0.0)
    r_min, m_min = 0.0, m_centre
    if params.k < 0:  # m(r) has one interior minimum
        res = minimize_scalar(
            mismatch, bounds=(0.0, edge), method="bounded", options={"xatol": 1e-12 * a}
        )
        if res.fun < m_min:
            r_min, m_min = float(res.x), float(res.fun)
    if m_min >= 0.0:
        return 0.0, 0.0
    outer = a if mismatch(edge) < 0 else brentq(mismatch, r_min, edge, xtol=1e-16 * a)
    inner = 0.0 if m_centre <= 0.0 else brentq(mismatch, 0.0, r_min, xtol=1e-16 * a)
    return float(inner), float(outer)


def paper_integrals(
    u_m: float,
    p0_pa: float,
    params: ContactParameters,
    *,
    epsabs: float = QUAD_DEFAULT_EPSABS,
    epsrel: float = QUAD_DEFAULT_EPSREL,
    counter: list[int] | None = None,
) -> tuple[float, float, float]:
    """Outer stick radius c (m), Q_stick and Q_slip (N) at displacement ``u_m``, by quadrature.

    ``counter``, if given, is a two-item list incremented by the number of evaluations
    of the stick-boundary mismatch (index 0) and of the integrands (index 1).
    """
    calls = counter if counter is not None else [0, 0]
    a = float(contact_radius(p0_pa, params))
    q0 = params.shear_modulus_pa * u_m / (np.pi * a)
    c_in, c = stick_zone_by_root_finding(u_m, p0_pa, params, calls)
    kw = {"epsabs": epsabs, "epsrel": epsrel}

    def stick_regular(r: float) -> float:
        # q0/√(1 − r²/a²)·2πr = [2π r q0 a/√(a + r)]·(a − r)^(−1/2): the singular factor
        # goes into quad's algebraic weight, on intervals that end at r = a
        calls[1] += 1
        return 2 * np.pi * r * q0 * a / np.sqrt(a + r)

    def stick_to_edge(r0: float) -> float:
        return quad(stick_regular, r0, a, weight="alg", wvar=(0.0, -0.5), **kw)[0]

    def slip(r: float) -> float:
        calls[1] += 1
        s = np.sqrt(max(1 - (r / a) ** 2, 0.0))
        return 2 * np.pi * r * (params.mu * p0_pa * s + params.sigma0_pa)

    q_stick = stick_to_edge(c_in) - (stick_to_edge(c) if c < a else 0.0) if c > c_in else 0.0
    q_slip = quad(slip, c, a, **kw)[0] + (quad(slip, 0.0, c_in, **kw)[0] if c_in > 0 else 0.0)
    return float(c), float(q_stick), float(q_slip)
