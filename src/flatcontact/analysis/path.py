"""Sliding paths on a constant-pressure landscape.

**Zero-perpendicular-force path** (the paper's path, Fig. 2a). The slider is
pulled quasi-statically along the unit vector ``d`` at angle ``θ`` from x
(default 90°, i.e. y); nothing holds it in the perpendicular direction
``m = (-sin θ, cos θ)``, so at every position ``t`` along ``d`` it sits at a
*stable* minimum of the energy in ``n``:

.. math:: \\partial_n e(t, n) = 0, \\qquad \\partial_n^2 e(t, n) > 0,
          \\qquad \\mathbf r = \\mathbf r_0 + t\\,\\mathbf d + n\\,\\mathbf m .

The branch is continued from the global minimum ``r0`` by a predictor
(``dn/dt = -e_tn/e_nn``) and a Newton corrector with analytic derivatives of
the periodic interpolant. Where the branch disappears (a fold,
``e_nn → 0``) the slider jumps at fixed ``t`` to the next stable minimum in
``n``; the jump is recorded. Tracking stops when the slider reaches a point
equivalent to ``r0`` (``r - r0`` a lattice vector: one full period of the
motion) or at a maximum length.

Along the path ``de/dt = ∂_t e`` (the perpendicular force vanishes) is the
resisting lateral force per area, and the effective stiffness of the relaxed
path is the Schur complement ``d²e/dt² = e_tt - e_tn²/e_nn``.

**Minimum-energy path** between equivalent minima by the simplified string
method (W. E, W. Ren, E. Vanden-Eijnden, J. Chem. Phys. 126, 164103 (2007)):
images move down the gradient and are redistributed at equal arc length.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicSpline
from scipy.optimize import brentq

from flatcontact.analysis.diagnostics import PathNotPeriodicWarning
from flatcontact.analysis.periodic import PeriodicSurface, lattice_vectors
from flatcontact.foundation.errors import InputError


@dataclass(frozen=True)
class PathPoint:
    """State of the slider at ``t`` on a relaxed branch."""

    t: float
    n: float
    xy: np.ndarray
    energy: float  #: eV/Å² (surface units)
    force: float  #: ∂e/∂t, resisting force per area
    curvature: float  #: e_tt - e_tn²/e_nn
    perpendicular_curvature: float  #: e_nn


class PathFrame:
    """Pulling frame ``r = r0 + t d + n m`` on a surface, with the relaxation in ``n``."""

    def __init__(
        self, surface: PeriodicSurface, start_xy: np.ndarray, direction_deg: float
    ) -> None:
        self.surface = surface
        self.r0 = np.asarray(start_xy, float)
        th = np.deg2rad(direction_deg)
        self.d = np.array([np.cos(th), np.sin(th)])
        self.m = np.array([-np.sin(th), np.cos(th)])
        self.scale = float(min(np.linalg.norm(surface.a1), np.linalg.norm(surface.a2)))

    def point(self, t: float, n: float) -> PathPoint:
        """Evaluate the slider state at ``(t, n)`` (no relaxation)."""
        xy = self.r0 + t * self.d + n * self.m
        sv = self.surface.evaluate(xy)
        g, h = sv.gradient, sv.hessian
        e_t = g @ self.d
        e_tt, e_tn, e_nn = self.d @ h @ self.d, self.d @ h @ self.m, self.m @ h @ self.m
        schur = e_tt - e_tn**2 / e_nn if e_nn != 0 else -np.inf
        return PathPoint(
            float(t), float(n), xy, float(sv.value), float(e_t), float(schur), float(e_nn)
        )

    def perpendicular_force(self, t: float, n: float) -> tuple[float, float]:
        """``(∂_n e, ∂²_n e)`` at ``(t, n)``."""
        sv = self.surface.evaluate(self.r0 + t * self.d + n * self.m)
        return float(sv.gradient @ self.m), float(self.m @ sv.hessian @ self.m)

    def relax(self, t: float, n_guess: float, max_shift: float | None = None) -> PathPoint | None:
        """Newton on ``∂_n e = 0`` from ``n_guess``; ``None`` unless a stable root within ``max_shift``."""
        n = float(n_guess)
        cap = 0.05 * self.scale
        for _ in range(40):
            g, c = self.perpendicular_force(t, n)
            if not c > 0:
                return None
            dn = float(np.clip(-g / c, -cap, cap))
            n += dn
            if abs(dn) < 1e-11 * self.scale:
                break
        else:
            return None
        if max_shift is not None and abs(n - n_guess) > max_shift:
            return None
        p = self.point(t, n)
        return p if p.perpendicular_curvature > 0 else None

    def descend(self, t: float, n_start: float) -> PathPoint:
        """Slide down in ``n`` at fixed ``t`` from ``n_start`` to the next stable minimum (a jump).

        The slider moves against ``∂_n e``; where that vanishes by symmetry (a
        pitchfork) it goes to the lower side, and to ``+n`` if both are equal.
        """
        eps = 1e-4 * self.scale
        g0, _ = self.perpendicular_force(t, n_start)
        e_plus = self.surface(self.r0 + t * self.d + (n_start + eps) * self.m)
        e_minus = self.surface(self.r0 + t * self.d + (n_start - eps) * self.m)
        if abs(g0) * eps > 1e-9 * abs(e_plus - e_minus) and g0 != 0:
            direction = -float(np.sign(g0))
        else:
            direction = 1.0 if e_plus <= e_minus else -1.0
        a = n_start
        if direction * self.perpendicular_force(t, a)[0] >= 0:
            a = n_start + direction * eps
        step = 1e-3 * self.scale
        limit = 3.0 * max(np.linalg.norm(self.surface.a1), np.linalg.norm(self.surface.a2))
        while abs(a - n_start) < limit:
            b = a + direction * step
            ga = direction * self.perpendicular_force(t, a)[0]
            gb = direction * self.perpendicular_force(t, b)[0]
            if ga < 0 < gb:  # a minimum of e(n) lies between a and b
                root = brentq(
                    lambda x: self.perpendicular_force(t, x)[0], min(a, b), max(a, b), xtol=1e-15
                )
                p = self.relax(t, root) or self.point(t, root)
                if p.perpendicular_curvature >= 0:
                    return p
            a, step = b, min(step * 1.5, 0.02 * self.scale)
        raise InputError(
            "sliding path: no stable position found after a jump (the surface has no minimum across "
            "the pulling direction)"
        )


@dataclass(frozen=True)
class Jump:
    """A slip event: the tracked branch ended (fold) and the slider jumped at fixed ``t``."""

    t_angstrom: float
    xy_before: np.ndarray
    xy_after: np.ndarray
    energy_before: float
    energy_after: float


@dataclass(frozen=True)
class SlidingPath:
    """Samples of the zero-perpendicular-force path (surface energy units per area)."""

    direction_deg: float
    t_angstrom: np.ndarray  #: position along the pulling direction, from the start
    n_angstrom: np.ndarray  #: perpendicular coordinate relative to the start
    xy_angstrom: np.ndarray  #: (n, 2) Cartesian positions
    energy: np.ndarray  #: e along the path
    force: np.ndarray  #: de/dt, the resisting lateral force per area
    curvature: np.ndarray  #: Schur complement d²e/dt²
    perpendicular_curvature: np.ndarray  #: e_nn > 0
    branch: np.ndarray  #: branch index; increases by 1 after each jump
    jumps: tuple[Jump, ...]
    period_vector: np.ndarray | None  #: lattice vector from start to end if a period was completed
    frame: PathFrame = field(repr=False, compare=False)

    @property
    def periodic(self) -> bool:
        """Whether the path ended at a minimum equivalent to its start."""
        return self.period_vector is not None

    @property
    def length_angstrom(self) -> float:
        """Tracked length along the pulling direction (Å)."""
        return float(self.t_angstrom[-1])


def _period_candidates(
    surface: PeriodicSurface, d: np.ndarray, max_length: float
) -> list[np.ndarray]:
    vecs = lattice_vectors(surface.a1, surface.a2, 8)
    proj = vecs @ d
    keep = (proj > 1e-9) & (proj <= max_length * (1 + 1e-12))
    order = np.argsort(proj[keep], kind="stable")
    return list(vecs[keep][order])


def default_max_length(surface: PeriodicSurface, direction_deg: float) -> float:
    """Default tracking limit (Å): 4 × the longest primitive vector, or the lattice period along
    the direction if that is longer (up to index 8)."""
    th = np.deg2rad(direction_deg)
    d = np.array([np.cos(th), np.sin(th)])
    base = 4.0 * max(np.linalg.norm(surface.a1), np.linalg.norm(surface.a2))
    vecs = lattice_vectors(surface.a1, surface.a2, 8)
    norms = np.linalg.norm(vecs, axis=1)
    parallel = (np.abs(vecs @ d - norms) <= 1e-9 * np.maximum(norms, 1)) & (norms > 0)
    if np.any(parallel):
        base = max(base, 1.0001 * float(np.min(norms[parallel])))
    return base


def zero_perpendicular_force_path(
    surface: PeriodicSurface,
    direction_deg: float = 90.0,
    start_xy: np.ndarray | None = None,
    step_angstrom: float | None = None,
    max_length_angstrom: float | None = None,
) -> SlidingPath:
    """Track the zero-perpendicular-force path from the global minimum (see module docstring).

    Parameters
    ----------
    surface
        Periodic interpolant of the constant-pressure landscape.
    direction_deg
        Pulling direction, degrees from x (90 = y, the paper's choice).
    start_xy
        Start point (Å); default the global minimum of ``surface``.
    step_angstrom
        Largest step along ``d`` (default 1/400 of the shortest lattice vector);
        steps are halved automatically near folds.
    max_length_angstrom
        Stop here if no equivalent minimum was reached (default
        :func:`default_max_length`), with a :class:`PathNotPeriodicWarning`.
    """
    if not np.isfinite(direction_deg):
        raise InputError(f"direction_deg: expected a finite angle in degrees, got {direction_deg}")
    r0 = surface.global_minimum()[0] if start_xy is None else np.asarray(start_xy, float)
    frame = PathFrame(surface, r0, direction_deg)
    scale = frame.scale
    h_max = step_angstrom or scale / 400.0
    h_min = 1e-7 * scale
    max_len = max_length_angstrom or default_max_length(surface, direction_deg)
    candidates = _period_candidates(surface, frame.d, max_len)
    cand_t = [float(v @ frame.d) for v in candidates]

    first = frame.relax(0.0, 0.0)
    if first is None:
        raise InputError(
            "sliding path: the start point is not a stable minimum across the pulling direction"
        )
    pts = [first]
    branch = [0]
    jumps: list[Jump] = []
    period_vector = None
    t, h = 0.0, h_max
    ci = 0
    while t < max_len:
        while ci < len(cand_t) and cand_t[ci] <= t + 1e-12 * scale:
            ci += 1
        t_next = min(t + h, max_len)
        if ci < len(cand_t):
            t_next = min(t_next, cand_t[ci])
        prev = pts[-1]
        slope = 0.0
        if len(pts) > 1 and branch[-1] == branch[-2]:
            slope = (pts[-1].n - pts[-2].n) / (pts[-1].t - pts[-2].t)
        dt = t_next - t
        guess = prev.n + slope * dt
        p = frame.relax(t_next, guess, max_shift=max(4.0 * dt, 2e-3 * scale))
        if p is None:
            if dt > h_min:
                h = 0.5 * dt
                continue
            # fold: the branch ends here; jump to the next stable minimum in n
            t_jump = t + 4 * h_min
            after = frame.descend(t_jump, prev.n)
            jumps.append(Jump(t_jump, prev.xy, after.xy, prev.energy, after.energy))
            pts.append(after)
            branch.append(branch[-1] + 1)
            t, h = t_jump, h_max
            continue
        pts.append(p)
        branch.append(branch[-1])
        t = t_next
        h = min(2.0 * h, h_max) if dt >= h else h
        # one period done?
        for v, tv in zip(candidates, cand_t, strict=True):
            if abs(tv - t) <= 1e-9 * scale and abs(p.n - v @ frame.m) <= 1e-4 * scale:
                period_vector = np.asarray(v, float)
                break
        if period_vector is not None:
            break
    if period_vector is None:
        warnings.warn(
            f"sliding path at {direction_deg:g}°: no minimum equivalent to the start within "
            f"{max_len:.4g} Å; σ is computed over the tracked length",
            PathNotPeriodicWarning,
            stacklevel=2,
        )
    return SlidingPath(
        direction_deg=float(direction_deg),
        t_angstrom=np.array([q.t for q in pts]),
        n_angstrom=np.array([q.n for q in pts]),
        xy_angstrom=np.array([q.xy for q in pts]),
        energy=np.array([q.energy for q in pts]),
        force=np.array([q.force for q in pts]),
        curvature=np.array([q.curvature for q in pts]),
        perpendicular_curvature=np.array([q.perpendicular_curvature for q in pts]),
        branch=np.array(branch),
        jumps=tuple(jumps),
        period_vector=period_vector,
        frame=frame,
    )


# ---------------------------------------------------------------------------- string method


@dataclass(frozen=True)
class MinimumEnergyPath:
    """A converged string between two minima."""

    xy_angstrom: np.ndarray  #: (n_images, 2)
    arc_length_angstrom: np.ndarray
    energy: np.ndarray
    saddle_xy_angstrom: np.ndarray  #: highest saddle point (refined)
    barrier: float  #: saddle energy minus start energy (surface units)
    iterations: int
    converged: bool


def _redistribute(images: np.ndarray) -> np.ndarray:
    seg = np.linalg.norm(np.diff(images, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] <= 0:
        return images
    target = np.linspace(0.0, s[-1], len(images))
    keep = np.concatenate([[True], seg > 1e-14 * s[-1]])
    spline = CubicSpline(s[keep], images[keep], axis=0)
    return spline(target)


def minimum_energy_path(
    surface: PeriodicSurface,
    start_xy: np.ndarray,
    end_xy: np.ndarray,
    n_images: int = 41,
    max_iterations: int = 20000,
    tolerance: float = 1e-9,
    bow: float = 0.05,
) -> MinimumEnergyPath:
    """Minimum-energy path between two minima by the simplified string method.

    Interior images take explicit steepest-descent steps of size ``0.5/λ_max``
    (``λ_max`` the largest Hessian eigenvalue on the string, re-estimated every
    100 iterations), then are redistributed at equal arc length by a cubic
    spline; the endpoints stay fixed. The initial string is the chord bowed
    sideways by ``bow`` × the shortest lattice vector (a straight string on a
    mirror line would stay on the ridge). Converged when no image moves by more
    than ``tolerance`` × the shortest lattice vector in an iteration (at least
    20 iterations). The highest image is refined to the saddle by Newton on
    ``∇e = 0``, so the barrier does not depend on the number of images.
    """
    if n_images < 5:
        raise InputError(f"n_images: expected at least 5 images, got {n_images}")
    scale = float(min(np.linalg.norm(surface.a1), np.linalg.norm(surface.a2)))
    r_a, r_b = np.asarray(start_xy, float), np.asarray(end_xy, float)
    chord = r_b - r_a
    if not np.linalg.norm(chord) > 0:
        raise InputError("minimum_energy_path: start and end must differ")
    normal = np.array([-chord[1], chord[0]]) / np.linalg.norm(chord)
    u = np.linspace(0.0, 1.0, n_images)
    # a small bow so that a string lying on a symmetry line (a ridge) can leave it
    images = r_a + np.outer(u, chord) + np.outer(bow * scale * np.sin(np.pi * u), normal)
    images = _redistribute(images)
    step = None
    converged = False
    it = 0
    for it in range(1, max_iterations + 1):
        sv = surface.evaluate(images[1:-1])
        if step is None or it % 100 == 0:
            lam = float(np.max(np.linalg.eigvalsh(sv.hessian)))
            step = 0.5 / max(lam, 1e-300)
        moved = images.copy()
        moved[1:-1] -= step * sv.gradient
        moved = _redistribute(moved)
        change = float(np.max(np.linalg.norm(moved - images, axis=1)))
        images = moved
        if it >= 20 and change < tolerance * scale:
            converged = True
            break
    energy = surface(images)
    seg = np.linalg.norm(np.diff(images, axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    top = int(np.argmax(energy[1:-1])) + 1
    saddle = images[top].copy()
    for _ in range(30):
        sv = surface.evaluate(saddle)
        delta = np.linalg.solve(sv.hessian, sv.gradient)
        if np.linalg.norm(delta) > 0.1 * scale:
            saddle = images[top].copy()
            break
        saddle = saddle - delta
        if np.linalg.norm(delta) < 1e-13 * scale:
            break
    e_saddle = float(surface(saddle))
    return MinimumEnergyPath(
        xy_angstrom=images,
        arc_length_angstrom=arc,
        energy=energy,
        saddle_xy_angstrom=saddle,
        barrier=e_saddle - float(energy[0]),
        iterations=it,
        converged=converged,
    )
