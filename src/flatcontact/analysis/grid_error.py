"""The lateral grid's own estimate of its discretisation error in τ, σ_MSS and G_int.

Every analysis repeats the path and friction analysis (:mod:`.starts`, :mod:`.friction`: the
same pulling direction, start rule, noise floor and shift-space symmetrisation) on other
interpolants **of the same samples** and takes the difference as the grid's error. Three
estimators, each a signed per-load series per quantity:

* ``interpolant``: the symmetrised interpolant on the zone-folded frequency set against the
  grid's own square set (:func:`other_interpolant`). Both reproduce every sample and differ
  only between them, where the grid says nothing; their difference is a floor of the error.
* ``last shell``: the interpolant without its outermost harmonic shell (``|k| <= h − 1`` with
  ``h`` the grid's Nyquist harmonic; :func:`last_shell_surface`), the spectral methods'
  a-posteriori indicator: for a landscape whose Fourier coefficients fall geometrically the
  error of a band is of the order of its last shell's contribution.
* ``sub-grid``, where the grid has one of at least :data:`MIN_SUBGRID_POINTS` points per axis
  (every ``m``-th point, ``m`` the smallest divisor that leaves that many: 8×8 → 4×4, 12×12 →
  6×6): the analysis on the sub-grid ``q_c`` against the full grid ``q``, Richardson-scaled,

  .. math:: \\delta q = \\frac{q_c - q}{r^p - 1} \\approx q - q_\\infty

  (``r = m``; signed: positive when the full grid lies above the converged ``q_∞``; exact for
  ``q(h) = q_∞ + C h^p``). **Assumed order** ``p = 1`` (:data:`ASSUMED_ORDER`): τ and σ_MSS
  are first derivatives (or barriers over a period) of the trigonometric interpolant; for a
  landscape whose curvature jumps (a relaxation that switches branch, the least smooth ISPES
  whose lateral force is still continuous) the coefficients fall as ``k^-3`` and the error of
  the first derivative as ``h^1``; smoother landscapes converge faster, so ``p = 1`` is on the
  safe side. With a third level (a sub-grid of the sub-grid with at least 3 points: 12×12 →
  6×6 → 3×3) the **observed order** ``p_obs`` of τ per load solves
  ``(q_c − q_cc)/(q − q_c) = r^p (r_2^p − 1)/(r^p − 1)``; the order used is ``p_obs`` clipped to
  ``[MIN_ORDER, ASSUMED_ORDER]``.

  A 3×3 sub-grid (of 6×6 or 9×9) is not used: on real landscapes it is far from the asymptotic
  range, either way (measured: Cu(111) EAM 6×6, τ 29 % off on the 3×3 sub-grid against 0.3 %
  between 6×6 and 12×12; Al(111) 6×6, 4.5 % against 6 % between 6×6 and 9×9).

For each quantity the estimator with the largest rms over the loads is used (one estimator per
quantity, so the per-load series the laws are fitted to is consistent); at a load where it has
no value (its path abandoned there) the largest in magnitude of the others' at that load is
used (:func:`fill_missing`, recorded as ``fallback``), so one failed path does not take the
grid part out of the laws' intervals. Measured on the docs'
Al(111) example (Zhou EAM, at the CIF's 4.05 Å): 6×6, τ(0) = 2059 MPa, interpolant 170, last shell 333 MPa
(used: 16 %, "does not resolve"), against τ(9×9) − τ(6×6) = −122 MPa; 9×9: interpolant 15,
last shell 9 MPa (0.75 %). Cu(111) 6×6: interpolant 15, last shell 40 MPa (1 %) against 6–11 MPa
to 12×12. **Limit:** a landscape whose harmonics beyond the grid's Nyquist are large (aliased
into the grid's own band) can escape the first two estimators on a grid with no usable
sub-grid: a k^-3 synthetic landscape on 6×6 is 10 % off with an estimate of 0.8 %
(tests/analysis/test_grid_error.py); on 8×8 and finer the sub-grid catches it.

**Resolution.** The grid resolves τ at a load when ``|δτ| <= UNRESOLVED_FRACTION · |τ|``
(5 %, :data:`UNRESOLVED_FRACTION`: the spread between starts above which the analysis already
calls τ start-dependent, ``TAU_SPREAD_RTOL`` of :mod:`.starts`, and the size of the 6×6 → 9×9
move of τ of the docs' Al(111) example that went unnoticed). Otherwise the grid that would
resolve it is estimated from the order used, ``N' = N · (|δτ| / (f |τ|))^{1/p}`` per axis,
rounded up to an even count.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import brentq

from flatcontact.analysis.periodic import PeriodicSurface
from flatcontact.analysis.starts import paths_from_near_degenerate_minima
from flatcontact.foundation.errors import InputError

#: Points per axis a sub-grid must keep to be used (a 3×3 one is pre-asymptotic: docstring).
MIN_SUBGRID_POINTS = 4
#: Points per axis of the third level (it only sets the observed order).
MIN_THIRD_LEVEL_POINTS = 3
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
#: The estimators, in the order of preference on ties.
ESTIMATORS = ("sub-grid", "last shell", "interpolant")


@dataclass(frozen=True)
class CoarseGrid:
    """A sub-grid: every ``step``-th point from ``offset`` (module docstring)."""

    points: tuple[int, int]  #: points per axis of the sub-grid
    ratio: float  #: refinement ratio r (sub-grid spacing / grid spacing)
    step: tuple[int, int]  #: every step-th point along each axis
    offset: tuple[int, int] = (0, 0)  #: index of its first point on each axis

    def describe(self) -> str:
        """``"6×6 sub-grid (every 2nd point)"``."""
        a, b = self.step
        nth = {2: "2nd", 3: "3rd"}.get(a, f"{a}th") if a == b else f"{a}th/{b}th"
        return f"{self.points[0]}×{self.points[1]} sub-grid (every {nth} point)"


def _divisor(n: int, min_points: int) -> int | None:
    """Smallest m >= 2 with n % m == 0 and n // m >= min_points, else None."""
    for m in range(2, n // min_points + 1):
        if n % m == 0:
            return m
    return None


def coarse_grid(shape: tuple[int, int], min_points: int = MIN_SUBGRID_POINTS) -> CoarseGrid | None:
    """The sub-grid of an ``(N_a, N_b)`` grid with at least ``min_points`` per axis, or None."""
    n_a, n_b = int(shape[0]), int(shape[1])
    m_a, m_b = _divisor(n_a, min_points), _divisor(n_b, min_points)
    if not (m_a and m_b):
        return None
    return CoarseGrid((n_a // m_a, n_b // m_b), float(min(m_a, m_b)), (m_a, m_b))


def coarser(grid: CoarseGrid) -> CoarseGrid | None:
    """The sub-grid of a sub-grid (the third level, at least MIN_THIRD_LEVEL_POINTS), or None."""
    inner = coarse_grid(grid.points, MIN_THIRD_LEVEL_POINTS)
    if inner is None:
        return None
    step = (grid.step[0] * inner.step[0], grid.step[1] * inner.step[1])
    return CoarseGrid(inner.points, inner.ratio, step)


def coarse_surface(
    values: np.ndarray, a1: np.ndarray, a2: np.ndarray, grid: CoarseGrid, group: list
) -> PeriodicSurface:
    """The interpolant of ``values`` on the sub-grid, symmetrised over ``group`` like the full one.

    A sub-grid with an offset ``o`` starts at the fractional shift ``d = o/N``: its
    interpolant is the landscape translated by ``d`` (τ, σ_MSS and G_int do not depend on
    where the cell starts), and each operation ``s ↦ M s + t`` of the group acts on it as
    ``s ↦ M s + t + (M − 1) d``."""
    (oa, ob), (ma, mb) = grid.offset, grid.step
    surf = PeriodicSurface(values[oa::ma, ob::mb], a1, a2)
    d = np.array([oa / values.shape[0], ob / values.shape[1]])
    moved = [
        (np.asarray(m, float), np.asarray(t, float) + (np.asarray(m, float) - np.eye(2)) @ d)
        for m, t in group
    ]
    return surf.symmetrised(moved)


def last_shell_surface(
    values: np.ndarray, a1: np.ndarray, a2: np.ndarray, group: list
) -> PeriodicSurface:
    """The symmetrised interpolant without the grid's outermost harmonic shell: harmonics up to
    ``h − 1``, ``h = min(N_a, N_b) // 2`` the Nyquist harmonic of the shorter axis."""
    h = min(values.shape) // 2
    return PeriodicSurface(values, a1, a2, max_harmonic=max(h - 1, 1)).symmetrised(group)


#: Surface evaluations one comparison analysis (one load) may spend: a path on a knife-edge
#: landscape can halve its step towards the floor for minutes (measured: an 8×8 three-cosine
#: grid's last-shell interpolant pulled along y), while the examples' analyses take about 1700
#: per load (Al(111), MoS2 6×6). Past it the estimate is NaN at that load, named.
EVALUATION_BUDGET = 20_000


class BudgetExceeded(ArithmeticError):
    """A comparison analysis spent :data:`EVALUATION_BUDGET` surface evaluations."""


class _Budgeted(PeriodicSurface):
    """The same interpolant, counting its evaluations (:data:`EVALUATION_BUDGET`)."""

    left: int

    def evaluate(self, xy):
        self.left -= 1
        if self.left < 0:
            raise BudgetExceeded(
                f"the path took more than {EVALUATION_BUDGET} evaluations (abandoned)"
            )
        return super().evaluate(xy)


def _budgeted(surface: PeriodicSurface) -> PeriodicSurface:
    out = object.__new__(_Budgeted)
    out.__dict__.update(surface.__dict__)
    out.left = EVALUATION_BUDGET
    return out


def friction_on(
    surface: PeriodicSurface,
    direction_deg: float,
    tolerance_ev_per_a2: float,
    floor_ev_per_a2: float,
    max_length_angstrom: float | None,
) -> dict[str, float]:
    """τ, σ_MSS and G_int (``QUANTITIES``) of ``surface`` by the analysis's start rule; the
    coarse landscape's own warnings (a path that does not close, degenerate minima) are not
    passed on: they are about the comparison grid, and its difference is the result. At most
    :data:`EVALUATION_BUDGET` evaluations (:class:`BudgetExceeded`)."""
    surface = _budgeted(surface)
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


def other_interpolant(values: np.ndarray, a1: np.ndarray, a2: np.ndarray, group: list):
    """Another interpolant of the same samples: the grid's own square frequency set when the
    analysis symmetrises (``group`` of more than the identity), else the zone-folded one
    (:meth:`.PeriodicSurface.zone_folded`). Both reproduce every sample; they differ only
    between the samples, where the grid says nothing."""
    surf = PeriodicSurface(values, a1, a2)
    return surf if len(group) > 1 else surf.zone_folded()


def fill_missing(
    chosen: str, estimates: dict[str, np.ndarray]
) -> tuple[np.ndarray, list[str | None]]:
    """``estimates[chosen]`` with each non-finite load filled by the largest-magnitude finite
    estimate of another estimator at that load (NaN where none has one), and per load the
    estimator filled from (None where the chosen one's own value is kept or none exists)."""
    out = np.array(estimates[chosen], dtype=float)
    used: list[str | None] = [None] * out.size
    for i in np.flatnonzero(~np.isfinite(out)):
        others = [
            (abs(float(v[i])), name)
            for name, v in estimates.items()
            if name != chosen and np.isfinite(v[i])
        ]
        if others:
            _, name = max(others)
            out[i], used[i] = float(estimates[name][i]), name
    return out, used


def _rms(values: np.ndarray) -> float:
    v = np.asarray(values, float)
    v = v[np.isfinite(v)]
    return float(np.sqrt(np.mean(v * v))) if v.size else -1.0


@dataclass(frozen=True)
class GridEstimate:
    """The grid's estimate of its own error at every load (module docstring).

    ``fine``: quantity -> the full grid's per-load values; ``values``: estimator -> quantity ->
    the per-load values it compares with (the sub-grid's, the interpolant's without the last
    shell, the other interpolant's); ``estimates``: estimator -> quantity -> signed per-load
    δq; ``error``, ``source``: per quantity the estimate used and its estimator (the largest in
    rms over the loads). ``order``: the Richardson order per load (the sub-grid's; the assumed
    one for the recommendation otherwise). ``unavailable``: what could not be computed, why.
    """

    shape: tuple[int, int]
    grid: CoarseGrid | None
    p_gpa: np.ndarray
    fine: dict[str, np.ndarray]
    values: dict[str, dict[str, np.ndarray]]
    estimates: dict[str, dict[str, np.ndarray]]
    error: dict[str, np.ndarray]
    source: dict[str, str]
    order: np.ndarray
    observed_order: np.ndarray
    coarsest_grid: CoarseGrid | None = None
    coarsest: dict[str, np.ndarray] = field(default_factory=dict)
    unavailable: str | None = None
    fraction: float = UNRESOLVED_FRACTION
    fallback: dict[str, list[str | None]] = field(default_factory=dict)

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

    def describe_source(self, quantity: str = "tau_mpa") -> str:
        """How the estimate of ``quantity`` used was made, in words."""
        src = self.source.get(quantity)
        if src == "sub-grid":
            return f"against the {self.grid.describe()}, Richardson-scaled"
        if src == "last shell":
            return "against the interpolant without its outermost harmonic shell"
        return "between two interpolants of the same samples"

    def message(self) -> str | None:
        """One line when the grid does not resolve τ at some load, else None."""
        bad = np.flatnonzero(self.unresolved)
        if bad.size == 0:
            return None
        worst = int(bad[np.argmax(self.relative_tau_error[bad])])
        rec = self.recommended_grid()
        n_a, n_b = self.shape
        return (
            f"the {n_a}×{n_b} grid does not resolve τ: its estimated error (τ "
            f"{self.describe_source()}) is {100 * self.relative_tau_error[worst]:.3g} % of τ = "
            f"{self.fine['tau_mpa'][worst]:.4g} MPa at P = {self.p_gpa[worst]:g} GPa (above "
            f"{100 * self.fraction:g} % at {bad.size} of {self.p_gpa.size} loads); a grid of "
            f"about {rec[0]}×{rec[1]} would resolve it (scan.grid; estimated at order "
            f"{self.order[worst]:.2g}); the laws' and contact numbers' intervals carry this "
            "estimate as their grid part"
        )

    def to_json(self) -> dict:
        """``analyze.json["grid"]``: estimators, orders, threshold, per-load values, estimates."""

        def clean(values) -> list:
            return [float(v) if np.isfinite(v) else None for v in np.asarray(values, float)]

        rec = self.recommended_grid()
        doc = {
            "grid": list(self.shape),
            "sub_grid": None if self.grid is None else self.grid.describe(),
            "ratio": None if self.grid is None else self.grid.ratio,
            "assumed_order": ASSUMED_ORDER,
            "order_rule": f"sub-grid: observed order of tau clipped to [{MIN_ORDER:g}, "
            f"{ASSUMED_ORDER:g}] where the grid has a third level, else the assumed order",
            "estimators": {
                "sub-grid": "(sub-grid - full) / (ratio**order - 1), where a sub-grid of "
                f">= {MIN_SUBGRID_POINTS} points per axis exists",
                "last shell": "full - (full without its outermost harmonic shell)",
                "interpolant": "full (symmetrised, zone-folded) - (the grid's own square set)",
            },
            "rule": "per quantity the estimator with the largest rms over the loads; signed; "
            "at a load where it has no value, the largest in magnitude of the others' there "
            "(fallback: the estimator used per load, null where the rule's own)",
            "source": dict(self.source),
            "fallback": {ERROR_COLUMNS[q]: list(v) for q, v in self.fallback.items()},
            "unresolved_fraction": self.fraction,
            "p_gpa": clean(self.p_gpa),
            "order": clean(self.order),
            "observed_order": clean(self.observed_order),
            "values": {e: {q: clean(v) for q, v in d.items()} for e, d in self.values.items()},
            "estimates": {
                e: {ERROR_COLUMNS[q]: clean(v) for q, v in d.items()}
                for e, d in self.estimates.items()
            },
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


def _friction_series(surfaces, p, direction_deg, tol, floor, max_length, failed, what):
    """τ, σ_MSS, G_int per load on ``surfaces`` (a callable of the load index); a load whose
    landscape has no minimum or no path is NaN and named in ``failed``."""
    store = {q: np.full(p.size, np.nan) for q in QUANTITIES}
    for i in range(p.size):
        try:
            got = friction_on(
                surfaces(i), direction_deg, float(tol[i]), float(floor[i]), max_length
            )
        except (InputError, ValueError, ArithmeticError, np.linalg.LinAlgError) as exc:
            if failed is not None:
                failed.append(f"{what} at P = {p[i]:g} GPa: {type(exc).__name__}: {exc}")
            continue
        for q in QUANTITIES:
            store[q][i] = got[q]
    return store


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
    values = [np.asarray(v, float) for v in values_by_load]
    shape = tuple(values[0].shape)
    p = np.asarray(p_gpa, float)
    fine = {q: np.asarray(fine[q], float) for q in QUANTITIES}
    args = (p, direction_deg, tolerance_ev_per_a2, floor_ev_per_a2, max_length_angstrom)
    failed: list[str] = []
    compared = {
        "interpolant": _friction_series(
            lambda i: other_interpolant(values[i], a1, a2, group), *args, failed, "interpolant"
        ),
        "last shell": _friction_series(
            lambda i: last_shell_surface(values[i], a1, a2, group), *args, failed, "last shell"
        ),
    }
    estimates = {e: {q: fine[q] - v[q] for q in QUANTITIES} for e, v in compared.items()}
    grid = coarse_grid(shape)
    third = None if grid is None else coarser(grid)
    coarsest: dict[str, np.ndarray] = {}
    observed = np.full(p.size, np.nan)
    if grid is not None:
        coarse = _friction_series(
            lambda i: coarse_surface(values[i], a1, a2, grid, group), *args, failed, "sub-grid"
        )
        compared["sub-grid"] = coarse
        if third is not None:
            coarsest = _friction_series(
                lambda i: coarse_surface(values[i], a1, a2, third, group), *args, None, ""
            )
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
    if grid is not None:
        estimates["sub-grid"] = {
            q: np.array(
                [
                    richardson(fine[q][i], compared["sub-grid"][q][i], grid.ratio, order[i])
                    for i in range(p.size)
                ]
            )
            for q in QUANTITIES
        }
    error, source, fallback = {}, {}, {}
    for q in QUANTITIES:
        best = max(
            (e for e in ESTIMATORS if e in estimates),
            key=lambda e: (_rms(estimates[e][q]), -ESTIMATORS.index(e)),
        )
        source[q] = best
        error[q], fallback[q] = fill_missing(best, {e: estimates[e][q] for e in estimates})
    return GridEstimate(
        shape,
        grid,
        p,
        fine,
        compared,
        estimates,
        error,
        source,
        order,
        observed,
        coarsest_grid=third,
        coarsest=coarsest,
        unavailable="; ".join(failed) if failed else None,
        fallback=fallback,
    )
