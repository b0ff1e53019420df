"""The elastic moduli of the contact models and their conventions, stated once.

Contact modulus E* (Hertz; Johnson, *Contact Mechanics*, 1985, §4.2)
    1/E* = (1−ν1²)/E1 + (1−ν2²)/E2; a = π R p0/(2 E*) (:mod:`flatcontact.contact.hertz`).

Effective shear modulus: two conventions for the same traction
    The paper (Dong et al., Eq. for q0) writes the full-stick traction of a contact of
    radius a displaced by u as q(r) = q0/√(1 − r²/a²) with

        q0 = G*·u/(π a),       stiffness of a stuck contact ∫q dA/u = 2 G* a.

    Johnson (1985, §7.2) writes the same traction as q0 = 4 G*_J u/(π a) with

        1/G*_J = (2−ν1)/G1 + (2−ν2)/G2,    stiffness 8 G*_J a,

    hence **G* (paper) = 4 G*_J (Johnson)**. Everything in :mod:`flatcontact.contact` that
    is the paper's model (``ContactParameters.shear_modulus_gpa``,
    :mod:`~flatcontact.contact.mindlin`, the modified cycle) takes the paper's G*; the
    classical Cattaneo–Mindlin functions (:mod:`~flatcontact.contact.cattaneo_mindlin`)
    take Johnson's G*_J (``johnson_shear_modulus_pa``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

FloatArray = NDArray[np.float64]


def contact_modulus(e1_pa: float, nu1: float, e2_pa: float, nu2: float) -> float:
    """Hertz contact modulus E* of two isotropic bodies: 1/E* = (1−ν1²)/E1 + (1−ν2²)/E2
    (Johnson 1985, Eq. 4.22; any one unit for both E, returned in it)."""
    return 1.0 / ((1.0 - nu1**2) / e1_pa + (1.0 - nu2**2) / e2_pa)


def paper_shear_modulus(e1_pa: float, nu1: float, e2_pa: float, nu2: float) -> float:
    """The paper's G* (q0 = G*·u/(π a)) of two isotropic bodies from E and ν:
    G_i = E_i/(2(1+ν_i)), G* = 4 G*_J (:func:`johnson_effective_shear_modulus`)."""
    g1, g2 = e1_pa / (2.0 * (1.0 + nu1)), e2_pa / (2.0 * (1.0 + nu2))
    return 4.0 * johnson_effective_shear_modulus(g1, nu1, g2, nu2)


def johnson_effective_shear_modulus(g1_pa: float, nu1: float, g2_pa: float, nu2: float) -> float:
    """Johnson's G*_J from the shear moduli and Poisson ratios: 1/G*_J = (2−ν1)/G1 + (2−ν2)/G2."""
    return 1.0 / ((2.0 - nu1) / g1_pa + (2.0 - nu2) / g2_pa)


def paper_shear_modulus_from_johnson(g_johnson: ArrayLike) -> FloatArray:
    """The paper's G* (q0 = G*·u/(π a)) from Johnson's G*_J (q0 = 4 G*_J u/(π a)): G* = 4 G*_J."""
    return 4.0 * np.asarray(g_johnson, dtype=float)


def johnson_shear_modulus_from_paper(g_paper: ArrayLike) -> FloatArray:
    """Johnson's G*_J from the paper's G*: G*_J = G*/4."""
    return np.asarray(g_paper, dtype=float) / 4.0
