"""Model ISPES grids whose constant-pressure landscape and friction are known in closed form.

Used by the tests and the documentation to check :mod:`flatcontact.analysis`
against exact answers. The model energy per area of the interface at lateral
shift ``r = s_a·a1 + s_b·a2`` (fractional ``s``) and thickness ``z`` is

.. math::

    e(s, z) = D(s)\\,\\varphi(u) + V\\,g(s), \\qquad
    \\varphi(u) = u^2 - 2u, \\qquad u = e^{-\\alpha (z - z_0(s))},

    D(s) = \\bar D\\,(1 + c\\,g(s)), \\qquad z_0(s) = \\bar z + \\delta\\,g(s),

a Morse adhesion well of depth ``D`` (eV/Å²) and range ``1/α`` (Å) whose depth
and equilibrium gap are modulated by a periodic pattern ``g(s)``, plus a
z-independent corrugation ``V·g``. The normal stress (positive when pressed) is

.. math:: p = -\\partial e/\\partial z = 2\\alpha D (u^2 - u),

monotone decreasing in z on the repulsive branch ``u > 1/2`` with the maximum
tension ``-αD/2`` at ``u = 1/2``. At a fixed load ``P`` the branch is inverted in
closed form, ``u* = (1 + sqrt(1 + 2P/(αD)))/2``, so that

- internal energy (the paper's form): ``ẽ = D φ(u*) + V g``,
- enthalpy: ``h = ẽ + P z*`` with ``z* = z0 - ln(u*)/α``.

With ``c = 0`` the internal landscape is exactly ``const + V g`` and the
enthalpy landscape exactly ``const + (V + P δ) g``: path, τ, σ and the shear
stiffness then follow from ``g`` alone (see the tests).

Patterns are functions of the fractional coordinates with period 1 in each;
each returns ``(g, dg/ds, d²g/ds²)`` with shapes ``(...)``, ``(..., 2)``,
``(..., 2, 2)``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import xarray as xr

from flatcontact.foundation import units
from flatcontact.foundation.errors import require
from flatcontact.ispes import contract

Pattern = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]

TWO_PI = 2.0 * np.pi


def hexagonal_cell(
    a_angstrom: float = 4.916, rotation_deg: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """Primitive vectors of a hexagonal lattice, 120° apart, ``a1`` at ``rotation_deg`` from x."""
    th = np.deg2rad(rotation_deg)
    a1 = a_angstrom * np.array([np.cos(th), np.sin(th)])
    a2 = a_angstrom * np.array([np.cos(th + TWO_PI / 3), np.sin(th + TWO_PI / 3)])
    return a1, a2


def rectangular_cell(a_angstrom: float, b_angstrom: float) -> tuple[np.ndarray, np.ndarray]:
    """Primitive vectors ``a1 = (a, 0)``, ``a2 = (0, b)`` of a rectangular lattice (Å)."""
    return np.array([a_angstrom, 0.0]), np.array([0.0, b_angstrom])


def cosine_sum(
    terms: list[tuple[int, int, float]] | list[tuple[int, int, float, float]],
) -> Pattern:
    """Band-limited pattern ``g(s) = Σ_j w_j cos(2π(k_j s_a + l_j s_b) + φ_j)``.

    ``terms`` holds ``(k, l, w)`` or ``(k, l, w, φ)`` tuples (φ in radians).
    """
    kl = np.array([[t[0], t[1]] for t in terms], dtype=float)
    w = np.array([t[2] for t in terms], dtype=float)
    phase = np.array([t[3] if len(t) > 3 else 0.0 for t in terms], dtype=float)

    def pattern(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s = np.asarray(s, dtype=float)
        arg = TWO_PI * (s @ kl.T) + phase  # (..., n_terms)
        c, sn = np.cos(arg), np.sin(arg)
        g = c @ w
        grad = -(sn * w) @ (TWO_PI * kl)
        hess = -np.einsum("...j,ja,jb->...ab", c * w, TWO_PI * kl, TWO_PI * kl)
        return g, grad, hess

    return pattern


def three_cosine(
    a1: np.ndarray, a2: np.ndarray, weights: tuple[float, float, float] = (1, 1, 1)
) -> Pattern:
    """Σ cos(G·r) over the three shortest reciprocal vectors of a hexagonal cell.

    ``g = 3`` at the lattice points (the maxima), ``-3/2`` at the two hollow sites
    and ``-1`` at the bond midpoints (the saddles). Unequal ``weights`` break the
    six-fold symmetry. For a 120° cell the third vector is ``b2 - b1``, for a 60°
    cell ``b1 + b2``.
    """
    third = (-1, 1) if float(np.dot(a1, a2)) < 0 else (1, 1)
    return cosine_sum([(1, 0, weights[0]), (0, 1, weights[1]), (*third, weights[2])])


def canyon(winding: int = 1, wiggle: float = 0.1, barrier_weight: float = 0.5) -> Pattern:
    """A winding canyon along ``a2``: ``g = -cos 2π(s_a - m s_b - λ sin 2π s_b) - w cos 2π s_b``.

    The canyon floor ``s_a = m s_b + λ sin(2π s_b)`` (mod 1) is where ``∂g/∂s_a = 0``
    with ``∂²g/∂s_a² > 0``; on a rectangular cell pulled along ``a2`` (y) it is the
    zero-perpendicular-force path, curved for ``λ ≠ 0`` and tilted for ``m ≠ 0``.
    Along it ``g = -1 - w cos 2π s_b``.
    """
    m, lam, w = float(winding), float(wiggle), float(barrier_weight)

    def pattern(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s = np.asarray(s, dtype=float)
        sa, sb = s[..., 0], s[..., 1]
        psi = sa - m * sb - lam * np.sin(TWO_PI * sb)
        dpsi_b = -m - lam * TWO_PI * np.cos(TWO_PI * sb)
        d2psi_b = lam * TWO_PI**2 * np.sin(TWO_PI * sb)
        c, sn = np.cos(TWO_PI * psi), np.sin(TWO_PI * psi)
        cb, sb_ = np.cos(TWO_PI * sb), np.sin(TWO_PI * sb)
        g = -c - w * cb
        ga = TWO_PI * sn
        gb = TWO_PI * sn * dpsi_b + w * TWO_PI * sb_
        gaa = TWO_PI**2 * c
        gab = TWO_PI**2 * c * dpsi_b
        gbb = TWO_PI**2 * c * dpsi_b**2 + TWO_PI * sn * d2psi_b + w * TWO_PI**2 * cb
        grad = np.stack([ga, gb], axis=-1)
        hess = np.stack([np.stack([gaa, gab], -1), np.stack([gab, gbb], -1)], -2)
        return g, grad, hess

    return pattern


def shifted(pattern: Pattern, shift_frac: tuple[float, float]) -> Pattern:
    """The pattern translated by ``shift_frac`` (fractional): ``g'(s) = g(s - shift)``."""
    d = np.asarray(shift_frac, dtype=float)

    def moved(s: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return pattern(np.asarray(s, dtype=float) - d)

    return moved


@dataclass(frozen=True)
class SyntheticInterface:
    """Morse adhesion with a periodic modulation; see the module docstring.

    Parameters
    ----------
    a1, a2
        In-plane primitive vectors (Å).
    pattern
        Periodic pattern ``g(s)`` of the fractional coordinates.
    well_depth_ev_per_a2
        ``D̄``: mean adhesion energy per area (eV/Å²).
    alpha_per_angstrom
        ``α``: inverse range of the Morse well (1/Å).
    gap_angstrom
        ``z̄``: mean equilibrium thickness (Å).
    depth_modulation
        ``c``: relative modulation of the well depth by ``g``.
    gap_modulation_angstrom
        ``δ``: modulation of the equilibrium thickness by ``g`` (Å).
    corrugation_ev_per_a2
        ``V``: z-independent corrugation amplitude (eV/Å²), signed.
    energy_offset_ev
        Constant added to the cell energy (the slabs' own energy).
    """

    a1: np.ndarray
    a2: np.ndarray
    pattern: Pattern
    well_depth_ev_per_a2: float = 0.02
    alpha_per_angstrom: float = 1.2
    gap_angstrom: float = 25.0
    depth_modulation: float = 0.0
    gap_modulation_angstrom: float = 0.0
    corrugation_ev_per_a2: float = 1.0e-3
    energy_offset_ev: float = -1234.5

    @property
    def area(self) -> float:
        """Cell area |a1 × a2| (Å²)."""
        return contract.cell_area(self.a1, self.a2)

    def fractional(self, xy: np.ndarray) -> np.ndarray:
        """Fractional coordinates of Cartesian points ``xy`` (Å)."""
        lat = np.column_stack([self.a1, self.a2])
        return np.asarray(xy, dtype=float) @ np.linalg.inv(lat).T

    def _depth_gap(self, g: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        depth = self.well_depth_ev_per_a2 * (1.0 + self.depth_modulation * g)
        gap = self.gap_angstrom + self.gap_modulation_angstrom * g
        return depth, gap

    def energy_per_area(self, s: np.ndarray, z: np.ndarray) -> np.ndarray:
        """``e(s, z)`` in eV/Å² (without the constant offset)."""
        g = self.pattern(s)[0]
        depth, gap = self._depth_gap(g)
        u = np.exp(-self.alpha_per_angstrom * (z - gap))
        return depth * (u * u - 2.0 * u) + self.corrugation_ev_per_a2 * g

    def stress_ev_per_a3(self, s: np.ndarray, z: np.ndarray) -> np.ndarray:
        """Normal stress ``p = -∂e/∂z`` (eV/Å³), positive when pressed."""
        g = self.pattern(s)[0]
        depth, gap = self._depth_gap(g)
        u = np.exp(-self.alpha_per_angstrom * (z - gap))
        return 2.0 * self.alpha_per_angstrom * depth * (u * u - u)

    def landscape_of_g(
        self, g: np.ndarray, p_ev_per_a3: float, form: str = "internal"
    ) -> np.ndarray:
        """Closed-form constant-pressure energy per area (eV/Å²) as a function of ``g``.

        Works for complex ``g`` (complex-step derivatives). ``form`` is
        ``"internal"`` (ẽ = e at z*) or ``"enthalpy"`` (ẽ + P z*).
        """
        depth, gap = self._depth_gap(g)
        ustar = 0.5 * (1.0 + np.sqrt(1.0 + 2.0 * p_ev_per_a3 / (self.alpha_per_angstrom * depth)))
        e = depth * (ustar * ustar - 2.0 * ustar) + self.corrugation_ev_per_a2 * g
        if form == "enthalpy":
            e = e + p_ev_per_a3 * (gap - np.log(ustar) / self.alpha_per_angstrom)
        return e

    def thickness_at(self, s: np.ndarray, p_ev_per_a3: float) -> np.ndarray:
        """Closed-form thickness ``z*`` (Å) at which ``p(s, z*) = P``."""
        g = self.pattern(s)[0]
        depth, gap = self._depth_gap(g)
        ustar = 0.5 * (1.0 + np.sqrt(1.0 + 2.0 * p_ev_per_a3 / (self.alpha_per_angstrom * depth)))
        return gap - np.log(ustar) / self.alpha_per_angstrom

    def landscape(self, s: np.ndarray, p_ev_per_a3: float, form: str = "internal") -> np.ndarray:
        """Closed-form constant-pressure energy per area (eV/Å²) at fractional points ``s``."""
        return self.landscape_of_g(self.pattern(s)[0], p_ev_per_a3, form)

    def grid(
        self,
        n_a: int,
        n_b: int,
        thickness_angstrom: np.ndarray,
        *,
        energy_noise_ev: float = 0.0,
        stress_noise_gpa: float = 0.0,
        seed: int = 0,
    ) -> xr.Dataset:
        """The model sampled on a contract grid (``ispes.nc`` layout), optionally with noise."""
        z = np.asarray(thickness_angstrom, dtype=float)
        require(z.ndim == 1 and z.size >= 1, "thickness_angstrom: expected a 1-D array of Å")
        ds = contract.empty_grid(n_a, n_b, z, self.a1, self.a2, potential="synthetic Morse model")
        sa, sb = np.meshgrid(ds.shift_a.values, ds.shift_b.values, indexing="ij")
        s = np.stack([sa, sb], axis=-1)[:, :, None, :]
        zz = ds.thickness.values[None, None, :]
        e = self.energy_per_area(s, zz)
        p = self.stress_ev_per_a3(s, zz)
        rng = np.random.default_rng(seed)
        energy = e * self.area + self.energy_offset_ev
        stress = p * units.EV_PER_A3_TO_GPA
        if energy_noise_ev:
            energy = energy + rng.normal(scale=energy_noise_ev, size=energy.shape)
        if stress_noise_gpa:
            stress = stress + rng.normal(scale=stress_noise_gpa, size=stress.shape)
        ds[contract.VAR_ENERGY][:] = energy
        ds[contract.VAR_STRESS][:] = stress
        ds[contract.VAR_CONVERGED][:] = True
        return ds
