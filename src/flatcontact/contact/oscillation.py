"""Load-controlled lateral oscillation of the modified Mindlin contact (paper, Fig. 5b).

The tip is driven by Q(t) = Q_max sin θ. Quasi-statically u(t) = u(Q(t)) on the
rising (loading) branch of Q(u), u(Q) = the smallest u with Q(u) = Q (closed
form, :func:`flatcontact.contact.mindlin.displacement_on_rising_branch`). The
paper's averages over a quarter cycle are

    ⟨u⟩² = (2/π) ∫0^{π/2} u²(Q_max sin θ) dθ,      ⟨Q⟩² = (2/π) ∫ Q_max² sin²θ dθ = Q_max²/2,

and the lateral stiffness is k = d⟨Q⟩/d⟨u⟩ along the family of amplitudes Q_max,
computed here from the exact derivative

    d⟨u⟩/dQ_max = (1/⟨u⟩)(2/π) ∫ u(Q) u'(Q) sin θ dθ,   u'(Q) = (du/ds)/(dQ/ds).

The integrals use composite Gauss–Legendre panels graded geometrically towards
θ = π/2, where u'(Q) becomes singular as Q_max approaches the peak of Q(u).

Collapse: under load control there is no quasi-static state once Q_max exceeds
the peak Q_peak of Q(u) (the saturated force if Q(u) is monotone): gross sliding,
k = 0. With an interior peak k -> 0 continuously (logarithmically) as
Q_max -> Q_peak; with a monotone Q(u) k drops from a finite value to 0.

Stress measures (every output names its measure):

- ``amplitude``: Q_max/(π a²), what the paper's experiment plots (force amplitude
  over the ideal Hertz area);
- ``rms``: ⟨Q⟩/(π a²) = Q_max/(√2 π a²), the paper's ⟨q⟩ in Fig. 5b.

Knee: the stress at which k first falls to ``knee_fraction`` (default 0.5) of the
initial stiffness k0 = dQ/du|0 (= 2 G* a, the paper's G*), solved with brentq.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import brentq

from flatcontact.contact import mindlin
from flatcontact.contact.parameters import ContactParameters, check_positive
from flatcontact.foundation.errors import require

FloatArray = NDArray[np.float64]

STRESS_MEASURES = ("amplitude", "rms")


@lru_cache(maxsize=8)
def graded_nodes(levels: int = 40, order: int = 6) -> tuple[FloatArray, FloatArray]:
    """Nodes φ = π/2 − θ in (0, π/2) and weights, panels [0, h·2^-levels], ..., [h/2, h]."""
    x, w = np.polynomial.legendre.leggauss(order)
    edges = np.concatenate([[0.0], (np.pi / 2) * 2.0 ** -np.arange(levels, -1, -1)])
    lo, hi = edges[:-1, None], edges[1:, None]
    nodes = 0.5 * (hi - lo) * x[None, :] + 0.5 * (hi + lo)
    weights = 0.5 * (hi - lo) * w[None, :]
    return nodes.ravel(), weights.ravel()


def mean_displacement(
    q_max_n: ArrayLike,
    p0_pa: ArrayLike,
    params: ContactParameters,
    breaks: mindlin.RisingBranchBreaks | None = None,
) -> tuple[FloatArray, FloatArray]:
    """⟨u⟩ (m) and d⟨u⟩/dQ_max (m/N) for amplitudes 0 < Q_max <= Q_peak (broadcasting).

    ``breaks``: :func:`flatcontact.contact.mindlin.rising_branch_breaks` of ``p0_pa`` and
    ``params`` when the caller has them (they do not depend on Q_max: a root search over the
    amplitude computes them once, :func:`amplitude_at_stiffness_fraction`).

    The θ integral is split where u(Q_max sin θ) is not smooth
    (:func:`flatcontact.contact.mindlin.rising_branch_breaks`: the kink where the centre
    starts to slip for k < 0, a jump past a local maximum of Q(u) below the peak), each
    part on Gauss–Legendre panels graded towards its upper end. A jump of u from u₋ to u₊
    at Q_j moves with Q_max and adds the boundary term
    (u₊² − u₋²)·Q_j/(Q_max √(Q_max² − Q_j²)) to d∫u²dθ/dQ_max.

    Raises
    ------
    InputError
        If any Q_max is negative or exceeds the peak of Q(u) (no quasi-static oscillation),
        or τ, σ are not positive on the contact at some p0.
    """
    qmax = np.asarray(q_max_n, dtype=float)
    p0 = np.asarray(p0_pa, dtype=float)
    qmax, p0 = np.broadcast_arrays(qmax, p0)
    peak = mindlin.peak_force(p0, params).force_n
    require(bool(np.all(qmax >= 0.0)), "q_max_n must be >= 0")
    require(
        bool(np.all(qmax <= peak * (1.0 + 1e-12))),
        "q_max_n exceeds the peak lateral force: no quasi-static oscillation (gross sliding)",
    )
    half = np.pi / 2.0
    brk = mindlin.rising_branch_breaks(p0, params) if breaks is None else breaks
    qm = qmax[..., None]
    active = brk.force_n < qm
    n_split = int(active.sum(axis=-1).max(initial=0))
    with np.errstate(divide="ignore", invalid="ignore"):
        theta = np.where(active, np.arcsin(np.minimum(brk.force_n / qm, 1.0)), half)
    edges = np.concatenate(
        [np.zeros_like(qm), theta[..., :n_split], np.full_like(qm, half)], axis=-1
    )
    lo, hi = edges[..., :-1, None], edges[..., 1:, None]  # (..., parts, 1)
    phi, w = graded_nodes()  # distance below each part's upper end, scaled to its length
    span = (hi - lo) / half
    psi = (half - hi) + phi * span  # π/2 − θ at the nodes (accurate near θ = π/2)
    weights = (w * span).reshape(*qmax.shape, -1)
    cospsi = np.cos(psi).reshape(*qmax.shape, -1)
    q = qm * cospsi  # Q = Q_max sin θ
    pe = p0[..., None]
    s = mindlin.s_on_rising_branch(q, pe, params)
    u = mindlin.displacement_from_s(s, pe, params)
    dq_ds = mindlin.force_slope_s(s, pe, params)
    du_ds = mindlin.displacement_slope_s(s, pe, params)
    with np.errstate(divide="ignore", invalid="ignore"):
        du_dq = np.where(s > 0.0, du_ds / dq_ds, 0.0)
    du_dq = np.where(np.isfinite(du_dq) & (du_dq >= 0.0), du_dq, np.inf)
    two_over_pi = 2.0 / np.pi
    u2 = two_over_pi * np.sum(weights * u**2, axis=-1)
    with np.errstate(invalid="ignore"):
        du2 = two_over_pi * np.sum(np.where(u > 0.0, weights * u * du_dq * cospsi, 0.0), axis=-1)
    jump = active & (brk.displacement_above_m > brk.displacement_below_m)
    if np.any(jump):
        fj = np.where(jump, brk.force_n, 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            term = (
                (brk.displacement_above_m**2 - brk.displacement_below_m**2)
                * fj
                / (qm * np.sqrt(qm**2 - fj**2))
            )
        du2 = du2 + two_over_pi * 0.5 * np.sum(np.where(jump, term, 0.0), axis=-1)
    mean_u = np.sqrt(u2)
    with np.errstate(divide="ignore", invalid="ignore"):
        dmean = np.where(
            mean_u > 0.0,
            du2 / mean_u,
            1.0 / mindlin.initial_lateral_stiffness(p0, params) / np.sqrt(2.0),
        )
    return mean_u, dmean


def lateral_stiffness(
    q_max_n: ArrayLike,
    p0_pa: ArrayLike,
    params: ContactParameters,
    breaks: mindlin.RisingBranchBreaks | None = None,
) -> FloatArray:
    """k = d⟨Q⟩/d⟨u⟩ (N/m) at amplitude Q_max (N); k0 at Q_max = 0, 0 at the peak
    (``breaks`` as :func:`mean_displacement`)."""
    qmax = np.asarray(q_max_n, dtype=float)
    _, dmean = mean_displacement(qmax, p0_pa, params, breaks)
    with np.errstate(divide="ignore"):
        k = (1.0 / np.sqrt(2.0)) / dmean
    peak = mindlin.peak_force(np.broadcast_to(p0_pa, qmax.shape), params)
    at_peak = qmax >= peak.force_n * (1.0 - 1e-15)
    return np.where(at_peak & peak.overshoot, 0.0, k)


@dataclass(frozen=True)
class StiffnessCurve:
    """Stiffness vs mean shear stress for one p0 (SI units).

    The arrays run over amplitudes 0 <= Q_max <= Q_peak and end with the collapse
    point (Q_max = Q_peak, k = 0).

    Attributes
    ----------
    p0_pa, contact_radius_m : the load (Pa) and Hertz radius (m)
    q_max_n : amplitudes Q_max (N)
    mean_force_n : ⟨Q⟩ = Q_max/√2 (N)
    mean_displacement_m : ⟨u⟩ (m)
    stiffness_n_per_m : k = d⟨Q⟩/d⟨u⟩ (N/m)
    stress_amplitude_pa : Q_max/(π a²) (Pa)
    stress_rms_pa : ⟨Q⟩/(π a²) (Pa)
    initial_stiffness_n_per_m : k0 = dQ/du at u = 0 (N/m)
    collapse_force_n : Q_peak (N)
    collapse_stress_amplitude_pa, collapse_stress_rms_pa : Q_peak/(π a²), Q_peak/(√2 π a²)
    knee_fraction : the fraction of k0 that defines the knee
    knee_stress_amplitude_pa, knee_stress_rms_pa : stress where k = knee_fraction·k0
    """

    p0_pa: float
    contact_radius_m: float
    q_max_n: FloatArray
    mean_force_n: FloatArray
    mean_displacement_m: FloatArray
    stiffness_n_per_m: FloatArray
    stress_amplitude_pa: FloatArray
    stress_rms_pa: FloatArray
    initial_stiffness_n_per_m: float
    collapse_force_n: float
    collapse_stress_amplitude_pa: float
    collapse_stress_rms_pa: float
    knee_fraction: float
    knee_stress_amplitude_pa: float
    knee_stress_rms_pa: float

    def stress_pa(self, measure: str) -> FloatArray:
        """The stress axis in ``measure`` ('amplitude' or 'rms')."""
        require(
            measure in STRESS_MEASURES,
            f"stress measure must be one of {STRESS_MEASURES}, got {measure!r}",
        )
        return self.stress_amplitude_pa if measure == "amplitude" else self.stress_rms_pa

    def knee_stress_pa(self, measure: str) -> float:
        """The knee stress in ``measure``."""
        self.stress_pa(measure)
        return self.knee_stress_amplitude_pa if measure == "amplitude" else self.knee_stress_rms_pa


def amplitude_grid(n_linear: int = 200, n_log: int = 60, closest: float = 1e-9) -> FloatArray:
    """Q_max/Q_peak in [0, 1): uniform points plus points clustered at the collapse
    (1 − 10^-m down to 1 − ``closest``); sorted, unique, 1 excluded."""
    lin = np.linspace(0.0, 1.0, n_linear, endpoint=False)
    near = 1.0 - np.logspace(np.log10(1.0 / n_linear), np.log10(closest), n_log)
    return np.unique(np.concatenate([lin, near]))


def amplitude_at_stiffness_fraction(
    p0_pa: float, params: ContactParameters, fraction: float
) -> float:
    """The smallest amplitude Q_max (N) at which k = ``fraction``·k0 (brentq on a bracket
    from a coarse amplitude grid); Q_peak if k is still above it when the contact collapses
    (monotone Q(u): the stiffness then drops from a finite value to 0 at Q_peak)."""
    require(0.0 < fraction < 1.0, f"stiffness fraction must be in (0, 1), got {fraction!r}")
    p0 = check_positive("p0_pa", p0_pa)
    params.check_p0_pa(p0)
    peak = mindlin.peak_force(p0, params)
    q_peak = float(peak.force_n)
    target = fraction * float(mindlin.initial_lateral_stiffness(p0, params))
    q_top = q_peak * (1.0 - 1e-13)
    grid = np.append(amplitude_grid(24, 16, closest=1e-12), 1.0 - 1e-13) * q_peak
    breaks = mindlin.rising_branch_breaks(p0, params)  # one p0: the same at every amplitude
    k = lateral_stiffness(grid, p0, params, breaks)
    below = np.nonzero(k < target)[0]
    if below.size == 0:
        return q_peak
    i = int(below[0])
    if i == 0:
        return 0.0

    def excess(q: float) -> float:
        return float(lateral_stiffness(q, p0, params, breaks)) - target

    return float(brentq(excess, grid[i - 1], min(grid[i], q_top), xtol=1e-15 * q_peak, rtol=1e-12))


def stiffness_curve(
    p0_pa: float,
    params: ContactParameters,
    *,
    knee_fraction: float = 0.5,
    q_max_over_peak: ArrayLike | None = None,
) -> StiffnessCurve:
    """The oscillatory stiffness curve k(stress) for one peak pressure (closed form + quadrature).

    Parameters
    ----------
    p0_pa : float
        Peak Hertz pressure (Pa), > 0.
    params : ContactParameters
    knee_fraction : float
        The knee is where k first falls to this fraction of k0; in (0, 1).
    q_max_over_peak : array_like, optional
        Amplitudes as fractions of Q_peak in [0, 1); default :func:`amplitude_grid`.
    """
    p0 = check_positive("p0_pa", p0_pa)
    params.check_p0_pa(p0)
    require(0.0 < knee_fraction < 1.0, f"knee_fraction must be in (0, 1), got {knee_fraction!r}")
    frac = amplitude_grid() if q_max_over_peak is None else np.asarray(q_max_over_peak, dtype=float)
    require(bool(np.all((frac >= 0.0) & (frac < 1.0))), "q_max_over_peak must lie in [0, 1)")
    frac = np.unique(frac)
    peak = mindlin.peak_force(p0, params)
    q_peak = float(peak.force_n)
    a = float(mindlin.contact_radius(p0, params))
    k0 = float(mindlin.initial_lateral_stiffness(p0, params))
    qmax = frac * q_peak
    mean_u, dmean = mean_displacement(qmax, p0, params)
    k = (1.0 / np.sqrt(2.0)) / dmean
    # the collapse point: k -> 0 (continuously for an interior peak, by a drop otherwise)
    mean_u_peak, _ = mean_displacement(q_peak, p0, params)
    if not bool(peak.overshoot):
        qmax = np.append(qmax, q_peak)
        mean_u = np.append(mean_u, mean_u_peak)
        k = np.append(k, (1.0 / np.sqrt(2.0)) / float(mean_displacement(q_peak, p0, params)[1]))
    qmax = np.append(qmax, q_peak)
    mean_u = np.append(mean_u, mean_u_peak)
    k = np.append(k, 0.0)
    area = np.pi * a**2
    q_knee = amplitude_at_stiffness_fraction(p0, params, knee_fraction)
    return StiffnessCurve(
        p0_pa=p0,
        contact_radius_m=a,
        q_max_n=qmax,
        mean_force_n=qmax / np.sqrt(2.0),
        mean_displacement_m=mean_u,
        stiffness_n_per_m=k,
        stress_amplitude_pa=qmax / area,
        stress_rms_pa=qmax / (np.sqrt(2.0) * area),
        initial_stiffness_n_per_m=k0,
        collapse_force_n=q_peak,
        collapse_stress_amplitude_pa=q_peak / area,
        collapse_stress_rms_pa=q_peak / (np.sqrt(2.0) * area),
        knee_fraction=float(knee_fraction),
        knee_stress_amplitude_pa=q_knee / area,
        knee_stress_rms_pa=q_knee / (np.sqrt(2.0) * area),
    )
