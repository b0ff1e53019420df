"""The steady cycle of the paper's modified Mindlin model: the element rule in closed form.

The tip is driven by Q(t) = Q_amp sin θ below gross sliding; :mod:`flatcontact.contact.cycle`
integrates the cycle (first harmonic, loops) of this model and of the classical one
(:mod:`flatcontact.contact.cattaneo_mindlin`). Here: the paper's rule per element and its
closed forms (U1), (W). SI units; the paper's G* (:mod:`flatcontact.contact.moduli`).

The paper's local rule, written per surface element at s = √(1 − r²/a²): the element's
full-stick traction is q0/s with q0 = G*·u/(π a) (paper's G*), i.e. a spring of stiffness
κ(s) = G*/(π a s) per area, in series with a slider that holds until its traction reaches
its static strength τ(s) = k p0 s + τ0 and then slips carrying the kinetic (MSS) traction
σ(s) = μ p0 s + σ0. Loading from rest gives the paper's Q(u) (:mod:`.mindlin`). The paper
is silent about reversal; the rule continued to it is:

* at a reversal every element re-sticks; its traction then changes by κ·Δu;
* it slips the other way once the change since the reversal exceeds what holds it:
  τ + σ if it had slipped (it carried σ), τ + q if it had stuck (it carried q), i.e. once
  its traction reaches ∓τ; slipping elements carry ∓σ.

With X = G*U/(π a) the drive at the top (U: displacement amplitude) and D = G*Δ/(π a) the
drive decrement Δ = U − u since the reversal, and g(s) = s τ(s), g₂(s) = s (τ + σ)(s):

* the elements that slipped on loading are S₁ = {s : g(s) <= X} (the slip zone of the
  loading branch at U; a ring, or ring and centre for k < 0);
* on unloading the slipped ones re-slip once g₂(s) <= D: S₂(D) = S₁ ∩ {g₂ <= D}; the
  stuck ones (g > X) never slip during the cycle (their traction stays inside ±τ);
* the force falls by (dA = 2π a² s ds)

      Q_amp − Q(D) = 2π a² [ D·|[0,1] \\ S₂(D)| + ∫_{S₂(D)} 2 σ(s) s ds ];            (U1)

* if σ <= τ on the contact, S₁ ⊂ {g₂ <= 2X}: at D = 2X (u = −U) every element of S₁ has
  re-slipped and every traction is the mirror image of the top, Q = −Q_amp. The loop closes
  after the first quarter cycle (a sudden start and a slow ramp give the same steady cycle),
  reloading is the mirror image u → −u, Q → −Q of unloading, and Q(D) stays above −Q_amp
  for D < 2X (it is below 2 Q_load(D/2)). Where (U1) is not monotone in D the load-controlled
  path jumps (u at fixed Q); it follows the running maximum of Q_amp − Q(D).
* generalised Masing rule: while S₂ is the full sublevel set {g₂ <= D} (k, k + μ >= 0 and
  D <= g₂(s₁)), (U1) is the paper's loading branch of a contact with static strength τ + σ
  and slip traction 2σ, evaluated at the displacement Δ. In the classical limit τ = σ
  (k = μ, τ0 = σ0) that contact is the original one with both laws doubled, g₂ = 2g, and
  Q_amp − Q(Δ) = 2 Q_load(Δ/2): **Masing's rule**, the return branch is the loading branch
  with force and displacement doubled. For σ < τ the return branch is stiffer than Masing's
  and ends in a straight (elastic) segment once all of S₁ has re-slipped.

Energy per cycle, from each element's own loop (spring + slider: linear from −σ to +τ,
instantaneous drop τ → σ, sliding at σ, and back):

    W = (2π² a³/G*) ∫_{S₁} [4σ s (X − σ s) + (τ − σ)² s²] ds.                         (W)

The (τ − σ)² term is the energy of the static-to-kinetic drop. As Q_amp → 0 (τ0 > 0):
S₁ ≈ [0, X/τ0], X ≈ Q_amp/(2π a²), W ≈ (2π²a³/G*)(X/τ0)³(τ0² + 4τ0σ0 − 3σ0²)/3: cubic in
Q_amp; for τ0 = 0 (then σ0 = 0 here) W ∝ Q_amp^(5/2).

Numerics: (U1) and (W) are closed forms (polynomials on the intervals cut by the roots of
the quadratics g = X and g₂ = D; membership decided at each interval's midpoint, which
covers every sign of k and μ).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from flatcontact.contact import mindlin
from flatcontact.contact.parameters import ContactParameters
from flatcontact.contact.roots import quadratic_roots

FloatArray = NDArray[np.float64]


def _roots01(c2, c1, level):
    """The two roots of c2 s² + c1 s = level, as candidates in [0, 1] (0 where absent)."""
    r1, r2 = quadratic_roots(c2, c1, -level)
    out = []
    for r in (r1, r2):
        ok = np.isfinite(r) & (r > 0.0) & (r < 1.0)
        out.append(np.where(ok, r, 0.0))
    return out


def _poly_integral(coeffs, lo, hi):
    """∫_lo^hi Σ_j c_j s^j ds, coeffs = (c0, c1, c2, ...) broadcasting."""
    total = 0.0
    for j, c in enumerate(coeffs):
        total = total + c * (hi ** (j + 1) - lo ** (j + 1)) / (j + 1)
    return total


def _ex(z):
    """``z`` with a new last axis, to broadcast against the pieces of :func:`_pieces`."""
    return np.asarray(z)[..., None]


def _slipped_on_loading(x, kp, t0):
    """The loading branch at drive X: the pieces [lo, hi] of s ∈ [0, 1] and ``member``, True on
    the slipped set S₁ = {k p0 s² + τ0 s <= X}."""
    lo, hi, mid = _pieces(*_roots01(kp, t0, x))
    return lo, hi, _ex(kp) * mid**2 + t0 * mid <= _ex(x)


def _pieces(*candidates):
    """Sorted breakpoints 0, candidates..., 1 along a new last axis; (lo, hi, mid)."""
    cands = np.broadcast_arrays(*candidates)
    zero = np.zeros_like(cands[0])
    b = np.sort(np.stack([zero, *cands, zero + 1.0], axis=-1), axis=-1)
    lo, hi = b[..., :-1], b[..., 1:]
    return lo, hi, 0.5 * (lo + hi)


def unloading_decrement(
    drive_decrement_pa: ArrayLike, drive_pa: ArrayLike, p0_pa: ArrayLike, params: ContactParameters
) -> FloatArray:
    """(Q_amp − Q)/(2π a²) (Pa) on the unloading branch, Eq. (U1) of the module doc.

    ``drive_pa`` is X = G*U/(π a) at the top, ``drive_decrement_pa`` D = G*Δ/(π a) with
    Δ = U − u; both broadcast with p0. Closed form for any sign of k, μ.
    """
    d = np.asarray(drive_decrement_pa, dtype=float)
    x = np.asarray(drive_pa, dtype=float)
    p0 = np.asarray(p0_pa, dtype=float)
    kp, mp = params.k * p0, params.mu * p0
    t0, s0 = params.tau0_pa, params.sigma0_pa
    r1, r2 = _roots01(kp, t0, x)
    r3, r4 = _roots01(kp + mp, t0 + s0, d)
    lo, hi, mid = _pieces(r1, r2, r3, r4)
    member = (_ex(kp) * mid**2 + t0 * mid <= _ex(x)) & (
        _ex(kp + mp) * mid**2 + (t0 + s0) * mid <= _ex(d)
    )
    slipped = _poly_integral((0.0, 2.0 * s0, 2.0 * _ex(mp)), lo, hi)
    stuck = _ex(d) * (hi - lo)
    return np.sum(np.where(member, slipped, stuck), axis=-1)


def loading_force_per_area(
    drive_pa: ArrayLike, p0_pa: ArrayLike, params: ContactParameters
) -> FloatArray:
    """Q/(2π a²) (Pa) on the loading branch at drive X = q0, from the element rule:
    ∫ [σ(s) s on S₁, X elsewhere] ds (equal to :func:`mindlin.lateral_force`)."""
    x = np.asarray(drive_pa, dtype=float)
    p0 = np.asarray(p0_pa, dtype=float)
    kp, mp = params.k * p0, params.mu * p0
    t0, s0 = params.tau0_pa, params.sigma0_pa
    lo, hi, member = _slipped_on_loading(x, kp, t0)
    slipped = _poly_integral((0.0, s0, _ex(mp)), lo, hi)
    return np.sum(np.where(member, slipped, _ex(x) * (hi - lo)), axis=-1)


def dissipated_energy(
    drive_pa: ArrayLike, p0_pa: ArrayLike, params: ContactParameters
) -> FloatArray:
    """Energy dissipated per steady cycle (J), Eq. (W): the sum of every element's own loop."""
    x = np.asarray(drive_pa, dtype=float)
    p0 = np.asarray(p0_pa, dtype=float)
    kp, mp = params.k * p0, params.mu * p0
    t0, s0 = params.tau0_pa, params.sigma0_pa
    lo, hi, member = _slipped_on_loading(x, kp, t0)
    m, n = _ex(mp), s0  # σ s = m s² + n s
    m2, n2 = _ex(kp - mp), t0 - s0  # (τ − σ) s = m2 s² + n2 s
    coeffs = (
        0.0,
        4.0 * _ex(x) * n,
        4.0 * _ex(x) * m - 4.0 * n * n + n2 * n2,
        -8.0 * m * n + 2.0 * m2 * n2,
        -4.0 * m * m + m2 * m2,
    )
    integral = np.sum(np.where(member, _poly_integral(coeffs, lo, hi), 0.0), axis=-1)
    a = mindlin.contact_radius(p0, params)
    return 2.0 * np.pi**2 * a**3 / params.shear_modulus_pa * integral


def unloading_drive_breaks(x, p0, params: ContactParameters):
    """D where the set S₂(D) changes structure: g₂ at the boundaries of S₁, at g₂'s vertex, at 1."""
    kp, mp = params.k * p0, params.mu * p0
    t0, s0 = params.tau0_pa, params.sigma0_pa
    r1, r2 = _roots01(kp, t0, x)
    c2 = np.asarray(kp + mp, dtype=float)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # k + μ -> 0−
        v = np.where(c2 < 0.0, -(t0 + s0) / (2.0 * np.where(c2 < 0.0, c2, -1.0)), 1.0)
    v = np.clip(np.where(np.isfinite(v), v, 1.0), 0.0, 1.0)
    pts = [r1, r2, v, np.ones_like(r1)]
    return [c2 * s * s + (t0 + s0) * s for s in np.broadcast_arrays(*pts)]
