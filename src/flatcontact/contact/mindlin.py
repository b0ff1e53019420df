"""The paper's modified Mindlin model: tractions, stick zone, Q(u), its peak and inverse, in SI.

Modified Mindlin model (Dong et al., section "Modified Mindlin model")
---------------------------------------------------------------------
A Hertz contact (radius a, peak pressure p0, p(r) = p0·s(r) with
s(r) = √(1 − r²/a²)) is displaced laterally by u.

- local shear strength      τ(r) = k·p(r) + τ0
- slip-zone friction        σ(r) = μ·p(r) + σ0
- full-stick traction       q(r) = q0 / s(r),  q0 = G*·u/(π a)   (the paper's G* = 4 G*_J,
                            :mod:`flatcontact.contact.moduli`)
- stick zone                q(r) < τ(r) (the paper's "local slip where the applied stress
                            exceeds the local shear strength"); with s = √(1 − r²/a²) this
                            is g(s) = k·p0·s² + τ0·s > q0
- stick radius c            q(c) = τ(c): the smaller root s = 2 q0 / (τ0 + √(τ0² + 4 k p0 q0))
                            of g(s) = q0 (cancellation-free, any sign of k, k = 0 too)
- stick force               Q_stick = 2π ∫0^c q r dr = 2π a² q0 (1 − s)
- slip force                Q_slip = 2π ∫c^a σ r dr = 2π a² (μ p0 s³/3 + σ0 s²/2)
- total                     Q(u) = Q_stick + Q_slip; saturated (gross sliding) force
                            Q_sat = ∫σ dA = 2π a² (μ p0/3 + σ0/2), at full slip.

Eliminating q0 = k p0 s² + τ0 s gives Q(s)/(2π a²) = A1 s + A2 s² + A3 s³ with
A1 = τ0, A2 = k p0 − τ0 + σ0/2, A3 = μ p0/3 − k p0 and u(s) = π a (k p0 s² + τ0 s)/G*,
so the peak (dQ/ds = 0, a quadratic) and the inverse u(Q) (a cubic) are closed forms.
The initial stiffness is dQ/du|0 = 2 G* a (τ0 > 0).

Negative slopes (k < 0 or μ < 0)
--------------------------------
The model needs τ > 0 and σ >= 0 on the whole contact: τ0 > 0 and k p0 + τ0 > 0,
σ0 >= 0 and μ p0 + σ0 >= 0 (:meth:`ContactParameters.check_p0_gpa` refuses other p0).
For k < 0, g(s) is concave with its maximum at t* = τ0/(2|k| p0).

- p0 <= τ0/(2|k|) (t* >= 1): g increases on [0, 1], the stick zone is the central
  disc at every u, everything above holds unchanged; full slip at s = 1,
  u_fs = π a (k p0 + τ0)/G*.
- τ0/(2|k|) < p0 < τ0/|k| (t* < 1): once q0 exceeds τ(centre) = k p0 + τ0 the centre
  slips (with k < 0 the strength is lowest where the pressure is highest) while the
  annulus s < s(r) < t2 = 2t* − s still sticks. With t2 = min(1, 2t* − s),

      Q/(2π a²) = q0 (t2 − s) + μ p0 (1 − t2³ + s³)/3 + σ0 (1 − t2² + s²)/2,

  which in h = t* − s is the cubic B0 + B1 h + B3 h³ (B0 = Q_sat/(2π a²),
  B1 = 2 t* [τ(t*) − σ(t*)], B3 = 2 k p0 − 2 μ p0/3). The ring shrinks onto s = t*
  and vanishes at q0 = τ0²/(4|k| p0): full slip at s = t*, u_fs = π a τ0 t*/(2 G*).
  Q(u) is continuous with a kink at the centre's slip (slope change
  2π a² (σ − τ)(centre)/(du/ds)) and approaches Q_sat as √(u_fs − u).

So s (outer stick boundary) runs over [0, s_fs], s_fs = min(1, t*); u(s) increases
on it for either sign of k, and Q(s) is a cubic on [0, s_c], s_c = min(1, 2t* − 1),
and another on (s_c, s_fs]. The peak and the rising-branch inverse work piece by piece
(:mod:`flatcontact.contact.piecewise_cubic`).

Inside the stick zone the paper keeps the full-stick traction q0/s (no Cattaneo
corrective traction); in the classical limit (k = μ, τ0 = σ0 = 0) it therefore agrees
with Cattaneo–Mindlin (:mod:`flatcontact.contact.cattaneo_mindlin`) only in the initial
stiffness and at full slip (:mod:`flatcontact.contact.classical_limit`, docs/contact.md).
Unloading, reloading and the steady cycle of the modified model:
:mod:`flatcontact.contact.cycle`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from flatcontact.contact import piecewise_cubic as pc
from flatcontact.contact.hertz import hertz_contact_radius
from flatcontact.contact.parameters import ContactParameters

FloatArray = NDArray[np.float64]

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


# --------------------------------------------------------------------------------------
# the stick zone


def vertex_s(p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """t* = τ0/(2|k| p0): where g(s) = k p0 s² + τ0 s is largest when k < 0; inf for k >= 0."""
    p0 = np.asarray(p0_pa, dtype=float)
    if params.k >= 0.0:
        return np.full(p0.shape, np.inf)
    with np.errstate(divide="ignore", over="ignore"):  # k -> 0−: t* -> inf
        return params.tau0_pa / (-2.0 * params.k * p0)


def _annulus_vertex_s(p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """t* where t* < 1 (an annulus can stick: k < 0, p0 > τ0/(2|k|)), inf elsewhere; every
    use below depends on t* only through min(1, ·), so this avoids overflow for k -> 0−."""
    ts = vertex_s(p0_pa, params)
    return np.where(ts < 1.0, ts, np.inf)


def full_slip_s(p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """s_fs = min(1, t*): s of the outer stick boundary when the stick zone vanishes.

    1 (the stick disc shrinks to the centre) unless k < 0 and p0 > τ0/(2|k|); then the
    stick zone ends as a ring at s = t* (radius a√(1 − t*²)).
    """
    return np.minimum(1.0, _annulus_vertex_s(p0_pa, params))


def centre_slip_s(p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """s_c = min(1, 2t* − 1): s of the outer stick boundary when the centre starts to slip
    (q0 = τ(centre) = k p0 + τ0); s_c = s_fs = 1 unless k < 0 and p0 > τ0/(2|k|)."""
    return np.minimum(1.0, 2.0 * _annulus_vertex_s(p0_pa, params) - 1.0)


def stick_boundary_s(q0_pa: ArrayLike, p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """s = √(1 − c²/a²) of the outer stick boundary: the smaller root of k p0 s² + τ0 s = q0.

    Uses the cancellation-free form s = 2 q0 / (τ0 + √(τ0² + 4 k p0 q0)), valid for
    either sign of k and for k = 0. s = 0 at q0 = 0 (full stick); s = s_fs
    (:func:`full_slip_s`) once no point sticks: s >= 1, or, for k < 0, q0 above
    the maximum τ0²/(4|k| p0) of k p0 s² + τ0 s (negative discriminant).
    """
    q0 = np.asarray(q0_pa, dtype=float)
    p0 = np.asarray(p0_pa, dtype=float)
    tau0 = params.tau0_pa
    disc = tau0**2 + 4.0 * params.k * p0 * q0
    s_fs = full_slip_s(p0, params)
    den = tau0 + np.sqrt(np.maximum(disc, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(q0 > 0.0, 2.0 * q0 / den, 0.0)
    s = np.where((disc < 0.0) | np.isnan(s), s_fs, s)
    return np.clip(s, 0.0, s_fs)


def stick_inner_s(s: ArrayLike, p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """s of the inner stick boundary, min(1, 2t* − s): 1 (no inner boundary, a stick disc)
    unless the centre slips (k < 0, s > s_c); the stick zone is s < s(r) < stick_inner_s."""
    return np.minimum(1.0, 2.0 * _annulus_vertex_s(p0_pa, params) - np.asarray(s, dtype=float))


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
    stick_radius_m : outer radius c of the stick zone (m); 0 at full slip
    stick_inner_radius_m : inner radius of the stick zone (m): 0 for a stick disc; > 0
        when the centre slips and an annulus sticks (k < 0, p0 > τ0/(2|k|)); 0 at full slip
    s : √(1 − c²/a²) of the outer stick boundary, in [0, s_fs] (:func:`full_slip_s`)
    q0_pa : full-stick centre traction G*·u/(π a) (Pa)
    """

    displacement_m: FloatArray
    lateral_force_n: FloatArray
    stick_force_n: FloatArray
    slip_force_n: FloatArray
    stick_radius_m: FloatArray
    stick_inner_radius_m: FloatArray
    s: FloatArray
    q0_pa: FloatArray


def contact_radius(p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """Hertz radius a (m) at peak pressure p0 (Pa) for the tip and E* of ``params``."""
    return hertz_contact_radius(p0_pa, params.radius_m, params.contact_modulus_pa)


def lateral_force(u_m: ArrayLike, p0_pa: ArrayLike, params: ContactParameters) -> LateralResponse:
    """Total lateral force Q(u) of the modified Mindlin model (closed form).

    The stick zone is where q(r) < τ(r), i.e. s(r) in (s, t2) with s, t2 the roots of
    k p0 s² + τ0 s = q0 (t2 clipped to 1): a disc r < c, or, once the centre slips
    (k < 0, q0 > k p0 + τ0), an annulus. It carries q0/s(r), the slip zone σ(r):

        Q/(2π a²) = q0 (t2 − s) + μ p0 (1 − t2³ + s³)/3 + σ0 (1 − t2² + s²)/2,

    the paper's Q = 2π a² [q0 (1 − s) + μ p0 s³/3 + σ0 s²/2] for a stick disc (t2 = 1).

    Parameters
    ----------
    u_m : array_like
        Lateral displacement u >= 0 (m).
    p0_pa : array_like
        Peak Hertz pressure (Pa); broadcasts against ``u_m`` (e.g. ``p0[:, None]``).
    params : ContactParameters

    Raises
    ------
    InputError
        If τ <= 0 or σ < 0 somewhere in the contact at some p0 (k or μ < 0).
    """
    u = np.asarray(u_m, dtype=float)
    p0 = np.asarray(p0_pa, dtype=float)
    params.check_p0_pa(p0)
    a = contact_radius(p0, params)
    q0 = full_stick_q0(u, a, params)
    s = stick_boundary_s(q0, p0, params)
    t2 = stick_inner_s(s, p0, params)
    area2 = 2.0 * np.pi * a**2
    stick = area2 * q0 * (t2 - s)
    slip = area2 * (
        params.mu * p0 * ((1.0 - t2**3) + s**3) / 3.0
        + params.sigma0_pa * ((1.0 - t2**2) + s**2) / 2.0
    )
    sticks = t2 > s
    u_b, stick_b = np.broadcast_arrays(u, stick)
    return LateralResponse(
        displacement_m=np.array(u_b, dtype=float),
        lateral_force_n=stick + slip,
        stick_force_n=stick,
        slip_force_n=np.broadcast_to(slip, stick_b.shape).copy(),
        stick_radius_m=np.where(sticks, a * np.sqrt(1.0 - s**2), 0.0),
        stick_inner_radius_m=np.where(sticks, a * np.sqrt(1.0 - t2**2), 0.0),
        s=s,
        q0_pa=np.broadcast_to(q0, stick_b.shape).copy(),
    )


def saturated_force(p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """Gross-sliding force Q_sat = ∫σ dA = 2π a² (μ p0/3 + σ0/2) (N), any sign of μ."""
    p0 = np.asarray(p0_pa, dtype=float)
    a = contact_radius(p0, params)
    return 2.0 * np.pi * a**2 * (params.mu * p0 / 3.0 + params.sigma0_pa / 2.0)


def displacement_from_s(s: ArrayLike, p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """u(s) = π a (k p0 s² + τ0 s)/G* (m): the displacement at which the outer stick
    boundary is at s (increasing in s on [0, s_fs], for either sign of k)."""
    s = np.asarray(s, dtype=float)
    p0 = np.asarray(p0_pa, dtype=float)
    a = contact_radius(p0, params)
    return np.pi * a * (params.k * p0 * s**2 + params.tau0_pa * s) / params.shear_modulus_pa


def displacement_slope_s(s: ArrayLike, p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """du/ds = π a (2 k p0 s + τ0)/G* (m); >= 0 on [0, s_fs], 0 at s_fs = t* < 1."""
    s = np.asarray(s, dtype=float)
    p0 = np.asarray(p0_pa, dtype=float)
    a = contact_radius(p0, params)
    return np.pi * a * (2.0 * params.k * p0 * s + params.tau0_pa) / params.shear_modulus_pa


def full_slip_displacement(p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """u_fs = u(s_fs) (m), where the stick zone vanishes: π a (k p0 + τ0)/G* (q0 = τ(centre))
    for a stick disc, π a τ0²/(4|k| p0 G*) (q0 = max of k p0 s² + τ0 s) for a stick ring."""
    return displacement_from_s(full_slip_s(p0_pa, params), p0_pa, params)


def force_coefficients(
    p0_pa: ArrayLike, params: ContactParameters
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """(A1, A2, A3) (Pa) in Q(s)/(2π a²) = A1 s + A2 s² + A3 s³ while the stick zone is a
    disc, s in [0, s_c] (:func:`centre_slip_s`); any sign of k, μ."""
    p0 = np.asarray(p0_pa, dtype=float)
    kp0 = params.k * p0
    a1 = np.full_like(p0, params.tau0_pa)
    a2 = kp0 - params.tau0_pa + params.sigma0_pa / 2.0
    a3 = params.mu * p0 / 3.0 - kp0
    return a1, a2, a3


def annulus_force_coefficients(
    p0_pa: ArrayLike, params: ContactParameters
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """(B0, B1, B3) (Pa) in Q/(2π a²) = B0 + B1 h + B3 h³, h = t* − s, while an annulus
    sticks (k < 0, s in (s_c, t*]): the stick ring is t* − h < s(r) < t* + h.

    B0 = μ p0/3 + σ0/2 (saturation), B1 = 2 t* [τ(t*) − σ(t*)] with τ(t*) = τ0/2,
    B3 = 2 k p0 − 2 μ p0/3. B1, B3 are nan where no annulus sticks (t* >= 1).
    """
    p0 = np.asarray(p0_pa, dtype=float)
    ts = _annulus_vertex_s(p0, params)
    ts = np.where(np.isfinite(ts), ts, np.nan)
    b0 = params.mu * p0 / 3.0 + params.sigma0_pa / 2.0
    b1 = 2.0 * ts * (params.tau0_pa / 2.0 - (params.mu * p0 * ts + params.sigma0_pa))
    b3 = 2.0 * params.k * p0 - 2.0 * params.mu * p0 / 3.0 + 0.0 * ts
    return b0, b1, b3


def _branch(p0: FloatArray, params: ContactParameters) -> pc.Branch:
    """Q(s)/(2π a²) at each p0 as the piecewise cubic of :mod:`.piecewise_cubic`."""
    a = contact_radius(p0, params)
    ts = _annulus_vertex_s(p0, params)
    return pc.Branch(
        a=a,
        area2=2.0 * np.pi * a**2,
        tstar=np.where(np.isfinite(ts), ts, 0.0),
        s_c=centre_slip_s(p0, params),
        s_fs=full_slip_s(p0, params),
        A=force_coefficients(p0, params),
        B=annulus_force_coefficients(p0, params),
    )


def force_at_s(s: ArrayLike, p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """Q (N) when the outer stick boundary is at s in [0, s_fs] (u = :func:`displacement_from_s`)."""
    p0 = np.asarray(p0_pa, dtype=float)
    br = _branch(p0, params)
    return br.area2 * br.y(np.asarray(s, dtype=float))


def force_slope_s(s: ArrayLike, p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """dQ/ds (N) at s in [0, s_fs]; at the kink s = s_c (the centre starts to slip), the
    slope on the disc side. dQ/du = (dQ/ds)/(du/ds) (:func:`displacement_slope_s`)."""
    p0 = np.asarray(p0_pa, dtype=float)
    br = _branch(p0, params)
    return br.area2 * br.dy_ds(np.asarray(s, dtype=float))


# --------------------------------------------------------------------------------------
# the peak and the rising-branch inverse (numerics: :mod:`.piecewise_cubic`)


@dataclass(frozen=True)
class PeakForce:
    """The maximum of Q(u) over u (SI; arrays over p0).

    Attributes
    ----------
    force_n : Q_peak, the global maximum of Q(u) (N); gross sliding under load control
    displacement_m : u at the peak (m)
    s : s of the outer stick boundary at the peak (s_fs: the peak is the saturation)
    stick_radius_m : outer stick radius c at the peak (m)
    stick_inner_radius_m : inner stick radius at the peak (m); > 0 if an annulus sticks
    saturated_force_n : Q_sat (N)
    full_slip_displacement_m : u_fs (m)
    overshoot : Q_peak > Q_sat (an interior peak, Q falls after it)
    first_local_max_s : s of the first local maximum of Q(s), a kink included (== s
        unless Q has a local maximum lower than a later one: the load-controlled rising
        branch then jumps from it to a larger u)
    """

    force_n: FloatArray
    displacement_m: FloatArray
    s: FloatArray
    stick_radius_m: FloatArray
    stick_inner_radius_m: FloatArray
    saturated_force_n: FloatArray
    full_slip_displacement_m: FloatArray
    overshoot: NDArray[np.bool_]
    first_local_max_s: FloatArray


def peak_force(p0_pa: ArrayLike, params: ContactParameters) -> PeakForce:
    """Peak of Q(u) (closed form, vectorised over p0).

    Q(s) is a cubic on [0, s_c] (stick disc; dQ/ds = A1 + 2 A2 s + 3 A3 s² = 0 is a
    quadratic) and, for k < 0 and p0 > τ0/(2|k|), another cubic in h = t* − s on
    (s_c, t*] (stick annulus; dQ/dh = B1 + 3 B3 h² = 0); the peak is the largest of Q
    at those critical points, at the kink s_c and at full slip (Q_sat).
    """
    p0 = np.atleast_1d(np.asarray(p0_pa, dtype=float))
    params.check_p0_pa(p0)
    br = _branch(p0, params)
    b, yb = pc.breakpoints(br)
    s_peak, y_peak, overshoot, first = pc.peak(br, b, yb)
    t2 = stick_inner_s(s_peak, p0, params)
    sticks = t2 > s_peak
    a = br.a
    shape = np.shape(np.asarray(p0_pa))
    out = {
        "force_n": br.area2 * y_peak,
        "displacement_m": displacement_from_s(s_peak, p0, params),
        "s": s_peak,
        "stick_radius_m": np.where(sticks, a * np.sqrt(1.0 - s_peak**2), 0.0),
        "stick_inner_radius_m": np.where(sticks, a * np.sqrt(1.0 - t2**2), 0.0),
        "saturated_force_n": br.area2 * yb[..., -1],
        "full_slip_displacement_m": full_slip_displacement(p0, params),
        "overshoot": overshoot,
        "first_local_max_s": first,
    }
    return PeakForce(**{k: np.reshape(v, shape) for k, v in out.items()})


def s_on_rising_branch(
    lateral_force_n: ArrayLike, p0_pa: ArrayLike, params: ContactParameters
) -> FloatArray:
    """s(Q) on the load-controlled (rising) branch: the smallest s in [0, s_fs] with Q(s) = Q.

    Q(s) is split into monotone cubic pieces (:func:`peak_force`); the first piece that
    reaches Q holds the root, found in closed form (Cardano, polished by two Newton
    steps; bisection where that is not accurate to ~1e-12). Q is clipped to [0, Q_peak]:
    beyond the peak there is no quasi-static state under load control.
    """
    q = np.asarray(lateral_force_n, dtype=float)
    p0 = np.asarray(p0_pa, dtype=float)
    params.check_p0_pa(p0)
    br = _branch(p0, params)
    b, yb = pc.breakpoints(br)
    _, y_peak, _, _ = pc.peak(br, b, yb)
    y = np.clip(q / br.area2, 0.0, y_peak)
    return pc.first_crossing(y, b, yb, br)


def displacement_on_rising_branch(
    lateral_force_n: ArrayLike, p0_pa: ArrayLike, params: ContactParameters
) -> FloatArray:
    """u(Q) (m) on the rising branch under load control, 0 <= Q <= Q_peak (closed form)."""
    s = s_on_rising_branch(lateral_force_n, p0_pa, params)
    return displacement_from_s(s, p0_pa, params)


@dataclass(frozen=True)
class RisingBranchBreaks:
    """Forces below Q_peak where the rising branch u(Q) is not smooth (SI; (..., 4) over p0).

    A break is a record value of Q(s) at a piece boundary: the kink where the centre
    starts to slip (u(Q) continuous, u'(Q) jumps) or a local maximum lower than the peak
    (u jumps from ``displacement_below_m`` to ``displacement_above_m``). Sorted by force;
    unused entries have force inf.
    """

    force_n: FloatArray
    displacement_below_m: FloatArray
    displacement_above_m: FloatArray


def rising_branch_breaks(p0_pa: ArrayLike, params: ContactParameters) -> RisingBranchBreaks:
    """The forces where u(Q) on the rising branch has a kink or a jump, below Q_peak."""
    p0 = np.asarray(p0_pa, dtype=float)
    params.check_p0_pa(p0)
    br = _branch(p0, params)
    b, yb = pc.breakpoints(br)
    s_peak, _, _, _ = pc.peak(br, b, yb)
    inner, y_in = b[..., 1:-1], yb[..., 1:-1]
    earlier = np.maximum.accumulate(yb, axis=-1)[..., :-2]
    record = (y_in > earlier) & (inner < s_peak[..., None])
    jump = record & (yb[..., 2:] < y_in)
    # where u jumps: the first crossing of the same force beyond the local maximum
    later = yb[..., None, :] > y_in[..., None]  # (..., 4, 6)
    later &= np.arange(6) > np.arange(1, 5)[:, None]
    i = np.argmax(later, axis=-1)
    i = np.where(np.any(later, axis=-1), i, 5)[..., None]
    brx = br.expanded()
    bb = np.broadcast_to(b[..., None, :], (*i.shape[:-1], 6))
    lo = np.take_along_axis(bb, np.maximum(i - 1, 0), axis=-1)[..., 0]
    hi = np.take_along_axis(bb, i, axis=-1)[..., 0]
    s_above = np.where(jump, pc.solve_on_piece(np.where(jump, y_in, 0.0), lo, hi, brx), inner)
    pe = p0[..., None]
    force = np.where(record, brx.area2 * y_in, np.inf)
    below = displacement_from_s(inner, pe, params)
    above = displacement_from_s(s_above, pe, params)
    order = np.argsort(force, axis=-1, kind="stable")
    return RisingBranchBreaks(
        force_n=np.take_along_axis(force, order, axis=-1),
        displacement_below_m=np.take_along_axis(np.broadcast_to(below, force.shape), order, -1),
        displacement_above_m=np.take_along_axis(np.broadcast_to(above, force.shape), order, -1),
    )


# --------------------------------------------------------------------------------------
# stiffness


def initial_lateral_stiffness(p0_pa: ArrayLike, params: ContactParameters) -> FloatArray:
    """dQ/du at u -> 0 (N/m): 2 G* a when τ0 > 0 (= 8 G*_J a, Johnson; any sign of k, μ), and
    2 G* a (k p0 + σ0/2)/(k p0) when τ0 = 0 (then k > 0; the slip annulus carries σ0 from
    the start)."""
    p0 = np.asarray(p0_pa, dtype=float)
    a = contact_radius(p0, params)
    g = params.shear_modulus_pa
    if params.tau0_pa > 0.0:
        return 2.0 * g * a * np.ones_like(p0)
    kp0 = params.k * p0  # > 0: ContactParameters refuses τ0 = 0 with k <= 0
    return 2.0 * g * a * (kp0 + params.sigma0_pa / 2.0) / kp0
