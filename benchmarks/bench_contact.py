"""Contact model: closed forms vs direct numerical integration (scipy quad + brentq).

Q(u) at 10⁴ displacements and the oscillatory stiffness curve for one load
(p0 = 1.77 GPa, the paper's parameters); the steady cycle: a loop at 10⁴ points and a
full lock-in stiffness curve per load (closed forms, :mod:`flatcontact.contact.cycle`)
against direct time-stepping of the cycle (:mod:`flatcontact.contact.cycle_reference`).
Prints seconds, function-evaluation counts and ratios; the direct versions run on a
subset and are scaled.
"""

import time

import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq

from flatcontact.contact import cycle, mindlin, oscillation
from flatcontact.contact.cycle_reference import time_stepped_cycle
from flatcontact.contact.parameters import ContactParameters
from flatcontact.contact.quadrature import paper_integrals

P = ContactParameters()
P0 = 1.77e9


def _best(fn, repeat=5):
    out, best = None, np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return out, best


def _q_direct(u, counter):
    """The paper's two integrals by quad (scipy's default tolerance), c by brentq."""
    _, stick, slip = paper_integrals(u, P0, P, counter=counter)
    return stick + slip


def _mean_u_direct(qmax, counter):
    pk = mindlin.peak_force(P0, P)

    def u_of_q(q):
        if q <= 0:
            return 0.0
        return brentq(
            lambda u: _q_direct(u, counter) - q, 0.0, float(pk.displacement_m), xtol=1e-22
        )

    def integrand(t):
        return u_of_q(qmax * np.sin(t)) ** 2

    return np.sqrt(2 / np.pi * quad(integrand, 0, np.pi / 2, epsrel=1e-8)[0])


def main() -> None:
    u = np.linspace(0, 1.5, 10_000) * float(mindlin.full_slip_displacement(P0, P))
    res, t_closed = _best(lambda: mindlin.lateral_force(u, P0, P).lateral_force_n)
    n_sub = 200
    sub = u[:: u.size // n_sub]
    counter = [0, 0]
    t = time.perf_counter()
    direct = np.array([_q_direct(x, counter) for x in sub])
    t_direct = (time.perf_counter() - t) * u.size / sub.size
    err = np.max(np.abs(direct - res[:: u.size // n_sub])) / np.max(res)
    print(f"Q(u), 10^4 displacements: closed form {t_closed * 1e3:.2f} ms")
    print(
        f"  direct quad+brentq: {t_direct:.2f} s (scaled from {sub.size}), "
        f"{(counter[0] + counter[1]) * u.size // sub.size} integrand/root evaluations; "
        f"ratio {t_direct / t_closed:.0f}x; max |dQ|/Q_peak = {err:.1e}"
    )

    inv_q = np.linspace(0, 1, 10_000) * float(mindlin.peak_force(P0, P).force_n)
    _, t_inv = _best(lambda: mindlin.displacement_on_rising_branch(inv_q, P0, P))
    print(f"u(Q) on the rising branch, 10^4 forces: closed form (Cardano) {t_inv * 1e3:.2f} ms")

    curve, t_curve = _best(lambda: oscillation.stiffness_curve(P0, P), repeat=3)
    nq = curve.q_max_n.size
    nodes = oscillation.graded_nodes()[0].size
    print(
        f"stiffness curve, {nq} amplitudes x {nodes} quadrature nodes (+ knee by brentq): {t_curve * 1e3:.1f} ms"
    )
    qs = curve.q_max_n[: nq - 1 : max(1, nq // 4)][1:]
    counter = [0, 0]
    t = time.perf_counter()
    ref = np.array([_mean_u_direct(q, counter) for q in qs[:2]])
    t_one = (time.perf_counter() - t) / 2
    ours = oscillation.mean_displacement(qs[:2], P0, P)[0]
    print(
        f"  direct <u> per amplitude (quad over theta of brentq-inverted quad Q(u)): {t_one:.2f} s, "
        f"{(counter[0] + counter[1]) // 2} evaluations; the curve would take ~{t_one * nq * 2:.0f} s "
        f"(two <u> per finite-difference stiffness); ratio ~{t_one * nq * 2 / t_curve:.0f}x; "
        f"max rel. diff of <u> = {np.max(np.abs(ours / ref - 1)):.1e}"
    )

    cycle_benchmark()


def cycle_benchmark() -> None:
    """The steady cycle: closed forms vs direct time-stepping (2000 rings, brentq per step)."""
    q_peak = float(mindlin.peak_force(P0, P).force_n)
    qa = 0.9 * q_peak
    loop, t_loop = _best(lambda: cycle.loops(qa, P0, P, n_points=5001)[0])
    n_loop = loop.force_n.size
    steps = 360
    t = time.perf_counter()
    ref = time_stepped_cycle(qa, P0, P, n_elements=2000, steps=steps, cycles=2)
    t_ref = time.perf_counter() - t
    scale = n_loop / (2 * steps)  # 2 cycles were stepped; one cycle of n_loop points wanted
    closed = cycle.steady_cycle(qa, P0, P)
    print(
        f"steady loop at Q_amp = 0.9 Q_peak, {n_loop} points: closed form {t_loop * 1e3:.2f} ms; "
        f"direct time-stepping {t_ref * scale:.1f} s (scaled from 2 x {steps} steps), "
        f"{int(ref.force_evaluations * scale)} Q(u) evaluations x 2000 rings; "
        f"ratio {t_ref * scale / t_loop:.0f}x"
    )
    print(
        f"  agreement (2000 rings, {steps} steps): W {ref.dissipated_energy_j / closed.dissipated_energy_j[0] - 1:+.1e}, "
        f"u'_1 {ref.in_phase_displacement_m / closed.in_phase_displacement_m[0] - 1:+.1e}, "
        f"u''_1 {ref.quadrature_displacement_m / closed.quadrature_displacement_m[0] - 1:+.1e} (relative)"
    )
    for p0_gpa in (1.0, 1.77, 3.0):
        p0 = p0_gpa * 1e9
        curve, t_curve = _best(lambda p0=p0: cycle.lockin_curve(p0, P), repeat=3)
        n_amp = curve.force_amplitude_n.size
        t = time.perf_counter()
        one = time_stepped_cycle(
            0.5 * float(curve.gross_sliding_force_n), p0, P, n_elements=2000, steps=steps
        )
        t_one = time.perf_counter() - t
        print(
            f"lock-in curve at p0 = {p0_gpa:g} GPa, {n_amp} amplitudes: closed form "
            f"{t_curve * 1e3:.1f} ms; direct {t_one:.2f} s per amplitude "
            f"({one.force_evaluations} Q(u) evaluations), ~{t_one * n_amp:.0f} s per curve; "
            f"ratio ~{t_one * n_amp / t_curve:.0f}x"
        )


if __name__ == "__main__":
    main()
