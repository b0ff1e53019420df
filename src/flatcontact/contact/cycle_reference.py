"""Direct time-stepping of the load-controlled cycle: the independent reference of
:mod:`flatcontact.contact.cycle` (tests and ``benchmarks/bench_contact.py``).

The contact is cut into ``n_elements`` rings of equal width in s = √(1 − r²/a²) (midpoints,
dA = 2π a² s ds). Each ring is the paper's element: a spring κ = G*/(π a s) per area in
series with a slider that sticks until |traction| reaches τ(s) = k p0 s + τ0 and then slips
carrying ±σ(s) = ±(μ p0 s + σ0) while it keeps moving the same way; at a reversal it
sticks again. Q(t) = Q_amp sin(2π j/steps) is imposed step by step from rest; at each step
the tip displacement u with Σ traction·dA = Q is found by brentq, each trial u updating
every ring from its state at the previous step. Nothing here uses the closed forms.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

from flatcontact.contact import mindlin
from flatcontact.contact.parameters import ContactParameters


@dataclass(frozen=True)
class SteppedCycle:
    """The last simulated cycle (SI).

    Attributes
    ----------
    theta : drive phase 2π j/steps, j = 0..steps−1
    force_n, displacement_m : Q and u at those phases
    dissipated_energy_j : ∮ Q du over the cycle (trapezoids)
    in_phase_displacement_m, quadrature_displacement_m : u′₁, u″₁ of u = u′₁ sin θ − u″₁ cos θ
        (discrete Fourier sums)
    force_evaluations : how many times Q(u) was evaluated (each updates every ring)
    """

    theta: np.ndarray
    force_n: np.ndarray
    displacement_m: np.ndarray
    dissipated_energy_j: float
    in_phase_displacement_m: float
    quadrature_displacement_m: float
    force_evaluations: int


def time_stepped_cycle(
    amplitude_n: float,
    p0_pa: float,
    params: ContactParameters,
    *,
    n_elements: int = 2000,
    steps: int = 720,
    cycles: int = 2,
    ramp_cycles: int = 0,
) -> SteppedCycle:
    """Simulate ``cycles`` cycles of Q = Q_amp sin θ from rest; return the last one.

    ``ramp_cycles`` > 0: the amplitude first grows linearly from 0 to Q_amp over that many
    cycles (an experiment's slow ramp), then ``cycles`` cycles at Q_amp follow.
    """
    a = float(mindlin.contact_radius(p0_pa, params))
    s = (np.arange(n_elements) + 0.5) / n_elements
    da = 2.0 * np.pi * a**2 * s / n_elements
    kappa = params.shear_modulus_pa / (np.pi * a * s)
    tau = params.k * p0_pa * s + params.tau0_pa
    sig = params.mu * p0_pa * s + params.sigma0_pa
    plastic = np.zeros(n_elements)
    direction = np.zeros(n_elements)
    calls = [0]

    def update(u, u_prev):
        calls[0] += 1
        moving = np.sign(u - u_prev)
        trial = kappa * (u - plastic)
        cont = (direction != 0.0) & (direction == moving)
        q = np.where(cont, direction * sig, trial)
        new_dir = np.where(cont, direction, 0.0)
        fwd = ~cont & (trial >= tau)
        bwd = ~cont & (trial <= -tau)
        q = np.where(fwd, sig, np.where(bwd, -sig, q))
        new_dir = np.where(fwd, 1.0, np.where(bwd, -1.0, new_dir))
        new_plastic = np.where(new_dir != 0.0, u - q / kappa, plastic)
        return q, new_plastic, new_dir

    k0 = 2.0 * params.shear_modulus_pa * a
    theta = 2.0 * np.pi * np.arange(steps) / steps
    u_prev, q_prev = 0.0, 0.0
    us = np.zeros(steps)
    qs = amplitude_n * np.sin(theta)
    for c in range(ramp_cycles + cycles):
        for j in range(steps):
            if c == 0 and j == 0:
                continue
            ramp = min(1.0, (c + j / steps) / ramp_cycles) if ramp_cycles > 0 else 1.0
            target = ramp * qs[j]

            def mismatch(u, up=u_prev, t=target):
                return float(np.dot(update(u, up)[0], da)) - t

            step = (target - q_prev) / k0
            if step == 0.0:
                u_new = u_prev
            else:
                lo, hi = u_prev, u_prev + step
                while np.sign(mismatch(hi)) == np.sign(mismatch(lo)) and mismatch(hi) != 0.0:
                    hi = u_prev + 2.0 * (hi - u_prev)
                u_new = brentq(mismatch, min(lo, hi), max(lo, hi), xtol=1e-22, rtol=1e-13)
            _, plastic, direction = update(u_new, u_prev)
            u_prev, q_prev = u_new, target
            us[j] = u_new
    # the last cycle, closed: trapezoids of Q du, discrete Fourier sums
    u_cl = np.append(us, us[0])
    q_cl = np.append(qs, qs[0])
    w = float(np.sum(0.5 * (q_cl[1:] + q_cl[:-1]) * np.diff(u_cl)))
    u1 = 2.0 / steps * float(np.sum(us * np.sin(theta)))
    u2 = -2.0 / steps * float(np.sum(us * np.cos(theta)))
    return SteppedCycle(
        theta=theta,
        force_n=qs,
        displacement_m=us,
        dissipated_energy_j=w,
        in_phase_displacement_m=u1,
        quadrature_displacement_m=u2,
        force_evaluations=calls[0],
    )
