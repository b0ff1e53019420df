"""Roots of quadratics and cubics in closed form, vectorised over numpy arrays.

The numerics behind the modified Mindlin model's closed forms
(:mod:`flatcontact.contact.mindlin`, :mod:`flatcontact.contact.piecewise_cubic`) and the
oscillation cycle (:mod:`flatcontact.contact.cycle`): every coefficient broadcasts, a
missing root is nan, and each formula avoids the cancellation of the textbook one.

- :func:`quadratic_roots`: q = −(b + sign(b)√(b² − 4ac))/2, roots q/a and c/q
  (Numerical Recipes §5.6); a linear equation when |a| is negligible.
- :func:`cubic_roots`: Cardano with complex arithmetic, the root of smallest magnitude
  recovered from Vieta (x1 x2 x3 = −d/a); a quadratic when the cubic coefficient is
  negligible.
"""

from __future__ import annotations

import numpy as np


def quadratic_roots(qa, qb, qc):
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


def cubic_roots(c3, c2, c1, c0):
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
    q1, q2 = quadratic_roots(c2, c1, c0)
    quad = np.stack([q1, q2, np.full_like(q1, np.nan)], axis=-1).astype(complex)
    return np.where(cubic[..., None], cub, quad)
