"""Q(s) of the modified Mindlin model as a piecewise cubic: its monotone pieces, peak and inverse.

The numerics behind :func:`flatcontact.contact.mindlin.peak_force`,
:func:`~flatcontact.contact.mindlin.s_on_rising_branch` and
:func:`~flatcontact.contact.mindlin.rising_branch_breaks`; the theory (what the coefficients
are) is :mod:`flatcontact.contact.mindlin`, which builds the :class:`Branch`.

With s = √(1 − c²/a²) the outer stick boundary, Q(s)/(2π a²) is

- A1 s + A2 s² + A3 s³ on [0, s_c] (a stick disc), and
- B0 + B1 h + B3 h³, h = t* − s, on (s_c, s_fs] (a stick ring, k < 0 only).

Each cubic has closed-form critical points (quadratics), so [0, s_fs] splits into at most
five monotone pieces (:func:`breakpoints`); the peak is the largest value at a breakpoint
(:func:`peak`), and the inverse on the rising branch is the root on the first piece that
reaches the force (:func:`first_crossing`): Cardano, polished by two Newton steps, with a
bisection safeguard where the closed form is not accurate to ~1e-12 (:func:`solve_on_piece`).
All arrays broadcast over p0; values y are Q/(2π a²) in Pa.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from flatcontact.contact.roots import cubic_roots, quadratic_roots

FloatArray = NDArray[np.float64]


@dataclass(frozen=True)
class Branch:
    """Q(s)/(2π a²) as a piecewise cubic: A on [0, s_c] (disc), B in h = t* − s on (s_c, s_fs].

    Attributes
    ----------
    a : Hertz radius (m)
    area2 : 2π a² (m²), the factor from y = Q/(2π a²) to Q
    tstar : t*, where the ring cubic is centred
    s_c, s_fs : s where the centre starts to slip and where the stick zone vanishes
    A : (A1, A2, A3) (Pa) of the disc cubic; B : (B0, B1, B3) (Pa) of the ring cubic
    """

    a: FloatArray
    area2: FloatArray
    tstar: FloatArray  # 0 where there is no annulus (k >= 0), never used there
    s_c: FloatArray
    s_fs: FloatArray
    A: tuple[FloatArray, FloatArray, FloatArray]
    B: tuple[FloatArray, FloatArray, FloatArray]

    def expanded(self) -> Branch:
        """The same branch with a trailing axis on every array (to broadcast against (..., n))."""

        def ex(x):
            return np.asarray(x)[..., None]

        return Branch(
            a=ex(self.a),
            area2=ex(self.area2),
            tstar=ex(self.tstar),
            s_c=ex(self.s_c),
            s_fs=ex(self.s_fs),
            A=tuple(ex(x) for x in self.A),
            B=tuple(ex(x) for x in self.B),
        )

    def y(self, s):
        """Q/(2π a²) (Pa) at s."""
        a1, a2, a3 = self.A
        b0, b1, b3 = self.B
        h = self.tstar - s
        with np.errstate(invalid="ignore"):
            return np.where(s <= self.s_c, ((a3 * s + a2) * s + a1) * s, b0 + (b3 * h * h + b1) * h)

    def dy_ds(self, s):
        """d(Q/(2π a²))/ds (Pa), the disc piece at s = s_c."""
        a1, a2, a3 = self.A
        _, b1, b3 = self.B
        h = self.tstar - s
        with np.errstate(invalid="ignore"):
            return np.where(
                s <= self.s_c, (3.0 * a3 * s + 2.0 * a2) * s + a1, -(3.0 * b3 * h * h + b1)
            )


def breakpoints(br: Branch) -> tuple[FloatArray, FloatArray]:
    """s (..., 6) splitting [0, s_fs] into pieces where Q(s) is monotone and one cubic:
    0, the critical points of the disc cubic in (0, s_c), s_c, the critical point of the
    annulus cubic in (s_c, s_fs), s_fs (missing ones repeat a neighbour); and Q/(2π a²) there."""
    a1, a2, a3 = br.A
    _, b1, b3 = br.B
    r1, r2 = quadratic_roots(3.0 * a3, 2.0 * a2, a1)
    with np.errstate(invalid="ignore"):
        d1 = np.where((r1 > 0.0) & (r1 < br.s_c), r1, br.s_c)
        d2 = np.where((r2 > 0.0) & (r2 < br.s_c), r2, br.s_c)
    with np.errstate(divide="ignore", invalid="ignore"):
        h2 = -b1 / (3.0 * b3)
        rc = br.tstar - np.sqrt(np.where(h2 > 0.0, h2, np.nan))
        rc = np.where((rc > br.s_c) & (rc < br.s_fs), rc, br.s_fs)
    zero = np.zeros_like(br.s_c)
    b = np.stack(
        np.broadcast_arrays(zero, np.minimum(d1, d2), np.maximum(d1, d2), br.s_c, rc, br.s_fs),
        axis=-1,
    )
    return b, br.expanded().y(b)


def peak(br: Branch, b: FloatArray, yb: FloatArray):
    """(s_peak, y_peak, overshoot, first_local_max_s) from the breakpoints."""
    y_fs = yb[..., -1]
    i = np.argmax(yb[..., :-1], axis=-1)[..., None]
    y_in = np.take_along_axis(yb, i, axis=-1)[..., 0]
    overshoot = y_in > y_fs
    s_peak = np.where(overshoot, np.take_along_axis(b, i, axis=-1)[..., 0], br.s_fs)
    y_peak = np.where(overshoot, y_in, y_fs)
    falls = yb[..., 2:] < yb[..., 1:-1]  # Q decreases on the piece after breakpoint j = 1..4
    j = np.argmax(falls, axis=-1)[..., None] + 1
    first = np.where(np.any(falls, axis=-1), np.take_along_axis(b, j, axis=-1)[..., 0], br.s_fs)
    return s_peak, y_peak, overshoot, first


def solve_on_piece(y, lo, hi, br: Branch):
    """s in [lo, hi] with Q(s)/(2π a²) = y, where [lo, hi] lies in one cubic piece on which
    Q rises from below y to >= y (unique root): Cardano, Newton polish, bisection safeguard."""
    a1, a2, a3 = br.A
    b0, b1, b3 = br.B
    ring = hi > br.s_c
    ts = br.tstar
    # the piece's cubic in its own variable x: x = s (disc, rising) or h = t* − s (ring, falling)
    c3 = np.where(ring, b3, a3)
    c2 = np.where(ring, 0.0, a2)
    c1 = np.where(ring, b1, a1)
    c0 = np.where(ring, b0 - y, -y)
    xlo = np.where(ring, ts - hi, lo)
    xhi = np.where(ring, ts - lo, hi)
    sign = np.where(ring, -1.0, 1.0)
    c3, c2, c1, c0, xlo, xhi, sign = np.broadcast_arrays(c3, c2, c1, c0, xlo, xhi, sign)
    roots = cubic_roots(c3, c2, c1, c0)
    tol = 1e-6
    re = roots.real
    ok = (
        (np.abs(roots.imag) <= tol * (1.0 + np.abs(re)))
        & (re >= xlo[..., None] - tol)
        & (re <= xhi[..., None] + tol)
    )
    x = np.min(np.where(ok, re, np.inf), axis=-1)
    x = np.clip(np.where(np.isfinite(x), x, xhi), xlo, xhi)

    def f(x):
        return ((c3 * x + c2) * x + c1) * x + c0

    def mag(x):
        return np.abs(c3 * x**3) + np.abs(c2 * x * x) + np.abs(c1 * x) + np.abs(c0) + np.abs(y)

    scale = np.abs(c3) + np.abs(c2) + np.abs(c1)
    for _ in range(2):  # Newton x − f/f' = (2 c3 x³ + c2 x² − c0)/f', kept inside the bracket
        df = (3.0 * c3 * x + 2.0 * c2) * x + c1
        good = sign * df > 1e-12 * scale
        newton = ((2.0 * c3 * x + c2) * x * x - c0) / np.where(good, df, 1.0)
        x = np.clip(np.where(good, newton, x), xlo, xhi)
    # safeguard: where the closed form is not accurate (near-degenerate cubic, the double
    # root at a local maximum) finish by bisection on the bracket, where f is monotone
    bad = np.abs(f(x)) > 1e-12 * np.abs(y) + 1e-14 * mag(x)
    if np.any(bad):
        lo_, hi_ = xlo.copy(), xhi.copy()
        for _ in range(64):
            mid = 0.5 * (lo_ + hi_)
            up = sign * f(mid) >= 0.0
            hi_ = np.where(up, mid, hi_)
            lo_ = np.where(up, lo_, mid)
        x = np.where(bad, np.where(sign > 0, hi_, lo_), x)
    return np.where(ring, ts - x, x)


def first_crossing(y, b, yb, br: Branch):
    """Smallest s with Q(s)/(2π a²) = y for 0 <= y <= max Q: the first monotone piece whose
    end reaches y (every earlier breakpoint lies below y, so Q rises through y there)."""
    j = np.argmax(yb >= y[..., None], axis=-1)[..., None]
    j1 = np.maximum(j - 1, 0)
    shape = np.broadcast_shapes((*y.shape, 1), b.shape)
    bb = np.broadcast_to(b, shape)
    lo = np.take_along_axis(bb, j1, axis=-1)[..., 0]
    hi = np.take_along_axis(bb, j, axis=-1)[..., 0]
    s = solve_on_piece(y, lo, hi, br)
    return np.where(y <= 0.0, 0.0, s)
