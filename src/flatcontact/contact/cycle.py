"""The steady oscillation cycle under load control: hysteresis loop, dissipation, lock-in.

The tip is driven by Q(t) = Q_amp sin θ, θ = 2πνt, below gross sliding. This module gives
the whole cycle — not only the loading quarter the paper uses — for two models:

``modified`` (the paper's modified Mindlin model, Dong et al.)
--------------------------------------------------------------
The paper's local rule per surface element (a spring in series with a slider that holds
up to τ and slips carrying σ), continued through the reversal; the unloading decrement
(U1), the energy per cycle (W) and the generalised Masing rule are closed forms in
:mod:`flatcontact.contact.modified_cycle`. The cycle needs σ <= τ on the contact.

``classical`` (Cattaneo–Mindlin, Mindlin–Deresiewicz)
----------------------------------------------------
Coulomb friction coefficient μ_CM = k (the paper's k, dimensionless: k_mpa_per_gpa·1e-3),
normal load P and radius a of Hertz, Johnson's G*_J = G*/4 (paper's G* = 4 G*_J). Closed
forms in :mod:`flatcontact.contact.cattaneo_mindlin` (Masing loop, Johnson Eq. 7.59 energy).

First harmonic (what a lock-in amplifier measures)
--------------------------------------------------
u(θ) is periodic and half-wave symmetric; its first harmonic u₁(θ) = u′₁ sin θ − u″₁ cos θ
(u lags Q). Integrating by parts along the unloading branch (u from U to −U):

    u′₁ = (2/π) ∫_0^{2U} √(1 − (Q/Q_amp)²) dΔ,       u″₁ = −(2/(π Q_amp)) ∫_0^{2U} Q dΔ,

so that ∮Q du = π Q_amp u″₁ (only the first harmonic of u does work against a sine force;
checked against the closed-form energy). A lock-in referenced to the drive reads the
in-phase and quadrature parts of the displacement at ν: the **lock-in stiffness is
k′ = Q_amp/u′₁** at each
amplitude (a secant, first-harmonic stiffness of the whole loop), with loss tangent
u″₁/u′₁. The paper's k = d⟨Q⟩/d⟨u⟩ (:mod:`.oscillation`) is a different curve: the slope of
the rms loading quarter-cycle across amplitudes, with no unloading. Both → 2 G*a (modified)
or 8 G*_J a (classical) as Q_amp → 0; k′ stays finite up to gross sliding (then the cycle
stops existing), while the paper's k falls to 0 there. A measured stiffness-vs-amplitude
curve from a lock-in is k′ (amplitude stress Q_amp/(π a²)), not d⟨Q⟩/d⟨u⟩.

Numerics: the Δ integrals use Gauss–Legendre panels in φ, Δ = U(1 − cos φ), split where
the slip sets of the modified model change (:func:`.modified_cycle.unloading_drive_breaks`).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from flatcontact.contact import cattaneo_mindlin as cm
from flatcontact.contact import mindlin, modified_cycle, oscillation
from flatcontact.contact.parameters import ContactParameters
from flatcontact.foundation import units
from flatcontact.foundation.errors import require

FloatArray = NDArray[np.float64]

MODELS = ("modified", "classical")

#: Default force amplitudes of ``contact --cycle``, as fractions of the gross-sliding force.
DEFAULT_AMPLITUDE_FRACTIONS: tuple[float, ...] = (0.2, 0.4, 0.6, 0.8, 0.9, 0.95)


def check_model(model: str) -> str:
    """Return ``model`` or raise InputError naming the allowed ones."""
    require(model in MODELS, f"model must be one of {', '.join(MODELS)}, got {model!r}")
    return model


def check_cycle_domain(
    p0_pa: ArrayLike, params: ContactParameters, model: str = "modified"
) -> None:
    """The cycle's domain: the loading branch's (τ > 0, σ >= 0) and, for the modified model,
    σ <= τ on the whole contact (σ0 <= τ0 and μ p0 + σ0 <= k p0 + τ0; a kinetic traction above
    the static strength has no steady cycle in this rule); for the classical model k > 0.

    Raises
    ------
    InputError
        One line naming the parameter and the limit.
    """
    check_model(model)
    p0 = np.atleast_1d(np.asarray(p0_pa, dtype=float))
    params.check_p0_pa(p0)
    if model == "classical":
        require(
            params.k_mpa_per_gpa > 0.0,
            f"k_mpa_per_gpa = {params.k_mpa_per_gpa:g}: the classical model uses the friction "
            "coefficient mu = k, which must be > 0",
        )
        return
    require(
        params.sigma0_mpa <= params.tau0_mpa,
        f"sigma0_mpa = {params.sigma0_mpa:g} > tau0_mpa = {params.tau0_mpa:g}: the cycle needs "
        "the kinetic traction sigma <= the static strength tau on the contact",
    )
    gap = (params.k - params.mu) * p0 + params.tau0_pa - params.sigma0_pa
    bad = gap < -1e-12 * (np.abs(params.k * p0) + params.tau0_pa)
    if np.any(bad):
        p = float(p0[np.argmax(bad)]) / units.GPA_TO_PA
        raise_msg = (
            f"p0_gpa = {p:g}: sigma(centre) = mu p0 + sigma0 exceeds tau(centre) = k p0 + tau0 "
            f"(mu_mpa_per_gpa = {params.mu_mpa_per_gpa:g} > k_mpa_per_gpa = "
            f"{params.k_mpa_per_gpa:g}); the cycle needs sigma <= tau on the contact"
        )
        require(False, raise_msg)


# --------------------------------------------------------------------------------------
# the cycle of either model


@lru_cache(maxsize=4)
def _gauss(order: int = 12) -> tuple[FloatArray, FloatArray]:
    return np.polynomial.legendre.leggauss(order)


def _phi_nodes(u_amp, breaks_delta, panels_per_segment=4, order=12):
    """Nodes φ in (0, π) (Δ = U(1 − cos φ)) and weights dΔ, panels split at the breaks.

    ``u_amp`` (n,), ``breaks_delta`` list of (n,) arrays in Δ units. Returns (n, m) arrays
    of Δ and of the weights w with ∫ f dΔ ≈ Σ w f(Δ).
    """
    u = np.asarray(u_amp, dtype=float)[:, None]
    cand = [np.asarray(b, dtype=float)[:, None] for b in breaks_delta]
    with np.errstate(divide="ignore", invalid="ignore"):
        phis = [np.arccos(np.clip(1.0 - c / u, -1.0, 1.0)) for c in cand]
    edges = np.sort(
        np.concatenate([np.zeros_like(u), *phis, np.full_like(u, np.pi)], axis=-1), axis=-1
    )
    t = np.linspace(0.0, 1.0, panels_per_segment + 1)
    lo_s, hi_s = edges[:, :-1, None], edges[:, 1:, None]
    sub = lo_s + (hi_s - lo_s) * t  # (n, segments, panels+1)
    lo, hi = sub[..., :-1].reshape(u.shape[0], -1), sub[..., 1:].reshape(u.shape[0], -1)
    x, w = _gauss(order)
    phi = 0.5 * (hi - lo)[..., None] * x + 0.5 * (hi + lo)[..., None]
    wphi = 0.5 * (hi - lo)[..., None] * w
    phi = phi.reshape(u.shape[0], -1)
    wphi = wphi.reshape(u.shape[0], -1)
    delta = u * (1.0 - np.cos(phi))
    return delta, wphi * u * np.sin(phi)


@dataclass(frozen=True)
class SteadyCycle:
    """The steady load-controlled cycle at several force amplitudes of one p0 (SI).

    Attributes
    ----------
    model : 'modified' or 'classical'
    p0_pa, contact_radius_m : the load and the Hertz radius
    gross_sliding_force_n : the largest amplitude with a steady cycle (Q_peak of the
        modified model; μP with μ = k for the classical one)
    force_amplitude_n : Q_amp
    displacement_amplitude_m : U, the displacement at Q_amp (loading branch)
    dissipated_energy_j : W per cycle, closed form (Eq. W; Johnson 7.59 for classical)
    in_phase_displacement_m, quadrature_displacement_m : u′₁, u″₁ (first harmonic of u(t))
    lockin_stiffness_n_per_m : k′ = Q_amp/u′₁
    loss_tangent : u″₁/u′₁
    secant_stiffness_n_per_m : Q_amp/U
    paper_stiffness_n_per_m : the paper's d⟨Q⟩/d⟨u⟩ at the same amplitudes
    initial_stiffness_n_per_m : 2 G* a (modified, τ0 > 0) or 8 G*_J a (classical)
    """

    model: str
    p0_pa: float
    contact_radius_m: float
    gross_sliding_force_n: float
    force_amplitude_n: FloatArray
    displacement_amplitude_m: FloatArray
    dissipated_energy_j: FloatArray
    in_phase_displacement_m: FloatArray
    quadrature_displacement_m: FloatArray
    lockin_stiffness_n_per_m: FloatArray
    loss_tangent: FloatArray
    secant_stiffness_n_per_m: FloatArray
    paper_stiffness_n_per_m: FloatArray
    initial_stiffness_n_per_m: float

    @property
    def loop_area_j(self) -> FloatArray:
        """∮ Q du = π Q_amp u″₁ (J), from the loop (the check of ``dissipated_energy_j``)."""
        return np.pi * self.force_amplitude_n * self.quadrature_displacement_m


class CycleModel:
    """Loading and unloading of one model at one p0, vectorised over amplitudes.

    Attributes: ``a`` (Hertz radius, m), ``gross`` (the gross-sliding force, N: Q_peak or
    μP), ``k0`` (initial stiffness, N/m). Methods give the loading displacement at an
    amplitude, the unloading decrement Q_amp − Q at Δ, the energy per cycle and the paper's
    d⟨Q⟩/d⟨u⟩. Raises InputError (one line) outside the model's domain.
    """

    def __init__(self, model: str, p0_pa: float, params: ContactParameters):
        self.model = check_model(model)
        self.p0 = float(p0_pa)
        self.params = params
        check_cycle_domain(self.p0, params, model)
        self.a = float(mindlin.contact_radius(self.p0, params))
        if model == "modified":
            self.gross = float(mindlin.peak_force(self.p0, params).force_n)
            self.k0 = float(mindlin.initial_lateral_stiffness(self.p0, params))
        else:
            load = 2.0 / 3.0 * np.pi * self.a**2 * self.p0
            self.mup = params.k * load
            self.gj = params.shear_modulus_pa / 4.0
            self.gross = float(self.mup)
            self.k0 = float(cm.initial_stiffness(self.a, self.gj))

    def amplitude_displacement(self, qa):
        if self.model == "modified":
            return mindlin.displacement_on_rising_branch(qa, self.p0, self.params)
        return cm.displacement(qa, self.mup, self.a, self.gj)

    def drive(self, u):
        return self.params.shear_modulus_pa * np.asarray(u) / (np.pi * self.a)

    def decrement(self, delta, qa, u_amp):
        """Q_amp − Q on the unloading branch at Δ (shape (n, m)); qa, u_amp (n,)."""
        if self.model == "modified":
            x = self.drive(u_amp)[:, None]
            e = modified_cycle.unloading_decrement(self.drive(delta), x, self.p0, self.params)
            return 2.0 * np.pi * self.a**2 * e
        return 2.0 * cm.force(delta / 2.0, self.mup, self.a, self.gj)

    def delta_breaks(self, u_amp):
        if self.model == "modified":
            x = self.drive(u_amp)
            d = modified_cycle.unloading_drive_breaks(x, self.p0, self.params)
            return [np.pi * self.a * b / self.params.shear_modulus_pa for b in d]
        return [np.asarray(u_amp)]

    def dissipated(self, qa, u_amp):
        if self.model == "modified":
            return modified_cycle.dissipated_energy(self.drive(u_amp), self.p0, self.params)
        return cm.dissipated_energy(qa, self.mup, self.a, self.gj)

    def paper_stiffness(self, qa):
        if self.model == "modified":
            return oscillation.lateral_stiffness(qa, self.p0, self.params)
        return _classical_paper_stiffness(qa, self.mup, self.a, self.gj)


def _classical_paper_stiffness(qa, mup, a, gj):
    """The paper's d⟨Q⟩/d⟨u⟩ for the Cattaneo–Mindlin loading curve (graded quadrature)."""
    qa = np.asarray(qa, dtype=float)[..., None]
    phi, w = oscillation.graded_nodes()
    q = qa * np.cos(phi)  # Q = Q_amp sin θ, θ = π/2 − φ
    u = cm.displacement(q, mup, a, gj)
    x = np.clip(q / mup, 0.0, 1.0)
    du_dq = cm.full_slip_displacement(mup, a, gj) * (2.0 / 3.0) / np.cbrt(1.0 - x) / mup
    two = 2.0 / np.pi
    u2 = two * np.sum(w * u**2, axis=-1)
    du2 = two * np.sum(w * u * du_dq * np.cos(phi), axis=-1)
    mean_u = np.sqrt(u2)
    with np.errstate(divide="ignore", invalid="ignore"):
        dmean = np.where(mean_u > 0.0, du2 / mean_u, 1.0 / (8.0 * gj * a) / np.sqrt(2.0))
        return (1.0 / np.sqrt(2.0)) / dmean


def check_amplitudes(
    amplitude_n: ArrayLike, gross_sliding_force_n: float, p0_gpa: float, model: str
) -> FloatArray:
    """Amplitudes must be finite, > 0 and below gross sliding; InputError names the value."""
    qa = np.atleast_1d(np.asarray(amplitude_n, dtype=float))
    for q in qa:
        require(
            bool(np.isfinite(q) and q > 0.0),
            f"lateral_force_amplitude_un = {q * units.N_TO_UN:g}: must be > 0",
        )
        require(
            q < gross_sliding_force_n,
            f"lateral_force_amplitude_un = {q * units.N_TO_UN:.6g} at p0_gpa = {p0_gpa:g} is at or "
            f"above gross sliding ({gross_sliding_force_n * units.N_TO_UN:.6g} uN, {model} model): "
            "no steady cycle",
        )
    return qa


def steady_cycle(
    amplitude_n: ArrayLike,
    p0_pa: float,
    params: ContactParameters,
    model: str = "modified",
) -> SteadyCycle:
    """The steady cycle at force amplitudes Q_amp (N) below gross sliding, one p0 (Pa).

    Raises
    ------
    InputError
        An amplitude <= 0 or at/above gross sliding, a p0 outside the model's domain,
        σ > τ somewhere (modified), k <= 0 (classical).
    """
    mdl = CycleModel(model, p0_pa, params)
    qa = check_amplitudes(amplitude_n, mdl.gross, mdl.p0 / units.GPA_TO_PA, model)
    u_amp = np.asarray(mdl.amplitude_displacement(qa), dtype=float)
    delta, w = _phi_nodes(u_amp, mdl.delta_breaks(u_amp))
    e = np.maximum.accumulate(mdl.decrement(delta, qa, u_amp), axis=-1)  # load control
    q = qa[:, None] - e
    ratio = np.clip(q / qa[:, None], -1.0, 1.0)
    in_phase = (2.0 / np.pi) * np.sum(w * np.sqrt(1.0 - ratio**2), axis=-1)
    quad = -(2.0 / (np.pi * qa)) * np.sum(w * q, axis=-1)
    return SteadyCycle(
        model=model,
        p0_pa=mdl.p0,
        contact_radius_m=mdl.a,
        gross_sliding_force_n=mdl.gross,
        force_amplitude_n=qa,
        displacement_amplitude_m=u_amp,
        dissipated_energy_j=np.asarray(mdl.dissipated(qa, u_amp), dtype=float),
        in_phase_displacement_m=in_phase,
        quadrature_displacement_m=quad,
        lockin_stiffness_n_per_m=qa / in_phase,
        loss_tangent=quad / in_phase,
        secant_stiffness_n_per_m=qa / u_amp,
        paper_stiffness_n_per_m=np.asarray(mdl.paper_stiffness(qa), dtype=float),
        initial_stiffness_n_per_m=mdl.k0,
    )


@dataclass(frozen=True)
class Loop:
    """One closed hysteresis loop u(Q) under load control (SI), starting at (−U, −Q_amp),
    up the reloading branch to (U, Q_amp) and down the unloading branch back."""

    force_amplitude_n: float
    displacement_m: FloatArray
    force_n: FloatArray


def loops(
    amplitude_n: ArrayLike,
    p0_pa: float,
    params: ContactParameters,
    model: str = "modified",
    n_points: int = 201,
) -> tuple[Loop, ...]:
    """Closed loops at amplitudes Q_amp (N), 2·``n_points`` − 1 points each (closed forms).

    Points are spaced as Δ = U(1 − cos φ) on each branch (dense near the tips); where the
    unloading force is not monotone in Δ the load-controlled path holds Q and jumps in u.
    """
    require(n_points >= 3, f"n_points must be >= 3, got {n_points!r}")
    mdl = CycleModel(model, p0_pa, params)
    qa = check_amplitudes(amplitude_n, mdl.gross, mdl.p0 / units.GPA_TO_PA, model)
    u_amp = np.asarray(mdl.amplitude_displacement(qa), dtype=float)
    phi = np.linspace(0.0, np.pi, n_points)
    delta = u_amp[:, None] * (1.0 - np.cos(phi))
    e = np.maximum.accumulate(mdl.decrement(delta, qa, u_amp), axis=-1)
    u_unl = u_amp[:, None] - delta
    q_unl = qa[:, None] - e
    out = []
    for i in range(qa.size):
        u = np.concatenate([-u_unl[i], u_unl[i, 1:]])
        q = np.concatenate([-q_unl[i], q_unl[i, 1:]])
        out.append(Loop(force_amplitude_n=float(qa[i]), displacement_m=u, force_n=q))
    return tuple(out)


# --------------------------------------------------------------------------------------
# the cycles of a list of p0 (JSON rows and the Dataset: :mod:`.cycle_output`)


def _amplitudes_for(
    gross_n: float,
    amplitudes_un: ArrayLike | None,
    fractions: ArrayLike | None,
    p0_gpa: float,
    model: str,
) -> FloatArray:
    if amplitudes_un is not None:
        return check_amplitudes(
            np.asarray(amplitudes_un, dtype=float) * units.UN_TO_N, gross_n, p0_gpa, model
        )
    f = np.atleast_1d(
        np.asarray(DEFAULT_AMPLITUDE_FRACTIONS if fractions is None else fractions, dtype=float)
    )
    for x in f:
        require(
            bool(np.isfinite(x) and 0.0 < x < 1.0),
            f"amplitude_fraction = {x:g}: must lie in (0, 1) (a fraction of the gross-sliding force)",
        )
    return f * gross_n


def validate_cycle_request(
    p0_gpa: Any,
    params: ContactParameters,
    model: str = "modified",
    *,
    amplitudes_un: ArrayLike | None = None,
    amplitude_fractions: ArrayLike | None = None,
) -> list[float]:
    """Check everything :func:`cycles` needs, before any work; returns the p0 list."""
    check_model(model)
    p0_list = params.check_p0_gpa(p0_gpa)
    for p in p0_list:
        mdl = CycleModel(model, p * units.GPA_TO_PA, params)
        _amplitudes_for(mdl.gross, amplitudes_un, amplitude_fractions, p, model)
    return p0_list


def cycles(
    p0_gpa: Any,
    params: ContactParameters,
    model: str = "modified",
    *,
    amplitudes_un: ArrayLike | None = None,
    amplitude_fractions: ArrayLike | None = None,
) -> tuple[SteadyCycle, ...]:
    """:func:`steady_cycle` for each p0 (GPa), amplitudes in µN or as fractions of the
    gross-sliding force (default :data:`DEFAULT_AMPLITUDE_FRACTIONS`)."""
    p0_list = validate_cycle_request(
        p0_gpa, params, model, amplitudes_un=amplitudes_un, amplitude_fractions=amplitude_fractions
    )
    out = []
    for p in p0_list:
        p0 = p * units.GPA_TO_PA
        mdl = CycleModel(model, p0, params)
        qa = _amplitudes_for(mdl.gross, amplitudes_un, amplitude_fractions, p, model)
        out.append(steady_cycle(qa, p0, params, model))
    return tuple(out)


def lockin_curve(
    p0_pa: float,
    params: ContactParameters,
    model: str = "modified",
    fractions: ArrayLike | None = None,
) -> SteadyCycle:
    """The lock-in stiffness curve of one p0 over amplitudes (default: the paper curve's
    :func:`oscillation.amplitude_grid` without 0), for the Fig. 5b/6 overlays."""
    f = oscillation.amplitude_grid(120, 30, closest=1e-6)[1:] if fractions is None else fractions
    mdl = CycleModel(model, p0_pa, params)
    return steady_cycle(np.asarray(f) * mdl.gross, p0_pa, params, model)
