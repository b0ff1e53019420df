"""The lateral grid's own estimate of its discretisation error in τ, σ_MSS and G_int.

Every analysis repeats the path and friction analysis (:mod:`.starts`, :mod:`.friction`) on a
**coarser grid taken from the same samples** and compares (Richardson-style):

* **sub-grid** (the default): every ``m``-th point along each axis, ``m`` the smallest
  divisor of the axis's point count that leaves at least :data:`MIN_COARSE_POINTS` (6×6 → the
  3×3 sub-grid through the origin, 12×12 → 6×6, 9×9 → 3×3); refinement ratio ``r = m``
  (the smaller of the two axes' when they differ);
* **low-pass** when an axis has no such divisor (7, 11: the approximant cells' prime grids):
  the exact interpolant with harmonics ``|k| <= h = max(1, (N − 1) // 4)`` only, the band of
  a ``2h + 1``-point grid; ``r = N / (2h + 1)``.

The coarse interpolant is symmetrised over the same shift-space group, pulled along the same
direction from the same start rule (near-degenerate minima, largest τ), with the same noise
floor, so the two numbers differ only by the grid. With ``q`` a quantity on the full grid and
``q_c`` on the coarse one, the estimate of the full grid's error is

.. math:: \\delta q = \\frac{q_c - q}{r^p - 1} \\approx q - q_\\infty

(signed: positive when the full grid lies above the converged value ``q_∞``), the
Richardson estimate for a quantity converging as ``q(h) = q_∞ + C h^p``. **Assumed order** ``p = 1``
(:data:`ASSUMED_ORDER`): τ and σ_MSS are first derivatives (or barriers over a period) of the
trigonometric interpolant; for a landscape whose curvature jumps (a relaxation that switches
branch, the least smooth ISPES whose lateral force is still continuous) the Fourier
coefficients fall as ``k^-3`` and the error of the interpolant's first derivative as ``h^1``.
Smoother landscapes converge faster (spectrally for an analytic one), so ``p = 1`` is on the
safe side: with ``r = 2`` the estimate is the whole coarse-to-fine change. When the grid has
a third level (a sub-grid of the sub-grid with at least 3 points: 12×12 → 6×6 → 3×3), the
**observed order** ``p_obs`` of τ at each load solves
``(q_c − q_cc)/(q − q_c) = r^p (r_2^p − 1)/(r^p − 1)``; the order used is ``p_obs`` clipped to
``[MIN_ORDER, ASSUMED_ORDER]`` (a slower observed convergence widens the estimate, a faster
one does not narrow it below the assumed order's).

**Resolution.** The grid resolves τ at a load when ``|δτ| <= UNRESOLVED_FRACTION · |τ|``
(5 %, :data:`UNRESOLVED_FRACTION`: the spread between starts above which the analysis already
calls τ start-dependent, ``TAU_SPREAD_RTOL`` of :mod:`.starts`, and the size of the 6×6 → 9×9
move of τ of the docs' Al(111) example that went unnoticed). Otherwise the grid that would
resolve it is estimated from the order used, ``N' = N · (|δτ| / (f |τ|))^{1/p}`` per axis,
rounded up to an even count (so that its own sub-grid estimate runs).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from flatcontact.analysis.periodic import PeriodicSurface
from flatcontact.analysis.starts import paths_from_near_degenerate_minima
from flatcontact.errors import InputError

#: Points per axis a coarse grid keeps at least (the periodic interpolant's first harmonic).
MIN_COARSE_POINTS = 3
#: Assumed convergence order of τ, σ_MSS and G_int in the grid spacing (module docstring).
ASSUMED_ORDER = 1.0
#: Lowest order used when the observed one is lower (a slower convergence than assumed).
MIN_ORDER = 0.5
#: |δτ| / |τ| above which the grid does not resolve τ (module docstring).
UNRESOLVED_FRACTION = 0.05
#: The quantities estimated, as ``friction.csv`` names them.
QUANTITIES = ("tau_mpa", "sigma_mss_mpa", "shear_stiffness_gpa_per_nm")
#: ``friction.csv`` column of each quantity's signed grid error.
ERROR_COLUMNS = {
    "tau_mpa": "tau_grid_error_mpa",
    "sigma_mss_mpa": "sigma_mss_grid_error_mpa",
    "shear_stiffness_gpa_per_nm": "shear_stiffness_grid_error_gpa_per_nm",
}


@dataclass(frozen=True)
class CoarseGrid:
    """How the coarse grid is taken from an ``shape`` grid (module docstring)."""

    method: str  #: "sub-grid" or "low-pass"
    points: tuple[int, int]  #: points per axis of the coarse grid (low-pass: 2h + 1)
    ratio: float  #: refinement ratio r (coarse spacing / fine spacing)
    step: tuple[int, int] | None = None  #: sub-grid: every step-th point
    max_harmonic: int | None = None  #: low-pass: the largest harmonic kept

    def describe(self) -> str:
        """``"3×3 sub-grid (every 2nd point)"`` or ``"low-pass to harmonic 2 (5-point band)"``."""
        if self.method == "sub-grid":
            return f"{self.points[0]}×{self.points[1]} sub-grid (every {_nth(self.step)} point)"
        return f"low-pass to harmonic {self.max_harmonic} ({self.points[0]}-point band)"


def _nth(step: tuple[int, int] | None) -> str:
    a, b = step or (1, 1)
    ordinal = {2: "2nd", 3: "3rd"}
    return ordinal.get(a, f"{a}th") if a == b else f"{a}th/{b}th"


def _divisor(n: int) -> int | None:
    """Smallest m >= 2 with n % m == 0 and n // m >= MIN_COARSE_POINTS, else None."""
    for m in range(2, n // MIN_COARSE_POINTS + 1):
        if n % m == 0:
            return m
    return None


def coarse_grid(shape: tuple[int, int]) -> CoarseGrid | None:
    """The coarse grid of an ``(N_a, N_b)`` grid, or None when it is too small for one
    (fewer than 2·MIN_COARSE_POINTS − 1 = 5 points along an axis without a divisor)."""
    n_a, n_b = int(shape[0]), int(shape[1])
    m_a, m_b = _divisor(n_a), _divisor(n_b)
    if m_a and m_b:
        return CoarseGrid("sub-grid", (n_a // m_a, n_b // m_b), float(min(m_a, m_b)), (m_a, m_b))
    h = max(1, (min(n_a, n_b) - 1) // 4)
    points = 2 * h + 1
    if min(n_a, n_b) <= points:
        return None
    return CoarseGrid("low-pass", (points, points), min(n_a, n_b) / points, max_harmonic=h)


def coarser(grid: CoarseGrid) -> CoarseGrid | None:
    """The sub-grid of a sub-grid (the third level), or None."""
    if grid.method != "sub-grid":
        return None
    inner = coarse_grid(grid.points)
    if inner is None or inner.method != "sub-grid":
        return None
    step = (grid.step[0] * inner.step[0], grid.step[1] * inner.step[1])
    return CoarseGrid("sub-grid", inner.points, inner.ratio, step)


def coarse_surface(
    values: np.ndarray, a1: np.ndarray, a2: np.ndarray, grid: CoarseGrid, group: list
) -> PeriodicSurface:
    """The interpolant of ``values`` on ``grid``, symmetrised over ``group`` like the full one."""
    if grid.method == "sub-grid":
        surf = PeriodicSurface(values[:: grid.step[0], :: grid.step[1]], a1, a2)
    else:
        surf = PeriodicSurface(values, a1, a2, max_harmonic=grid.max_harmonic)
    return surf.symmetrised(group)


def friction_on(
    surface: PeriodicSurface,
    direction_deg: float,
    tolerance_ev_per_a2: float,
    floor_ev_per_a2: float,
    max_length_angstrom: float | None,
) -> dict[str, float]:
    """τ, σ_MSS and G_int (``QUANTITIES``) of ``surface`` by the analysis's start rule; the
    coarse landscape's own warnings (a path that does not close, degenerate minima) are not
    passed on: they are about the comparison grid, and its difference is the result."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        starts, k = paths_from_near_degenerate_minima(
            surface,
            direction_deg,
            tolerance_ev_per_a2,
            min_barrier_ev_per_a2=floor_ev_per_a2,
            max_length_angstrom=max_length_angstrom,
        )
    fr = starts[k].friction
    return {q: float(getattr(fr, q)) for q in QUANTITIES}


def richardson(fine: float, coarse: float, ratio: float, order: float) -> float:
    """Signed estimate of the fine value's error ``fine − q_∞``, ``(coarse − fine)/(ratio^order
    − 1)`` (exact for ``q(h) = q_∞ + C h^order``)."""
    return (coarse - fine) / (ratio**order - 1.0)


def observed_order(
    fine: float, coarse: float, coarsest: float, ratio: float, ratio2: float
) -> float:
    """The order p with ``(coarse − coarsest)/(fine − coarse) = r^p (r2^p − 1)/(r^p − 1)``,
    NaN when the three values do not converge monotonically (no such p in (0.05, 20))."""
    d1, d2 = fine - coarse, coarse - coarsest
    if not (np.isfinite(d1) and np.isfinite(d2)) or d1 == 0 or d1 * d2 <= 0:
        return float("nan")
    target = math.log(d2 / d1)

    def g(p: float) -> float:
        return p * math.log(ratio) + math.log((ratio2**p - 1) / (ratio**p - 1)) - target

    lo, hi = 0.05, 20.0
    if g(lo) * g(hi) > 0:
        return float("nan")
    return float(brentq(g, lo, hi))


@dataclass(frozen=True)
class GridEstimate:
    """The grid's estimate of its own error at every load (module docstring).

    ``fine``, ``coarse``, ``coarsest``: quantity -> per-load values (``coarsest`` empty without
    a third level); ``order``: the order used per load; ``error``: quantity -> signed per-load
    estimate δq. ``unavailable``: why no estimate was made (then every array is NaN).
    """

    shape: tuple[int, int]
    grid: CoarseGrid | None
    p_gpa: np.ndarray
    fine: dict[str, np.ndarray]
    coarse: dict[str, np.ndarray]
    order: np.ndarray
    observed_order: np.ndarray
    error: dict[str, np.ndarray]
    coarsest_grid: CoarseGrid | None = None
    coarsest: dict[str, np.ndarray] = field(default_factory=dict)
    unavailable: str | None = None
    fraction: float = UNRESOLVED_FRACTION

    @property
    def relative_tau_error(self) -> np.ndarray:
        """|δτ| / |τ| per load (inf where τ = 0 and δτ ≠ 0)."""
        err, tau = np.abs(self.error["tau_mpa"]), np.abs(self.fine["tau_mpa"])
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.where(err == 0, 0.0, err / tau)

    @property
    def unresolved(self) -> np.ndarray:
        """Per load: the grid does not resolve τ (|δτ| > fraction · |τ|)."""
        rel = self.relative_tau_error
        return np.isfinite(self.error["tau_mpa"]) & (rel > self.fraction)

    def recommended_grid(self) -> tuple[int, int] | None:
        """The grid (points per axis) at which |δτ| falls to the fraction at every load, from
        the order used; None when the grid resolves τ (or no estimate was made)."""
        bad = self.unresolved
        if not np.any(bad):
            return None
        factor = max(
            float((rel / self.fraction) ** (1.0 / p))
            for rel, p in zip(self.relative_tau_error[bad], self.order[bad], strict=True)
        )
        factor = min(factor, 1e3) if np.isfinite(factor) else 1e3
        return tuple(int(2 * math.ceil(n * factor / 2)) for n in self.shape)

    def message(self) -> str | None:
        """One line when the grid does not resolve τ at some load, else None."""
        bad = np.flatnonzero(self.unresolved)
        if bad.size == 0:
            return None
        worst = int(bad[np.argmax(self.relative_tau_error[bad])])
        rec = self.recommended_grid()
        n_a, n_b = self.shape
        return (
            f"the {n_a}×{n_b} grid does not resolve τ: its estimated error (τ on the full grid "
            f"against the {self.grid.describe()}, order {self.order[worst]:.2g}) is "
            f"{100 * self.relative_tau_error[worst]:.3g} % of τ = "
            f"{self.fine['tau_mpa'][worst]:.4g} MPa at P = {self.p_gpa[worst]:g} GPa (above "
            f"{100 * self.fraction:g} % at {bad.size} of {self.p_gpa.size} loads); a grid of "
            f"about {rec[0]}×{rec[1]} would resolve it (scan.grid); the laws' and contact "
            "numbers' intervals carry this estimate as their grid part"
        )

    def to_json(self) -> dict:
        """``analyze.json["grid"]``: method, orders, threshold, per-load values and estimates."""

        def clean(values) -> list:
            return [float(v) if np.isfinite(v) else None for v in np.asarray(values, float)]

        rec = self.recommended_grid()
        doc = {
            "grid": list(self.shape),
            "method": None if self.grid is None else self.grid.method,
            "coarse": None if self.grid is None else self.grid.describe(),
            "ratio": None if self.grid is None else self.grid.ratio,
            "assumed_order": ASSUMED_ORDER,
            "order_rule": f"observed order of tau clipped to [{MIN_ORDER:g}, {ASSUMED_ORDER:g}] "
            "where the grid has a third level, else the assumed order",
            "estimate": "(coarse - fine) / (ratio**order - 1): signed, the fine value minus the "
            "converged one",
            "unresolved_fraction": self.fraction,
            "p_gpa": clean(self.p_gpa),
            "order": clean(self.order),
            "observed_order": clean(self.observed_order),
            "coarse_values": {q: clean(v) for q, v in self.coarse.items()},
            "errors": {ERROR_COLUMNS[q]: clean(v) for q, v in self.error.items()},
            "relative_tau_error": clean(self.relative_tau_error),
            "resolved": not bool(np.any(self.unresolved)),
            "recommended_grid": None if rec is None else list(rec),
            "unavailable": self.unavailable,
        }
        if self.coarsest_grid is not None:
            doc["coarsest"] = self.coarsest_grid.describe()
            doc["coarsest_values"] = {q: clean(v) for q, v in self.coarsest.items()}
        return doc


def estimate_grid_error(
    values_by_load: list[np.ndarray],
    a1: np.ndarray,
    a2: np.ndarray,
    group: list,
    p_gpa: np.ndarray,
    fine: dict[str, np.ndarray],
    direction_deg: float,
    tolerance_ev_per_a2: np.ndarray,
    floor_ev_per_a2: np.ndarray,
    max_length_angstrom: float | None = None,
) -> GridEstimate:
    """The grid's estimate of its error at every load (module docstring).

    Parameters
    ----------
    values_by_load
        The constant-pressure samples (eV/Å², any energy zero) per load, shape ``(N_a, N_b)``.
    a1, a2, group
        The lattice and the shift-space group the full interpolant was symmetrised over.
    p_gpa, fine
        The loads and the full grid's values (``QUANTITIES`` -> per-load arrays).
    direction_deg, tolerance_ev_per_a2, floor_ev_per_a2, max_length_angstrom
        The pulling direction, degeneracy tolerance, noise floor and tracking limit the full
        analysis used at each load.
    """
    shape = tuple(np.asarray(values_by_load[0]).shape)
    p = np.asarray(p_gpa, float)
    nan = {q: np.full(p.size, np.nan) for q in QUANTITIES}
    grid = coarse_grid(shape)
    if grid is None:
        return GridEstimate(
            shape, None, p, dict(fine), nan, np.full(p.size, np.nan), np.full(p.size, np.nan),
            dict(nan), unavailable=f"a {shape[0]}×{shape[1]} grid has no coarser grid of "
            f"{MIN_COARSE_POINTS} or more points per axis",
        )  # fmt: skip
    third = coarser(grid)
    levels = [grid] + ([third] if third is not None else [])
    out = [{q: np.full(p.size, np.nan) for q in QUANTITIES} for _ in levels]
    failed = []
    for i, values in enumerate(values_by_load):
        for level, store in zip(levels, out, strict=True):
            try:
                surf = coarse_surface(np.asarray(values, float), a1, a2, level, group)
                got = friction_on(
                    surf,
                    direction_deg,
                    float(tolerance_ev_per_a2[i]),
                    float(floor_ev_per_a2[i]),
                    max_length_angstrom,
                )
            except (InputError, ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
                # a coarse landscape may have no minimum or no path: named, not raised
                if level is grid:
                    failed.append(f"P = {p[i]:g} GPa: {type(exc).__name__}: {exc}")
                continue
            for q in QUANTITIES:
                store[q][i] = got[q]
    coarse = out[0]
    coarsest = out[1] if third is not None else {}
    observed = np.full(p.size, np.nan)
    if third is not None:
        observed = np.array(
            [
                observed_order(
                    fine["tau_mpa"][i],
                    coarse["tau_mpa"][i],
                    coarsest["tau_mpa"][i],
                    grid.ratio,
                    third.ratio,
                )
                for i in range(p.size)
            ]
        )
    order = np.where(
        np.isfinite(observed), np.clip(observed, MIN_ORDER, ASSUMED_ORDER), ASSUMED_ORDER
    )
    error = {
        q: np.array(
            [richardson(fine[q][i], coarse[q][i], grid.ratio, order[i]) for i in range(p.size)]
        )
        for q in QUANTITIES
    }
    return GridEstimate(
        shape,
        grid,
        p,
        {q: np.asarray(fine[q], float) for q in QUANTITIES},
        coarse,
        order,
        observed,
        error,
        coarsest_grid=third,
        coarsest=coarsest,
        unavailable=("the coarse grid has no sliding path at " + "; ".join(failed))
        if failed
        else None,
    )
