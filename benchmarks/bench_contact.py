"""Contact model: closed forms vs direct numerical integration (scipy quad + brentq).

Q(u) at 10⁴ displacements and the oscillatory stiffness curve for one load
(p0 = 1.77 GPa, the paper's parameters). Prints seconds, function-evaluation
counts and ratios; the direct versions run on a subset and are scaled.
"""

import time

import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq

from flatcontact.contact import mindlin, oscillation
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
    nodes = oscillation._graded_nodes()[0].size
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


if __name__ == "__main__":
    main()
