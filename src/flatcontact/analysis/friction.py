"""Shear strength, MSS friction and interfacial shear stiffness along a sliding path.

Conventions (paper, Fig. 2 and the equation for σ):

- energies are per area of the interface (eV/Å² in, meV/Å² out); the force
  along the path ``f(t) = de/dt`` is the lateral force per area that resists
  the pull (positive while the slider climbs), reported as a stress in MPa;
- **shear stiffness** ``G_int = d²e/dt²`` at the start (the global minimum):
  the initial slope of ``f(t)``. Along the relaxed path this is the Schur
  complement ``e_tt - e_tn²/e_nn`` of the Hessian, evaluated analytically.
  Reported in GPa/nm (stress per displacement);
- **shear strength** ``τ``: the largest ``f`` before the slider leaves the
  initial minimum, i.e. on the way from the start to the first barrier top,
  or to the first jump (fold) if the branch ends before a top. The maximum is
  located where ``d f/dt = 0`` by root finding on the relaxed branch. (When
  inequivalent minima are degenerate within the noise, the analysis computes
  this from each of them and reports the largest: :mod:`.starts`);
- **period shear strength** ``τ_period``: the largest ``f`` anywhere on one
  period of the path: the pull needed for sustained sliding. It equals ``τ``
  when the first barrier out of the global minimum is the hardest to climb,
  and exceeds it otherwise (a low first barrier followed by a higher one, as
  coarse or asymmetric landscapes give). Always ``σ ≤ τ_period``, because each
  barrier height is the integral of ``f`` over a climb shorter than the
  distance between minima; ``τ`` (the paper's definition) can fall below ``σ``;
- **MSS friction** ``σ = ΣΔU_i / ΣΔy_i``: ``ΔU_i`` the barrier heights, from
  each minimum to the next maximum in the pulling direction (a fold counts as
  the maximum of its climb), ``ΣΔy_i`` the distance between successive minima
  over one period, i.e. the period of the path along the pulling direction.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from flatcontact.analysis.path import SlidingPath
from flatcontact.foundation import units

#: stiffness eV/Å⁴ (stress per length) -> GPa/nm
EV_PER_A4_TO_GPA_PER_NM = units.EV_PER_A3_TO_GPA / units.ANGSTROM_TO_NM


@dataclass(frozen=True)
class Barrier:
    """One climb along the path: from a minimum to the next maximum (eV/Å², Å)."""

    t_min_angstrom: float
    energy_min: float
    t_max_angstrom: float
    energy_max: float
    at_jump: bool  #: the maximum is a fold: the slider jumped from there

    @property
    def height(self) -> float:
        """ΔU_i = energy_max - energy_min (eV/Å²)."""
        return self.energy_max - self.energy_min


@dataclass(frozen=True)
class FrictionResult:
    """Friction quantities of one sliding path (energies per area in eV/Å²)."""

    tau_ev_per_a3: float
    tau_position_angstrom: float
    tau_limited_by: str  #: "barrier top", "jump" or "path end"
    tau_period_ev_per_a3: float  #: largest resisting force per area over the whole path
    tau_period_position_angstrom: float
    sigma_ev_per_a3: float
    barriers: tuple[Barrier, ...]
    minima_t_angstrom: tuple[float, ...]
    sliding_distance_angstrom: float  #: ΣΔy_i used for σ
    shear_stiffness_ev_per_a4: float

    @property
    def tau_mpa(self) -> float:
        """Shear strength τ (MPa)."""
        return self.tau_ev_per_a3 * units.EV_PER_A3_TO_MPA

    @property
    def tau_period_mpa(self) -> float:
        """Period shear strength τ_period (MPa): the largest force over the whole path."""
        return self.tau_period_ev_per_a3 * units.EV_PER_A3_TO_MPA

    @property
    def sigma_mss_mpa(self) -> float:
        """MSS friction σ (MPa)."""
        return self.sigma_ev_per_a3 * units.EV_PER_A3_TO_MPA

    @property
    def shear_stiffness_gpa_per_nm(self) -> float:
        """Interfacial shear stiffness (GPa/nm)."""
        return self.shear_stiffness_ev_per_a4 * EV_PER_A4_TO_GPA_PER_NM


def _refine(path: SlidingPath, i: int, attr: str) -> tuple[float, float, float]:
    """Root of ``attr`` (force or curvature) on the relaxed branch between samples i-1 and i.

    Returns ``(t, energy, force)`` at the root.
    """
    frame = path.frame
    t_a, t_b = path.t_angstrom[i - 1], path.t_angstrom[i]
    n_a, n_b = path.n_angstrom[i - 1], path.n_angstrom[i]

    def state(t: float):
        n_guess = n_a + (n_b - n_a) * (t - t_a) / (t_b - t_a)
        return frame.relax(t, n_guess)

    def value(t: float) -> float:
        p = state(t)
        if p is None:
            raise ValueError("branch lost")
        return getattr(p, attr)

    try:
        t = brentq(value, t_a, t_b, xtol=1e-13 * frame.scale, rtol=1e-14)
        p = state(t)
        assert p is not None
        return p.t, p.energy, p.force
    except (ValueError, AssertionError):
        # fall back to linear interpolation of the samples
        ya, yb = _samples(path, attr)[i - 1], _samples(path, attr)[i]
        w = ya / (ya - yb) if ya != yb else 0.5
        t = t_a + w * (t_b - t_a)
        e = path.energy[i - 1] + w * (path.energy[i] - path.energy[i - 1])
        f = path.force[i - 1] + w * (path.force[i] - path.force[i - 1])
        return float(t), float(e), float(f)


def _samples(path: SlidingPath, attr: str) -> np.ndarray:
    """Sampled ``force`` or ``curvature`` of the path."""
    return path.force if attr == "force" else path.curvature


def _largest_force(path: SlidingPath, f: np.ndarray, stop: int) -> tuple[float, float, bool]:
    """Largest force over samples ``0..stop``, refined where the curvature changes sign.

    Returns ``(force, t, at_stop)``; ``at_stop`` is true when the maximum is the last
    sample considered (e.g. a fold, where the branch ends).
    """
    t = path.t_angstrom
    j = int(np.argmax(f[: stop + 1]))
    force, t_max = float(f[j]), float(t[j])
    if 0 < j < stop and path.curvature[j] * path.curvature[j + 1] <= 0:
        t_max, _, force = _refine(path, j + 1, "curvature")
    elif 0 < j < stop and path.curvature[j - 1] * path.curvature[j] <= 0:
        t_max, _, force = _refine(path, j, "curvature")
    return force, t_max, j == stop


def merge_shallow_minima(
    events: list[tuple[str, float, float, bool]], start_energy: float, min_barrier: float
) -> list[tuple[str, float, float, bool]]:
    """Drop minima whose dip is below ``min_barrier``, with the lower of their two maxima.

    ``events`` are ``(kind, t, energy, at_jump)`` in path order after the start
    minimum (energy ``start_energy``). The dip of a minimum is the smaller of the
    drop from the maximum before it and the climb to the maximum after it (the
    climb alone for a last minimum without a following maximum). The shallowest
    dip is removed first, repeatedly (persistence simplification): between two
    maxima it goes with the lower of them, so minima and maxima keep alternating;
    a minimum at the end of the list goes alone. ``min_barrier <= 0`` returns the events unchanged.
    """
    if not min_barrier > 0:
        return list(events)
    seq = [("min", 0.0, float(start_energy), False), *events]
    while True:
        best, best_dip = None, min_barrier
        for i in range(1, len(seq)):
            if seq[i][0] != "min":
                continue
            before = seq[i - 1][2] - seq[i][2] if seq[i - 1][0] == "max" else np.inf
            after = (
                seq[i + 1][2] - seq[i][2] if i + 1 < len(seq) and seq[i + 1][0] == "max" else np.inf
            )
            dip = min(before, after)
            if dip < best_dip:
                best, best_dip = i, dip
        if best is None:
            return seq[1:]
        both = [j for j in (best - 1, best + 1) if j < len(seq) and seq[j][0] == "max"]
        # between two maxima: merge them, keeping the higher; at an end: drop the minimum only
        drop = min(both, key=lambda j: seq[j][2]) if len(both) == 2 else best
        seq = [ev for j, ev in enumerate(seq) if j not in (best, drop)]


def friction_along_path(path: SlidingPath, min_barrier_ev_per_a2: float = 0.0) -> FrictionResult:
    """τ, σ_MSS and the shear stiffness of a zero-perpendicular-force path.

    The path's surface must be an energy per area in eV/Å² (then forces are
    eV/Å³ and the stiffness eV/Å⁴). See the module docstring for definitions.

    Parameters
    ----------
    path
        The sliding path.
    min_barrier_ev_per_a2
        Noise floor (eV/Å²): a minimum whose dip is shallower than this is not a
        minimum (:func:`merge_shallow_minima`), so it neither splits a barrier in
        σ_MSS nor ends the climb that sets τ. The analysis passes
        ``BARRIER_NOISE_FACTOR`` × the energy-noise estimate (:mod:`.noise`).
    """
    t, e = path.t_angstrom, path.energy
    f = path.force.copy()
    f[0] = 0.0  # the start is the minimum
    if path.periodic:
        f[-1] = 0.0  # the end is the start's equivalent
    branch = path.branch
    # events in order: ("min"|"max", t, energy, at_jump)
    events: list[tuple[str, float, float, bool]] = []
    for i in range(1, len(t)):
        if branch[i] != branch[i - 1]:  # a jump between i-1 and i
            if f[i - 1] > 0:
                events.append(("max", t[i - 1], e[i - 1], True))
            if f[i] > 0:
                events.append(("min", t[i], e[i], True))
            continue
        if f[i - 1] > 0 >= f[i]:
            tt, ee, _ = _refine(path, i, "force")
            events.append(("max", tt, ee, False))
        elif f[i - 1] < 0 <= f[i] and not (path.periodic and i == len(t) - 1):
            tt, ee, _ = _refine(path, i, "force")
            events.append(("min", tt, ee, False))

    events = merge_shallow_minima(events, float(e[0]), min_barrier_ev_per_a2)

    # τ: largest force before the first maximum (barrier top or fold)
    first_max = next((ev for ev in events if ev[0] == "max"), None)
    if first_max is None:
        stop = len(t) - 1
        limited = "path end"
    else:
        stop = int(np.searchsorted(t, first_max[1], side="right")) - 1
        limited = "jump" if first_max[3] else "barrier top"
    tau, tau_t, at_stop = _largest_force(path, f, stop)
    if at_stop and first_max is not None and first_max[3]:
        limited = "jump"
    tau_period, tau_period_t, _ = _largest_force(path, f, len(t) - 1)

    # σ: barriers from each minimum to the next maximum
    barriers: list[Barrier] = []
    minima = [0.0]
    current = (0.0, float(e[0]))
    for kind, tt, ee, jump in events:
        if kind == "min":
            current = (float(tt), float(ee))
            minima.append(float(tt))
        elif current is not None:
            barriers.append(Barrier(current[0], current[1], float(tt), float(ee), jump))
            current = None
    if path.periodic:
        distance = path.length_angstrom
        used = barriers
    else:
        last_min = minima[-1]
        used = [b for b in barriers if b.t_max_angstrom <= last_min]
        distance = last_min
    sigma = sum(b.height for b in used) / distance if used and distance > 0 else float("nan")
    return FrictionResult(
        tau_ev_per_a3=tau,
        tau_position_angstrom=tau_t,
        tau_limited_by=limited,
        tau_period_ev_per_a3=tau_period,
        tau_period_position_angstrom=tau_period_t,
        sigma_ev_per_a3=float(sigma),
        barriers=tuple(barriers),
        minima_t_angstrom=tuple(minima),
        sliding_distance_angstrom=float(distance),
        shear_stiffness_ev_per_a4=float(path.curvature[0]),
    )
