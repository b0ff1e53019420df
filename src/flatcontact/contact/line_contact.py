"""Line contact (a cylinder on a flat, 2D Hertz) with pointwise shear laws, in SI units.

Plain-number functions like :mod:`flatcontact.contact.hertz`; loads are per unit length
of the cylinder (N/m, written P', Q').

Hertz (Johnson, *Contact Mechanics* (1985), §4.3, plane strain)
---------------------------------------------------------------
- half-width          a² = 4 P' R / (π E*)
- pressure            p(x) = p0 √(1 − x²/a²),  |x| <= a
- load                P' = π a p0 / 2

Cattaneo's line contact (Johnson §7.2), Coulomb friction μ, 0 <= Q' <= μP'
---------------------------------------------------------------------------
stick zone |x| < c with c/a = √(1 − Q'/(μP')); traction
q = μ p0 [√(1 − x²/a²) − (c/a) √(1 − x²/c²)] inside it and μ p(x) outside.

Two modified models with the laws τ(p) = k p + τ0 and σ(p) = μ p + σ0
----------------------------------------------------------------------
Both take any pressure profile p(x) (Hertz, or the one measured in atoms) and apply the
laws point by point; they differ in the stick zone.

1. **elastic stick zone** (:func:`elastic_response`, the generalisation of Cattaneo): the
   slip zone c < |x| < a carries σ(p(x)); the stick zone is rigid (no tangential surface
   strain), so with q = σ(p) − q* the corrective traction q* on |x| < c solves
   (1/π) PV∫_{−c}^{c} q*(s)/(x − s) ds = h(x) = (1/π) PV∫_{−a}^{a} σ(s)/(x − s) ds, bounded
   at ±c (Muskhelishvili; with t = x/c, q* = √(1 − t²) Σ b_n U_n(t) and b_n the T_{n+1}
   Chebyshev coefficient of h(ct)). Then Q' = ∫σ dx − π c b_0 / 2. The traction is
   continuous at ±c (q*(±c) = 0), so τ never sets the stick boundary: the stick zone stays
   rigid while q <= τ inside (:attr:`LineResponse.stick_margin`), and Q' rises monotonically
   to the gross-sliding force Q'_sat = ∫σ dx. With σ = μ p, τ = μ p and Hertz p this *is*
   Cattaneo's solution (b_0 = μ p0 c/a, q* = μ p0 (c/a) √(1 − x²/c²)).
2. **pointwise** (:func:`pointwise_response`, the paper's construction of
   :mod:`flatcontact.contact.mindlin` transposed to the line): the full-stick traction of a
   rigid strip q_fs(x) = Q'_fs / (π √(a² − x²)) (Johnson Eq. 7.30, 2D), stick where
   q_fs < τ(p(x)), σ(p(x)) elsewhere; Q'(Q'_fs) = ∫ q dx has a peak above Q'_sat when τ > σ
   (the paper's stiffness collapse). Its classical limit is *not* Cattaneo's (the stick
   traction keeps the full-stick shape): it agrees at the start (full stick) and at full slip.

The 2D tangential compliance of a half-plane depends on a reference depth (a log), so the
displacement u is not given here: the comparison with atoms matches the initial stiffness
once (u = Q'_fs / K0 for the pointwise model; :func:`elastic_slip_displacement` adds the slip
part, which has zero net force and is well defined, for the elastic model).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq

from flatcontact.foundation.errors import require

FloatArray = NDArray[np.float64]

#: Chebyshev terms of the stick-zone corrective traction (h is smooth inside |x| < c < a)
_CHEBYSHEV_TERMS = 64


# --------------------------------------------------------------------------------------
# Hertz and Cattaneo


def line_half_width(load_n_per_m: ArrayLike, radius_m: float, contact_modulus_pa: float):
    """Hertz half-width a = √(4 P' R / (π E*)) (m) of a cylinder at load P' (N/m)."""
    p = np.asarray(load_n_per_m, dtype=float)
    return np.sqrt(4.0 * p * radius_m / (np.pi * contact_modulus_pa))


def line_peak_pressure(load_n_per_m: ArrayLike, half_width_m: ArrayLike) -> FloatArray:
    """Hertz peak pressure p0 = 2 P' / (π a) (Pa)."""
    return 2.0 * np.asarray(load_n_per_m, dtype=float) / (np.pi * np.asarray(half_width_m))


def line_pressure(x_m: ArrayLike, half_width_m: float, p0_pa: float) -> FloatArray:
    """Hertz pressure p0 √(1 − x²/a²) inside |x| < a, 0 outside (Pa)."""
    s2 = 1.0 - (np.asarray(x_m, dtype=float) / half_width_m) ** 2
    return p0_pa * np.sqrt(np.clip(s2, 0.0, None))


def cattaneo_stick_ratio(lateral_n_per_m: ArrayLike, friction_limit_n_per_m: float) -> FloatArray:
    """c/a = √(1 − Q'/(μP')) of Cattaneo's line contact (0 at and beyond Q' = μP')."""
    ratio = np.asarray(lateral_n_per_m, dtype=float) / friction_limit_n_per_m
    return np.sqrt(np.clip(1.0 - ratio, 0.0, 1.0))


def cattaneo_traction(
    x_m: ArrayLike, half_width_m: float, p0_pa: float, mu: float, stick_half_width_m: float
) -> FloatArray:
    """Cattaneo's shear traction μ p0 [√(1 − x²/a²) − (c/a) √(1 − x²/c²)] (Pa), Johnson §7.2."""
    x = np.asarray(x_m, dtype=float)
    c = stick_half_width_m
    outer = mu * line_pressure(x, half_width_m, p0_pa)
    if c <= 0.0:
        return outer
    inner = mu * p0_pa * (c / half_width_m) * np.sqrt(np.clip(1.0 - (x / c) ** 2, 0.0, None))
    return outer - inner


# --------------------------------------------------------------------------------------
# the laws and a pressure profile


@dataclass(frozen=True)
class PointLaws:
    """τ(p) = k p + τ0 (stick limit) and σ(p) = μ p + σ0 (slip zone), SI (k, μ dimensionless).

    Both are clipped at 0 where a tensile (negative) pressure would make them negative.
    """

    k: float
    tau0_pa: float
    mu: float
    sigma0_pa: float

    def tau_pa(self, p_pa: ArrayLike) -> FloatArray:
        """τ(p) (Pa), >= 0."""
        return np.maximum(self.k * np.asarray(p_pa, dtype=float) + self.tau0_pa, 0.0)

    def sigma_pa(self, p_pa: ArrayLike) -> FloatArray:
        """σ(p) (Pa), >= 0."""
        return np.maximum(self.mu * np.asarray(p_pa, dtype=float) + self.sigma0_pa, 0.0)

    @classmethod
    def coulomb(cls, mu: float) -> PointLaws:
        """The classical limit: τ = σ = μ p."""
        return cls(k=mu, tau0_pa=0.0, mu=mu, sigma0_pa=0.0)


@dataclass(frozen=True)
class Profile:
    """A symmetric pressure profile on 0 <= x <= a (nodes, piecewise linear), mirrored to |x|.

    Build it with :func:`hertz_profile` or :func:`measured_profile`.
    """

    x_m: FloatArray
    p_pa: FloatArray
    half_width_m: float

    def nodes(self) -> tuple[FloatArray, FloatArray]:
        """(x, p) on −a..a (the mirror image joined at 0)."""
        x = np.concatenate([-self.x_m[:0:-1], self.x_m])
        p = np.concatenate([self.p_pa[:0:-1], self.p_pa])
        return x, p

    def load_n_per_m(self) -> float:
        """P' = ∫ p dx (N/m), trapezoid over the nodes."""
        x, p = self.nodes()
        return float(np.trapezoid(p, x))


def hertz_profile(half_width_m: float, p0_pa: float, nodes: int = 2001) -> Profile:
    """The Hertz profile on ``nodes`` points, denser towards the edge (x = a sin θ)."""
    require(
        half_width_m > 0 and np.isfinite(half_width_m),
        f"half_width_m must be > 0, got {half_width_m!r}",
    )
    require(p0_pa > 0 and np.isfinite(p0_pa), f"p0_pa must be > 0, got {p0_pa!r}")
    x = half_width_m * np.sin(np.linspace(0.0, np.pi / 2, nodes))
    return Profile(x, line_pressure(x, half_width_m, p0_pa), float(half_width_m))


def measured_profile(x_m: ArrayLike, p_pa: ArrayLike, half_width_m: float) -> Profile:
    """A measured pressure p(x) (bin centres, any sign of x) as a symmetric profile on |x| <= a.

    The profile is symmetrised ((p(x) + p(−x))/2, by interpolation on |x|) and ends at
    p(a) = 0; a is the measured contact half-width (atoms in force contact).

    Raises
    ------
    InputError
        Unless x and p are finite arrays of the same length with at least 3 points inside
        |x| < a, and a > 0.
    """
    x = np.asarray(x_m, dtype=float)
    p = np.asarray(p_pa, dtype=float)
    require(
        x.ndim == 1 and x.shape == p.shape,
        f"x_m and p_pa must be 1D of one length, got {x.shape}, {p.shape}",
    )
    require(bool(np.all(np.isfinite(x)) and np.all(np.isfinite(p))), "x_m and p_pa must be finite")
    require(
        half_width_m > 0 and np.isfinite(half_width_m),
        f"half_width_m must be > 0, got {half_width_m!r}",
    )
    inside = np.abs(x) < half_width_m
    require(int(inside.sum()) >= 3, f"give at least 3 profile points inside |x| < {half_width_m!r}")
    order = np.argsort(np.abs(x))
    r, pr = np.abs(x)[order], p[order]
    grid = np.linspace(0.0, half_width_m, 401)
    right = np.interp(grid, x[np.argsort(x)], p[np.argsort(x)])
    left = np.interp(-grid, x[np.argsort(x)], p[np.argsort(x)])
    sym = 0.5 * (right + left) if np.any(x < 0) else np.interp(grid, r, pr)
    sym[-1] = 0.0
    return Profile(grid, sym, float(half_width_m))


# --------------------------------------------------------------------------------------
# the elastic stick zone (generalised Cattaneo)


def _hilbert_piecewise_linear(nodes_x: FloatArray, f: FloatArray, x: FloatArray) -> FloatArray:
    """(1/π) PV∫ f(s)/(x − s) ds of the piecewise-linear f on the nodes, at points x off the nodes.

    Per segment, with f(s) = f_lin(x) − m (x − s) the linear extension:
    ∫ f/(x − s) ds = f_lin(x) ln|(x − s_i)/(x − s_{i+1})| − m (s_{i+1} − s_i).
    """
    s0, s1 = nodes_x[:-1], nodes_x[1:]
    f0, f1 = f[:-1], f[1:]
    m = (f1 - f0) / (s1 - s0)
    xx = x[:, None]
    flin = f0 + m * (xx - s0)
    with np.errstate(divide="ignore", invalid="ignore"):
        logs = np.log(np.abs(xx - s0)) - np.log(np.abs(xx - s1))
    return np.sum(flin * logs - m * (s1 - s0), axis=1) / np.pi


@dataclass(frozen=True)
class _Corrective:
    """The bounded corrective traction q* = √(1 − t²) Σ b_n U_n(t), t = x/c."""

    c_m: float
    b: FloatArray

    def traction_pa(self, x_m: ArrayLike) -> FloatArray:
        x = np.asarray(x_m, dtype=float)
        if self.c_m <= 0.0:
            return np.zeros_like(x)
        t = x / self.c_m
        inside = np.abs(t) < 1.0
        tt = np.where(inside, t, 0.0)
        # U_n(cos θ) = sin((n+1)θ)/sin θ, so √(1 − t²) U_n(t) = sin((n+1)θ)
        theta = np.arccos(tt)
        n = np.arange(1, self.b.size + 1)
        val = np.sin(np.outer(theta, n)) @ self.b
        return np.where(inside, val.reshape(x.shape), 0.0)

    def force_n_per_m(self) -> float:
        return float(np.pi * self.c_m * self.b[0] / 2.0) if self.b.size else 0.0


def _corrective(nodes_x: FloatArray, sigma: FloatArray, c_m: float) -> _Corrective:
    if c_m <= 0.0:
        return _Corrective(0.0, np.zeros(0))
    n = _CHEBYSHEV_TERMS
    theta = np.pi * (np.arange(n) + 0.5) / n
    t = np.cos(theta)  # Chebyshev–Gauss points (off the nodes)
    h = _hilbert_piecewise_linear(nodes_x, sigma, c_m * t)
    # discrete Chebyshev transform: coefficient of T_k = (2/n) Σ_j h_j cos(k θ_j)
    coef = 2.0 / n * (np.cos(np.outer(np.arange(1, n), theta)) @ h)
    return _Corrective(c_m, coef)


@dataclass(frozen=True)
class LineResponse:
    """One state of a line contact under Q' (SI).

    Attributes
    ----------
    lateral_n_per_m : Q' (N/m)
    stick_half_width_m : c (m); 0 at gross sliding
    x_m, traction_pa : the shear traction q(x) on the profile's nodes (−a..a)
    stick_margin : max of q/τ(p) over the stick zone (<= 1: the rigid stick zone is
        admissible under the τ law; > 1: τ would be exceeded inside it); nan at full slip
    """

    lateral_n_per_m: float
    stick_half_width_m: float
    x_m: FloatArray
    traction_pa: FloatArray
    stick_margin: float


def sliding_force(profile: Profile, laws: PointLaws) -> float:
    """Q'_sat = ∫ σ(p(x)) dx over |x| < a (N/m): the gross-sliding force."""
    x, p = profile.nodes()
    return float(np.trapezoid(laws.sigma_pa(p), x))


def elastic_response(profile: Profile, laws: PointLaws, lateral_n_per_m: float) -> LineResponse:
    """The elastic-stick-zone model (generalised Cattaneo; module docstring, model 1) at Q'.

    Raises
    ------
    InputError
        Unless 0 <= Q' <= Q'_sat (:func:`sliding_force`).
    """
    x, p = profile.nodes()
    sigma = laws.sigma_pa(p)
    q_sat = float(np.trapezoid(sigma, x))
    q = float(lateral_n_per_m)
    require(
        np.isfinite(q) and 0.0 <= q <= q_sat * (1 + 1e-12),
        f"lateral_n_per_m must be in [0, Q'_sat = {q_sat:.6g}] N/m, got {lateral_n_per_m!r}",
    )
    a = profile.half_width_m

    def load_at(c: float) -> float:
        return q_sat - _corrective(x, sigma, c).force_n_per_m()

    if q >= q_sat:
        c = 0.0
    elif q <= 0.0:
        c = a
    else:
        hi = a * (1.0 - 1e-9)
        c = brentq(lambda cc: load_at(cc) - q, 0.0, hi, xtol=1e-14 * a) if load_at(hi) < q else hi
    corr = _corrective(x, sigma, c if c < a else a * (1.0 - 1e-9))
    traction = sigma - corr.traction_pa(x)
    stick = np.abs(x) < c
    tau = laws.tau_pa(p)
    with np.errstate(divide="ignore", invalid="ignore"):
        margin = float(np.max(traction[stick] / tau[stick])) if np.any(stick) else float("nan")
    return LineResponse(q, float(c), x, traction, margin)


def elastic_slip_displacement(
    profile: Profile, response: LineResponse, contact_modulus_pa: float
) -> float:
    """Extra relative displacement at x = 0 from slip, over a fully stuck contact of equal Q' (m).

    The difference q − q_fs of the traction and the full-stick traction of the same Q' has
    zero net force, so its displacement at the centre is depth-independent:
    Δu = −(2/(π E*)) ∫ (q − q_fs)(s) ln|s| ds (two like half-planes, plane strain; the
    tangential and normal compliances of an isotropic half-plane are equal).
    """
    a = profile.half_width_m
    theta = np.linspace(-np.pi / 2, np.pi / 2, 20001)[1:-1]
    s = a * np.sin(theta)
    q = np.interp(s, response.x_m, response.traction_pa)
    # full-stick part in θ: q_fs ds = Q'/π dθ; the slip traction with ds = a cos θ dθ
    integrand = q * a * np.cos(theta) - response.lateral_n_per_m / np.pi
    with np.errstate(divide="ignore"):
        weight = np.log(np.abs(s))
    weight[~np.isfinite(weight)] = 0.0
    return float(-2.0 / (np.pi * contact_modulus_pa) * np.trapezoid(integrand * weight, theta))


# --------------------------------------------------------------------------------------
# the pointwise model (the paper's construction)


@dataclass(frozen=True)
class PointwiseCurve:
    """Q'(Q'_fs) of the pointwise model on a ramp of full-stick loads (SI).

    Attributes
    ----------
    full_stick_n_per_m : Q'_fs, the load a fully stuck contact would carry (∝ u)
    lateral_n_per_m : Q' (N/m)
    stick_half_width_m : outer edge of the stick set (m)
    peak_n_per_m : max Q' (N/m); sliding_n_per_m : Q'_sat = ∫σ dx
    """

    full_stick_n_per_m: FloatArray
    lateral_n_per_m: FloatArray
    stick_half_width_m: FloatArray
    peak_n_per_m: float
    sliding_n_per_m: float


def pointwise_response(
    profile: Profile, laws: PointLaws, full_stick_n_per_m: ArrayLike
) -> PointwiseCurve:
    """The pointwise model (module docstring, model 2) at full-stick loads Q'_fs >= 0.

    Cells of the profile stick where q_fs(midpoint) < τ(p(midpoint)); a stuck cell carries
    ∫ q_fs dx = (Q'_fs/π)(arcsin(x1/a) − arcsin(x0/a)) exactly, a slipping one ∫σ dx.
    """
    qfs = np.atleast_1d(np.asarray(full_stick_n_per_m, dtype=float))
    require(
        bool(np.all(np.isfinite(qfs)) and np.all(qfs >= 0)),
        "full_stick_n_per_m must be finite and >= 0",
    )
    x, p = profile.nodes()
    a = profile.half_width_m
    xm = 0.5 * (x[1:] + x[:-1])
    pm = 0.5 * (p[1:] + p[:-1])
    dx = np.diff(x)
    arc = np.diff(np.arcsin(np.clip(x / a, -1.0, 1.0)))
    tau_m = laws.tau_pa(pm)
    sig_cell = 0.5 * (laws.sigma_pa(p[1:]) + laws.sigma_pa(p[:-1])) * dx
    kernel = 1.0 / (np.pi * np.sqrt(np.clip(a * a - xm * xm, 1e-300, None)))
    stick = qfs[:, None] * kernel[None, :] < tau_m[None, :]
    load = np.where(stick, qfs[:, None] / np.pi * arc[None, :], sig_cell[None, :]).sum(axis=1)
    edge = np.where(stick, np.abs(xm)[None, :], 0.0).max(axis=1)
    return PointwiseCurve(qfs, load, edge, float(load.max()), float(sig_cell.sum()))


def pointwise_peak(profile: Profile, laws: PointLaws, samples: int = 4001) -> PointwiseCurve:
    """The pointwise curve on a ramp up to full slip (q_fs = τ at the centre, and beyond).

    Full slip comes where q_fs(0) = Q'_fs/(π a) exceeds max τ; the ramp runs to 1.5 times that.
    """
    _, p = profile.nodes()
    top = 1.5 * np.pi * profile.half_width_m * float(np.max(laws.tau_pa(p)))
    return pointwise_response(profile, laws, np.linspace(0.0, top, samples))
