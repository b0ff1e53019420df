"""The paper's modified Mindlin model and classical Cattaneo–Mindlin, in SI units.

Modified Mindlin model (Dong et al., section "Modified Mindlin model")
---------------------------------------------------------------------
A Hertz contact (radius a, peak pressure p0, p(r) = p0·s(r) with
s(r) = √(1 − r²/a²)) is displaced laterally by u.

- local shear strength      τ(r) = k·p(r) + τ0
- slip-zone friction        σ(r) = μ·p(r) + σ0
- full-stick traction       q(r) = q0 / s(r),  q0 = G*·u/(π a)   (the paper's G*)
- stick radius c            q(c) = τ(c); with s = √(1 − c²/a²) this is the quadratic
                            k·p0·s² + τ0·s − q0 = 0, root s = 2 q0 / (τ0 + √(τ0² + 4 k p0 q0));
                            s >= 1 means full slip (c = 0)
- stick force               Q_stick = 2π ∫0^c q r dr = 2π a² q0 (1 − s)
- slip force                Q_slip = 2π ∫c^a σ r dr = 2π a² (μ p0 s³/3 + σ0 s²/2)
- total                     Q(u) = Q_stick + Q_slip; saturated (gross sliding) force
                            Q_sat = ∫σ dA = 2π a² (μ p0/3 + σ0/2), reached at s = 1,
                            u_fs = π a (k p0 + τ0)/G*.

Eliminating q0 = k p0 s² + τ0 s gives Q(s)/(2π a²) = A1 s + A2 s² + A3 s³ with
A1 = τ0, A2 = k p0 − τ0 + σ0/2, A3 = μ p0/3 − k p0 and u(s) = π a (k p0 s² + τ0 s)/G*.
Both are monotone in u ↔ s, so the peak and the inverse u(Q) are closed forms
(a quadratic for dQ/ds = 0, a cubic for Q(s) = Q).

Inside the stick zone the paper keeps the full-stick traction q0/s (no
Cattaneo corrective traction). Consequently, in the classical limit
(k = μ, τ0 = σ0 = 0, G* = 4 G*_J) it gives Q/μP = 3s² − 2s³ and a displacement
twice Cattaneo–Mindlin's at the same stick radius: it agrees with
Cattaneo–Mindlin in the initial stiffness 8 G*_J a and at full slip (Q = μP),
not in between (see :func:`classical_limit_of_paper_model` and docs/contact.md).

Classical Cattaneo–Mindlin (Johnson, *Contact Mechanics*, 1985, §7.2)
--------------------------------------------------------------------
c/a = (1 − Q/μP)^(1/3), δ = 3μP/(16 G*_J a)·[1 − (1 − Q/μP)^(2/3)] with
1/G*_J = (2−ν1)/G1 + (2−ν2)/G2 (Johnson's convention; paper's G* = 4 G*_J).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from flatcontact.contact.hertz import hertz_contact_radius
from flatcontact.contact.parameters import ContactParameters

FloatArray = NDArray[np.float64]

# --------------------------------------------------------------------------------------
# shear-modulus conventions


def johnson_effective_shear_modulus(g1_pa: float, nu1: float, g2_pa: float, nu2: float) -> float:
    """Johnson's G*_J from the shear moduli and Poisson ratios: 1/G*_J = (2−ν1)/G1 + (2−ν2)/G2."""
    return 1.0 / ((2.0 - nu1) / g1_pa + (2.0 - nu2) / g2_pa)


def paper_shear_modulus_from_johnson(g_johnson: ArrayLike) -> FloatArray:
    """The paper's G* (q0 = G*·u/(π a)) from Johnson's G*_J (q0 = 4 G*_J u/(π a)): G* = 4 G*_J."""
    return 4.0 * np.asarray(g_johnson, dtype=float)


def johnson_shear_modulus_from_paper(g_paper: ArrayLike) -> FloatArray:
    """Johnson's G*_J from the paper's G*: G*_J = G*/4."""
    return np.asarray(g_paper, dtype=float) / 4.0


# --------------------------------------------------------------------------------------
# local laws and tractions


def shear_strength(p_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """Local shear strength τ = k·p + τ0 (Pa) at local pressure p (Pa)."""
    return params.k * np.asarray(p_pa, dtype=float) + params.tau0_pa


def slip_friction(p_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """Local slip-zone friction σ = μ·p + σ0 (Pa) at local pressure p (Pa)."""
    return params.mu * np.asarray(p_pa, dtype=float) + params.sigma0_pa


def full_stick_q0(
    u_m: ArrayLike, contact_radius_m: ArrayLike, params: ContactParameters
) -> FloatArray:
    """Centre traction q0 = G*·u/(π a) (Pa) of a fully stuck contact (paper's G*)."""
    return (
        params.shear_modulus_pa
        * np.asarray(u_m, dtype=float)
        / (np.pi * np.asarray(contact_radius_m))
    )


def full_stick_traction(
    r_m: ArrayLike, u_m: ArrayLike, contact_radius_m: ArrayLike, params: ContactParameters
) -> FloatArray:
    """Full-stick traction q(r) = q0/√(1 − r²/a²) (Pa) for r < a (inf at r = a, nan beyond)."""
    a = np.asarray(contact_radius_m, dtype=float)
    s2 = 1.0 - (np.asarray(r_m, dtype=float) / a) ** 2
    with np.errstate(divide="ignore", invalid="ignore"):
        return full_stick_q0(u_m, a, params) / np.sqrt(s2)


def stick_boundary_s(q0_pa: ArrayLike, p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """Root s = √(1 − c²/a²) of k p0 s² + τ0 s − q0 = 0 (clipped to [0, 1]).

    Uses the cancellation-free form s = 2 q0 / (τ0 + √(τ0² + 4 k p0 q0)), valid
    for k = 0 too. s = 1 means full slip (c = 0), s = 0 full stick (q0 = 0).
    """
    q0 = np.asarray(q0_pa, dtype=float)
    kp0 = params.k * np.asarray(p0_pa, dtype=float)
    tau0 = params.tau0_pa
    den = tau0 + np.sqrt(tau0**2 + 4.0 * kp0 * q0)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(q0 > 0.0, 2.0 * q0 / den, 0.0)
    return np.clip(np.nan_to_num(s, nan=1.0, posinf=1.0), 0.0, 1.0)


# --------------------------------------------------------------------------------------
# Q(u)


@dataclass(frozen=True)
class LateralResponse:
    """Q(u) of the modified Mindlin model at displacements u (SI; arrays broadcast).

    Attributes
    ----------
    displacement_m : u (m)
    lateral_force_n : Q = Q_stick + Q_slip (N)
    stick_force_n, slip_force_n : the two contributions (N)
    stick_radius_m : c (m); 0 at full slip
    s : √(1 − c²/a²) in [0, 1]
    q0_pa : full-stick centre traction G*·u/(π a) (Pa)
    """

    displacement_m: FloatArray
    lateral_force_n: FloatArray
    stick_force_n: FloatArray
    slip_force_n: FloatArray
    stick_radius_m: FloatArray
    s: FloatArray
    q0_pa: FloatArray


def contact_radius(p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """Hertz radius a (m) at peak pressure p0 (Pa) for the tip and E* of ``params``."""
    return hertz_contact_radius(p0_pa, params.radius_m, params.contact_modulus_pa)


def lateral_force(u_m: ArrayLike, p0_pa: ArrayLike, params: ContactParameters) -> LateralResponse:
    """Total lateral force Q(u) of the modified Mindlin model (closed form).

    Parameters
    ----------
    u_m : array_like
        Lateral displacement u >= 0 (m).
    p0_pa : array_like
        Peak Hertz pressure (Pa); broadcasts against ``u_m`` (e.g. ``p0[:, None]``).
    params : ContactParameters

    Returns
    -------
    LateralResponse
        Q = 2π a² [q0 (1 − s) + μ p0 s³/3 + σ0 s²/2], s from the stick condition.
    """
    u = np.asarray(u_m, dtype=float)
    p0 = np.asarray(p0_pa, dtype=float)
    a = contact_radius(p0, params)
    q0 = full_stick_q0(u, a, params)
    s = stick_boundary_s(q0, p0, params)
    area2 = 2.0 * np.pi * a**2
    stick = area2 * q0 * (1.0 - s)
    slip = area2 * (params.mu * p0 * s**3 / 3.0 + params.sigma0_pa * s**2 / 2.0)
    u_b, stick_b = np.broadcast_arrays(u, stick)
    return LateralResponse(
        displacement_m=np.array(u_b, dtype=float),
        lateral_force_n=stick + slip,
        stick_force_n=stick,
        slip_force_n=np.broadcast_to(slip, stick_b.shape).copy(),
        stick_radius_m=a * np.sqrt(1.0 - s**2),
        s=s,
        q0_pa=np.broadcast_to(q0, stick_b.shape).copy(),
    )


def saturated_force(p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """Gross-sliding force Q_sat = ∫σ dA = 2π a² (μ p0/3 + σ0/2) (N)."""
    p0 = np.asarray(p0_pa, dtype=float)
    a = contact_radius(p0, params)
    return 2.0 * np.pi * a**2 * (params.mu * p0 / 3.0 + params.sigma0_pa / 2.0)


def displacement_from_s(s: ArrayLike, p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """u(s) = π a (k p0 s² + τ0 s)/G* (m): the displacement at which the stick zone is c(s)."""
    s = np.asarray(s, dtype=float)
    p0 = np.asarray(p0_pa, dtype=float)
    a = contact_radius(p0, params)
    return np.pi * a * (params.k * p0 * s**2 + params.tau0_pa * s) / params.shear_modulus_pa


def full_slip_displacement(p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """u_fs = π a (k p0 + τ0)/G* (m), where q0 reaches τ at the centre and c = 0."""
    return displacement_from_s(1.0, p0_pa, params)


def force_coefficients(
    p0_pa: ArrayLike, params: ContactParameters
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """(A1, A2, A3) (Pa) in Q(s)/(2π a²) = A1 s + A2 s² + A3 s³ for s in [0, 1]."""
    p0 = np.asarray(p0_pa, dtype=float)
    kp0 = params.k * p0
    a1 = np.full_like(p0, params.tau0_pa)
    a2 = kp0 - params.tau0_pa + params.sigma0_pa / 2.0
    a3 = params.mu * p0 / 3.0 - kp0
    return a1, a2, a3


def _poly(s, a1, a2, a3):
    return ((a3 * s + a2) * s + a1) * s


def _dpoly(s, a1, a2, a3):
    return (3.0 * a3 * s + 2.0 * a2) * s + a1


def _quadratic_roots(qa, qb, qc):
    """Both roots of qa x² + qb x + qc = 0 (nan where complex), stable, vectorised."""
    qa, qb, qc = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (qa, qb, qc)))
    disc = qb**2 - 4.0 * qa * qc
    sq = np.sqrt(np.where(disc >= 0.0, disc, np.nan))
    q = -0.5 * (qb + np.copysign(sq, qb))
    scale = np.maximum(np.abs(qb), np.abs(qc)) + np.abs(qa)
    linear = np.abs(qa) <= 1e-14 * scale
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        r1 = np.where(linear, -qc / qb, q / qa)
        r2 = np.where(linear, np.nan, qc / q)
    return r1, r2


@dataclass(frozen=True)
class PeakForce:
    """The maximum of Q(u) over u (SI; arrays over p0).

    Attributes
    ----------
    force_n : Q_peak, the global maximum of Q(u) (N); gross sliding under load control
    displacement_m : u at the peak (m)
    s : √(1 − c²/a²) at the peak (1: the peak is the saturation, Q(u) monotone)
    stick_radius_m : c at the peak (m)
    saturated_force_n : Q_sat (N)
    full_slip_displacement_m : u_fs (m)
    overshoot : Q_peak > Q_sat (an interior peak, Q falls after it)
    first_local_max_s : s of the first local maximum of Q (== s unless Q has a
        local maximum lower than a later one; the rising branch then has a jump)
    """

    force_n: FloatArray
    displacement_m: FloatArray
    s: FloatArray
    stick_radius_m: FloatArray
    saturated_force_n: FloatArray
    full_slip_displacement_m: FloatArray
    overshoot: NDArray[np.bool_]
    first_local_max_s: FloatArray


def peak_force(p0_pa: ArrayLike, params: ContactParameters) -> PeakForce:
    """Peak of Q(u): the local maximum from dQ/ds = A1 + 2 A2 s + 3 A3 s² = 0 in (0, 1)
    compared with the saturated force at s = 1 (closed form, vectorised over p0)."""
    p0 = np.atleast_1d(np.asarray(p0_pa, dtype=float))
    a1, a2, a3 = force_coefficients(p0, params)
    r1, r2 = _quadratic_roots(3.0 * a3, 2.0 * a2, a1)
    cands = []
    for r in (r1, r2):
        is_max = (r > 0.0) & (r < 1.0) & (2.0 * a2 + 6.0 * a3 * r < 0.0)
        cands.append(np.where(is_max, r, np.inf))
    s_loc = np.minimum(cands[0], cands[1])  # a cubic has at most one local maximum
    has_loc = np.isfinite(s_loc)
    q_loc = np.where(has_loc, _poly(np.where(has_loc, s_loc, 1.0), a1, a2, a3), -np.inf)
    q_one = _poly(1.0, a1, a2, a3)
    interior = q_loc > q_one
    s_peak = np.where(interior, s_loc, 1.0)
    a = contact_radius(p0, params)
    area2 = 2.0 * np.pi * a**2
    shape = np.shape(np.asarray(p0_pa))
    out = {
        "force_n": area2 * np.where(interior, q_loc, q_one),
        "displacement_m": displacement_from_s(s_peak, p0, params),
        "s": s_peak,
        "stick_radius_m": a * np.sqrt(1.0 - s_peak**2),
        "saturated_force_n": area2 * q_one,
        "full_slip_displacement_m": full_slip_displacement(p0, params),
        "overshoot": interior,
        "first_local_max_s": np.where(has_loc, s_loc, 1.0),
    }
    return PeakForce(**{k: np.reshape(v, shape) for k, v in out.items()})


def _cubic_real_roots(c3, c2, c1, c0):
    """The three roots of c3 x³ + c2 x² + c1 x + c0 (complex Cardano, vectorised).

    Returns an array (..., 3) of complex roots; for |c3| negligible the cubic is
    solved as a quadratic (the third root is nan).
    """
    c3, c2, c1, c0 = np.broadcast_arrays(*(np.asarray(x, dtype=float) for x in (c3, c2, c1, c0)))
    scale = np.maximum.reduce([np.abs(c2), np.abs(c1), np.abs(c0)])
    cubic = np.abs(c3) > 1e-12 * scale
    a = np.where(cubic, c3, 1.0)
    b, c, d = c2 / a, c1 / a, c0 / a  # monic
    d0 = b * b - 3.0 * c
    d1 = 2.0 * b**3 - 9.0 * b * c + 27.0 * d
    sq = np.sqrt((d1 * d1 - 4.0 * d0**3).astype(complex))
    big = np.where(np.abs(d1 + sq) >= np.abs(d1 - sq), d1 + sq, d1 - sq)
    cc = (big / 2.0) ** (1.0 / 3.0)
    xi = np.exp(2j * np.pi / 3.0)
    roots = []
    for kk in range(3):
        ck = cc * xi**kk
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(np.abs(ck) > 0.0, -(b + ck + d0 / ck) / 3.0, -b / 3.0)
        roots.append(r)
    cub = np.stack(roots, axis=-1)
    # the root of smallest magnitude loses relative accuracy to cancellation; recover it
    # from Vieta (x1 x2 x3 = −d) and the two larger roots
    idx = np.argmin(np.abs(cub), axis=-1)[..., None]
    with np.errstate(divide="ignore", invalid="ignore"):
        others = np.prod(cub, axis=-1) / np.take_along_axis(cub, idx, axis=-1)[..., 0]
        small = np.where(
            np.abs(others) > 0.0, -d / others, np.take_along_axis(cub, idx, axis=-1)[..., 0]
        )
    np.put_along_axis(cub, idx, small[..., None], axis=-1)
    q1, q2 = _quadratic_roots(c2, c1, c0)
    quad = np.stack([q1, q2, np.full_like(q1, np.nan)], axis=-1).astype(complex)
    return np.where(cubic[..., None], cub, quad)


def s_on_rising_branch(
    lateral_force_n: ArrayLike, p0_pa: ArrayLike, params: ContactParameters
) -> FloatArray:
    """s(Q) on the load-controlled (rising) branch: the smallest s in [0, 1] with Q(s) = Q.

    Closed form (the cubic A3 s³ + A2 s² + A1 s = Q/(2π a²) solved by Cardano,
    polished by two Newton steps). Q is clipped to [0, Q_peak]: beyond the peak
    there is no quasi-static state under load control.
    """
    q = np.asarray(lateral_force_n, dtype=float)
    p0 = np.asarray(p0_pa, dtype=float)
    q, p0 = np.broadcast_arrays(q, p0)
    pk = peak_force(p0, params)
    a = contact_radius(p0, params)
    y = np.clip(q, 0.0, pk.force_n) / (2.0 * np.pi * a**2)
    a1, a2, a3 = force_coefficients(p0, params)
    roots = _cubic_real_roots(a3, a2, a1, -y)
    scale = np.abs(a1) + np.abs(a2) + np.abs(a3)
    tol = 1e-6
    re = roots.real
    ok = (
        (np.abs(roots.imag) <= tol * (1.0 + np.abs(re)))
        & (re >= -tol)
        & (re <= pk.s[..., None] + tol)
    )
    s = np.min(np.where(ok, re, np.inf), axis=-1)
    s = np.where(np.isfinite(s), s, pk.s)  # only at the double root of the peak
    s = np.clip(s, 0.0, pk.s)
    for _ in range(2):  # Newton polish in the cancellation-free form, kept inside [0, s_peak]
        dg = _dpoly(s, a1, a2, a3)
        good = dg > 1e-12 * scale
        newton = (y + (a2 + 2.0 * a3 * s) * s * s) / np.where(good, dg, 1.0)
        s = np.clip(np.where(good, newton, s), 0.0, pk.s)
    # safeguard: where the closed form is not accurate to ~1e-12 (near-degenerate cubic,
    # near the double root at the peak) finish by bisection on the bracket where Q(s)
    # rises through Q (unique there)
    bad = np.abs(_poly(s, a1, a2, a3) - y) > 1e-12 * np.maximum(y, 1e-300) + 1e-15 * scale * s
    bad &= y > 0.0
    if np.any(bad):
        s = np.where(bad, _bisect_rising(y, a1, a2, a3, pk), s)
    return np.where(y <= 0.0, 0.0, s)


def _bisect_rising(y, a1, a2, a3, pk: PeakForce, iterations: int = 64):
    """Smallest s with Q(s)/(2π a²) = y by vectorised bisection on a monotone bracket."""
    s1 = pk.first_local_max_s
    first = y <= _poly(s1, a1, a2, a3)
    lo = np.where(first, 0.0, s1)
    hi = np.where(first, s1, pk.s)
    lo, hi = np.broadcast_arrays(lo, hi)
    lo, hi = lo.copy(), hi.copy()
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        up = _poly(mid, a1, a2, a3) >= y
        hi = np.where(up, mid, hi)
        lo = np.where(up, lo, mid)
    return hi


def displacement_on_rising_branch(
    lateral_force_n: ArrayLike, p0_pa: ArrayLike, params: ContactParameters
) -> FloatArray:
    """u(Q) (m) on the rising branch under load control, 0 <= Q <= Q_peak (closed form)."""
    s = s_on_rising_branch(lateral_force_n, p0_pa, params)
    return displacement_from_s(s, p0_pa, params)


def initial_lateral_stiffness(p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """dQ/du at u -> 0 (N/m): 2 G* a when τ0 > 0 (= 8 G*_J a, Johnson), and
    2 G* a (k p0 + σ0/2)/(k p0) when τ0 = 0 (the slip annulus then carries σ0 from the start)."""
    p0 = np.asarray(p0_pa, dtype=float)
    a = contact_radius(p0, params)
    g = params.shear_modulus_pa
    if params.tau0_pa > 0.0:
        return 2.0 * g * a * np.ones_like(p0)
    kp0 = params.k * p0
    return 2.0 * g * a * (kp0 + params.sigma0_pa / 2.0) / kp0


# --------------------------------------------------------------------------------------
# classical Cattaneo–Mindlin


def cattaneo_mindlin_stick_radius(
    lateral_force_n: ArrayLike, friction_limit_n: ArrayLike, contact_radius_m: ArrayLike
) -> FloatArray:
    """c = a (1 − Q/μP)^(1/3) (m), Johnson (1985) Eq. 7.43; ``friction_limit_n`` = μP."""
    ratio = np.clip(
        np.asarray(lateral_force_n, dtype=float) / np.asarray(friction_limit_n), 0.0, 1.0
    )
    return np.asarray(contact_radius_m, dtype=float) * np.cbrt(1.0 - ratio)


def cattaneo_mindlin_displacement(
    lateral_force_n: ArrayLike,
    friction_limit_n: ArrayLike,
    contact_radius_m: ArrayLike,
    johnson_shear_modulus_pa: ArrayLike,
) -> FloatArray:
    """δ = 3μP/(16 G*_J a)·[1 − (1 − Q/μP)^(2/3)] (m), Johnson (1985) Eq. 7.47 (G*_J: Johnson's)."""
    mup = np.asarray(friction_limit_n, dtype=float)
    ratio = np.clip(np.asarray(lateral_force_n, dtype=float) / mup, 0.0, 1.0)
    pref = 3.0 * mup / (16.0 * np.asarray(johnson_shear_modulus_pa) * np.asarray(contact_radius_m))
    return pref * (1.0 - np.cbrt(1.0 - ratio) ** 2)


def cattaneo_mindlin_force(
    displacement_m: ArrayLike,
    friction_limit_n: ArrayLike,
    contact_radius_m: ArrayLike,
    johnson_shear_modulus_pa: ArrayLike,
) -> FloatArray:
    """Q(δ) = μP [1 − (1 − δ/δ*)^(3/2)] for δ <= δ* = 3μP/(16 G*_J a), μP beyond (N)."""
    mup = np.asarray(friction_limit_n, dtype=float)
    dstar = 3.0 * mup / (16.0 * np.asarray(johnson_shear_modulus_pa) * np.asarray(contact_radius_m))
    x = np.clip(np.asarray(displacement_m, dtype=float) / dstar, 0.0, 1.0)
    return mup * (1.0 - (1.0 - x) ** 1.5)


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
