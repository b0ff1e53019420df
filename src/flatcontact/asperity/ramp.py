"""The amplitude ramp: the lock-in stiffness against amplitude, atoms and model (paper Fig. 6).

The experiment of the paper's Fig. 6 oscillates the tip at growing amplitudes and reads, with
a lock-in amplifier, the first harmonic of the displacement at the drive frequency. The
model's side is :mod:`flatcontact.contact.cycle`: under Q(t) = Q_c + Q_amp sin θ the
displacement's first harmonic is u₁(θ) = u′₁ sin θ − u″₁ cos θ and the **lock-in stiffness is
k′ = Q_amp/u′₁** (cycle.py, "First harmonic", the in-phase integral

    u′₁ = (1/π) ∫₀^{2π} u sin θ dθ = (1/π) ∮ cos θ du = (1/π) ∮ √(1 − r²) |du|,    r = (Q − Q_c)/Q_amp,

by parts over a closed loop: on the rising branch cos θ > 0 and du > 0, on the falling one
both < 0), and ∮ Q du = π Q_amp u″₁ is the energy per cycle (the loss tangent u″₁/u′₁).

:func:`loop_lockin` evaluates exactly this on a sampled loop (Q piecewise linear in u between
samples, each segment's integral in closed form). Under load control Q is monotone on each
branch and u jumps where the displacement-controlled force would fall back; the loop is
therefore read through its running envelope (running minimum on the falling branch, running
maximum on the rising one), as :func:`flatcontact.contact.cycle.steady_cycle` does.

**Atoms** (:func:`ramp_path`, :func:`run_ramp`): from the pressed state the tip block is
driven (displacement control, steps of at most ``step_angstrom``) to +U₁, −U₁, +U₁, then to
+U₂, −U₂, +U₂, ... (a ramp of growing amplitudes, as the experiment's); the loop at Uⱼ is the
states from the first +Uⱼ to the last; k′ from :func:`loop_lockin`. Resumable per step
(``ramp/step_<k>.npz``, the same rule as the slide: each state depends only on the ones before).

**Model** (:func:`model_lockin`): the paper's element rule (a spring in series with a slider
that holds up to τ(p) and slips carrying σ(p); at a reversal every element re-sticks and slips
the other way once its traction reaches ∓τ: :mod:`flatcontact.contact.modified_cycle`) on any
pressure profile — Hertz's (the contact stage's model) or the atoms' measured one — driven by
the full-stick load Q_fs through the loop, u = Q_fs/K0 with K0 the atoms' initial stiffness
(the one fitted compliance of :mod:`.compare`), at the same Q_amp/Q_peak as the atoms' (each
side's own peak: the two peaks differ by factors, docs/asperity.md).
"""

from __future__ import annotations

import itertools
import json
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from flatcontact.asperity.driver import (
    EV_PER_ANGSTROM_N,
    Protocol,
    StepState,
    load_state,
    relax,
    save_state,
)
from flatcontact.contact import line_contact as lc
from flatcontact.foundation.errors import InputError, require

# ------------------------------------------------------------------------------------------
# the lock-in reading of a loop


def _arc(r):
    """∫ √(1 − r²) dr = (r √(1 − r²) + arcsin r)/2."""
    r = np.clip(r, -1.0, 1.0)
    return 0.5 * (r * np.sqrt(1.0 - r * r) + np.arcsin(r))


def _segments_integral(u, r) -> float:
    """Σ over segments of ∫ √(1 − r²) |du|, r linear in u on each segment (closed form)."""
    du = np.diff(u)
    dr = np.diff(r)
    flat = np.abs(dr) < 1e-12
    safe = np.where(flat, 1.0, dr)
    exact = (_arc(r[1:]) - _arc(r[:-1])) / safe
    mid = np.sqrt(np.clip(1.0 - (0.5 * (r[1:] + r[:-1])) ** 2, 0.0, None))
    return float(np.sum(np.abs(du) * np.where(flat, mid, exact)))


@dataclass(frozen=True)
class LockIn:
    """The first harmonic of one closed loop (units of the inputs: u, Q).

    force_amplitude : Q_amp = (Q_max − Q_min)/2
    displacement_amplitude : U = (u_max − u_min)/2
    in_phase, quadrature : u′₁, u″₁
    stiffness : k′ = Q_amp/u′₁
    loss_tangent : u″₁/u′₁
    """

    force_amplitude: float
    displacement_amplitude: float
    in_phase: float
    quadrature: float

    @property
    def stiffness(self) -> float:
        return self.force_amplitude / self.in_phase

    @property
    def loss_tangent(self) -> float:
        return self.quadrature / self.in_phase


def loop_lockin(u, q) -> LockIn:
    """k′ = Q_amp/u′₁ of a closed loop sampled from its top (+U) down to −U and back to +U.

    Parameters
    ----------
    u, q : displacement and force along the loop (any consistent units; the falling branch
        from the first sample to the lowest u, the rising branch from there to the last
        sample, which is back at the top)

    Returns
    -------
    LockIn: u′₁ = (1/π) ∮ √(1 − r²)|du| and u″₁ = ∮ Q du/(π Q_amp) over the load-controlled
    envelope (module docstring; flatcontact.contact.cycle, "First harmonic").
    """
    u = np.asarray(u, dtype=float)
    q = np.asarray(q, dtype=float)
    require(u.shape == q.shape and u.ndim == 1 and u.size >= 3, "u, q: one loop of >= 3 samples")
    require(bool(np.all(np.isfinite(u)) and np.all(np.isfinite(q))), "u, q: must be finite")
    bottom = int(np.argmin(u))
    require(0 < bottom < u.size - 1, "u: the loop must fall from its top to -U and rise back")
    fall = np.minimum.accumulate(q[: bottom + 1])
    rise = np.maximum.accumulate(q[bottom:])
    q_lc = np.concatenate([fall, rise[1:]])
    q_max, q_min = float(q_lc.max()), float(q_lc.min())
    q_amp = 0.5 * (q_max - q_min)
    require(q_amp > 0, "q: the loop has no force amplitude")
    r = (q_lc - 0.5 * (q_max + q_min)) / q_amp
    in_phase = _segments_integral(u, r) / math.pi
    # falling along the lower branch, rising along the upper: ∮ Q du = W = π Q_amp u″₁ > 0
    work = float(np.sum(0.5 * (q_lc[1:] + q_lc[:-1]) * np.diff(u)))
    return LockIn(q_amp, 0.5 * float(u.max() - u.min()), in_phase, work / (math.pi * q_amp))


# ------------------------------------------------------------------------------------------
# the model: the paper's element rule on a pressure profile


@dataclass(frozen=True)
class Elements:
    """The contact cut into elements: ``share`` (the fraction of the full-stick load each
    carries, Σ = 1), ``tau_n`` and ``sigma_n`` (the loads at which it slips and which it
    carries slipping: τ(p)·area, σ(p)·area; N)."""

    share: np.ndarray
    tau_n: np.ndarray
    sigma_n: np.ndarray


def elements(
    geometry: str, x_m, p_pa, a_m: float, laws: lc.PointLaws, axis_m: float, n: int = 1600
) -> Elements:
    """Elements of a symmetric profile p(|x|) on 0..a (nodes ``x_m``, ``p_pa``).

    Full stick: q_fs = Q_fs/(π √(a² − x²)) per length (cylinder, the line model of
    :mod:`flatcontact.contact.line_contact`) or q₀/√(1 − r²/a²) with Q_fs = 2π a² q₀ (sphere,
    :mod:`flatcontact.contact.mindlin`); cells denser to the edge, their full-stick shares
    integrated in closed form (the kernel is singular at the edge).
    """
    edges = a_m * np.sin(np.linspace(0.0, np.pi / 2, n + 1))
    x0, x1 = edges[:-1], edges[1:]
    mid = 0.5 * (x0 + x1)
    p = np.interp(mid, np.asarray(x_m, float), np.asarray(p_pa, float))
    if geometry == "cylinder":
        share = (2.0 / np.pi) * (np.arcsin(x1 / a_m) - np.arcsin(x0 / a_m))
        area = 2.0 * (x1 - x0) * axis_m
    else:
        share = (np.sqrt(a_m**2 - x0**2) - np.sqrt(np.clip(a_m**2 - x1**2, 0, None))) / a_m
        area = np.pi * (x1**2 - x0**2)
    return Elements(share, laws.tau_pa(p) * area, laws.sigma_pa(p) * area)


def _branch(el: Elements, start_n, direction: float, travel):
    """Element loads along one monotone drive segment: stuck ones change by share·travel,
    one reaching ±τ slips and carries ±σ from then on (travel >= 0, increasing)."""
    trial = start_n[None, :] + direction * np.asarray(travel)[:, None] * el.share[None, :]
    slipped = direction * trial >= el.tau_n[None, :]
    return np.where(slipped, direction * el.sigma_n[None, :], trial)


def loading(el: Elements, drive_n):
    """Q(Q_fs) from rest (N), increasing drive."""
    return _branch(el, np.zeros_like(el.share), 1.0, drive_n).sum(axis=1)


def model_loop(el: Elements, drive_amplitude_n: float, points: int = 801):
    """(drive, Q) through the steady loop at drive amplitude X: loading to X, then X → −X → X.

    At X the elements are those of the loading branch; at each reversal all re-stick
    (:mod:`flatcontact.contact.modified_cycle`, the rule continued to reversal)."""
    top = _branch(el, np.zeros_like(el.share), 1.0, [drive_amplitude_n])[0]
    travel = np.linspace(0.0, 2 * drive_amplitude_n, points)
    down = _branch(el, top, -1.0, travel)
    up = _branch(el, down[-1], 1.0, travel)
    drive = np.concatenate([drive_amplitude_n - travel, -drive_amplitude_n + travel[1:]])
    q = np.concatenate([down.sum(axis=1), up[1:].sum(axis=1)])
    return drive, q


def model_lockin(el: Elements, fractions, k0_n_per_m: float, grid: int = 4001):
    """The model's lock-in stiffness (N/m) at force amplitudes ``fractions``·Q_peak (its own
    peak under load control), u = Q_fs/K0. None where a fraction is not in (0, 1)."""
    # drive far enough that every element has slipped: max over elements of τ/share
    top = float(np.max(el.tau_n / np.maximum(el.share, 1e-300)))
    drive = np.linspace(0.0, min(top, 50 * float(np.sum(el.tau_n))), grid)
    q = loading(el, drive)
    i_peak = int(np.argmax(q))
    peak = float(q[i_peak])
    out = []
    for f in fractions:
        if f is None or not 0.0 < f < 1.0 or i_peak == 0:
            out.append(None)
            continue
        rising = np.maximum.accumulate(q[: i_peak + 1])
        x = float(np.interp(f * peak, rising, drive[: i_peak + 1]))
        d, ql = model_loop(el, x)
        out.append(loop_lockin(d / k0_n_per_m, ql).stiffness)
    return peak, out


# ------------------------------------------------------------------------------------------
# the atoms: the ramp of cycles


def check_amplitudes(amplitudes_angstrom) -> tuple[float, ...]:
    """Amplitudes (Å) must be finite, > 0 and strictly increasing (a ramp)."""
    amps = tuple(float(a) for a in amplitudes_angstrom)
    for a in amps:
        require(math.isfinite(a) and a > 0, f"ramp_amplitudes_angstrom: {a!r} must be > 0")
    for lo, hi in itertools.pairwise(amps):
        require(hi > lo, f"ramp_amplitudes_angstrom: {hi:g} after {lo:g}: must increase")
    return amps


def ramp_path(amplitudes_angstrom, step_angstrom: float):
    """The tip's displacements (Å) through the ramp, from 0, and each amplitude's loop as
    (first, last) indices into them: 0 → +U₁ → −U₁ → +U₁ → +U₂ → −U₂ → +U₂ ..., in equal
    steps of at most ``step_angstrom`` between these turning points."""
    amps = check_amplitudes(amplitudes_angstrom)
    require(step_angstrom > 0, f"step_angstrom must be > 0, got {step_angstrom!r}")
    path = [0.0]

    def go(target):
        start = path[-1]
        n = max(1, math.ceil(abs(target - start) / step_angstrom - 1e-9))
        path.extend(start + (target - start) * (k / n) for k in range(1, n + 1))

    loops = []
    for a in amps:
        go(a)
        first = len(path) - 1
        go(-a)
        go(a)
        loops.append((first, len(path) - 1))
    return np.array(path), loops


def _check_ramp_state(folder: Path, amplitudes, step_angstrom: float) -> None:
    """Refuse ramp states of another step; more amplitudes (the old ones a prefix) extend."""
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / "ramp.json"
    doc = {"amplitudes_angstrom": list(amplitudes), "step_angstrom": step_angstrom}
    if path.exists():
        old = json.loads(path.read_text())
        n = len(old["amplitudes_angstrom"])
        if old["step_angstrom"] != step_angstrom or (
            old["amplitudes_angstrom"] != list(amplitudes)[:n]
        ):
            raise InputError(
                f"{folder}: holds a ramp of other amplitudes or step; give another --out or "
                "remove it"
            )
        if n > len(amplitudes):
            doc = old
    path.write_text(json.dumps(doc, indent=1))


def run_ramp(
    model,
    atoms,
    pressed: StepState,
    protocol: Protocol,
    amplitudes_angstrom,
    folder: Path,
    progress: Callable[[int, int, float], None] | None = None,
) -> tuple[np.ndarray, np.ndarray, list, list]:
    """Drive the pressed tip through the ramp; (u in Å, Q in N, loops, converged) per state.

    State k of the path in ``folder/step_<k>.npz`` (k >= 1; 0 is the pressed state); saved
    steps are read, not recomputed (resume). Q is the lateral force on the contact, as the
    slide's (:mod:`.records`).
    """
    path, loops = ramp_path(amplitudes_angstrom, protocol.step_angstrom)
    _check_ramp_state(folder, tuple(amplitudes_angstrom), protocol.step_angstrom)
    block = np.asarray(atoms.arrays["block"])
    states = [pressed]
    for k in range(1, len(path)):
        file = folder / f"step_{k:04d}.npz"
        if file.exists():
            states.append(load_state(file))
            continue
        t0 = time.perf_counter()
        start = states[-1].positions.copy()
        start[block == 2, 1] += path[k] - path[k - 1]
        st = relax(model, atoms, start, protocol)
        st = StepState(
            st.positions,
            st.tip_force,
            st.cross_force,
            float(path[k]),
            st.iterations,
            st.converged,
            st.residual_ev_per_angstrom,
            time.perf_counter() - t0,
        )
        save_state(file, st)
        states.append(st)
        if progress is not None:
            progress(k, len(path) - 1, time.perf_counter() - t0)
    q = np.array([-float(s.tip_force[1]) * EV_PER_ANGSTROM_N for s in states])
    return path, q, loops, [s.converged for s in states]


def compare_ramp(
    path_angstrom,
    q_n,
    loops,
    q_peak_n: float | None,
    k0_n_per_m: float | None,
    models: dict[str, Elements],
) -> dict:
    """Per amplitude: the atoms' k′ and loss tangent, the models' k′ at the same Q_amp/Q_peak
    (u = Q_fs/K0), and the ratios atoms/model (asperity.json's ``ramp``). Q is counted from
    the pressed state (the lock-in is blind to a constant offset)."""
    q_n = np.asarray(q_n, float) - float(q_n[0])
    rows = []
    fit = q_peak_n is not None and q_peak_n > 0 and k0_n_per_m and math.isfinite(k0_n_per_m)
    for first, last in loops:
        li = loop_lockin(path_angstrom[first : last + 1] * 1e-10, q_n[first : last + 1])
        frac = li.force_amplitude / q_peak_n if fit else None
        row = {
            "displacement_amplitude_angstrom": li.displacement_amplitude * 1e10,
            "force_amplitude_n": li.force_amplitude,
            "q_amp_over_q_peak": frac,
            "atoms_lockin_n_per_m": li.stiffness,
            "atoms_loss_tangent": li.loss_tangent,
            "atoms_secant_n_per_m": li.force_amplitude / li.displacement_amplitude,
        }
        for name, el in models.items():
            k = model_lockin(el, [frac], k0_n_per_m)[1][0] if fit else None
            row[f"model_{name}_lockin_n_per_m"] = k
            row[f"ratio_atoms_over_model_{name}"] = None if k is None else li.stiffness / k
        rows.append(row)
    curve = None
    if fit and models:
        fr = np.linspace(0.02, 0.98, 25)
        curve = {"q_amp_over_q_peak": fr.tolist(), "force_amplitude_n": (fr * q_peak_n).tolist()}
        for name, el in models.items():
            curve[f"model_{name}_lockin_n_per_m"] = model_lockin(el, fr, k0_n_per_m)[1]
    return {
        "displacement_angstrom": np.asarray(path_angstrom, float).tolist(),
        # the models' k′ over amplitudes (their own Q_amp/Q_peak), at the atoms' Q_peak scale
        "model_curve": curve,
        "lateral_force_n": q_n.tolist(),
        "loops": [list(lp) for lp in loops],
        "initial_stiffness_n_per_m": k0_n_per_m,
        "amplitudes": rows,
        "note": "k' = Q_amp/u'_1 (first harmonic under load control, contact/cycle.py); the "
        "models at the atoms' Q_amp/Q_peak with u = Q_fs/K0 (K0 the atoms' initial stiffness); "
        "None where Q_amp >= Q_peak (no steady cycle)",
    }
