"""Negative load slopes k < 0 (shear strength falling with load) and μ < 0 in the modified
Mindlin model: where the model is defined, the annular stick zone, continuity across k = 0,
the peak, the rising-branch inverse, the oscillatory stiffness, the refusal."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad
from scipy.optimize import brentq

from flatcontact.contact import experiment as ex
from flatcontact.contact import mindlin as m
from flatcontact.contact import oscillation as osc
from flatcontact.contact.parameters import ContactParameters
from flatcontact.contact.quadrature import paper_integrals
from flatcontact.contact.summary import analyse
from flatcontact.foundation.errors import InputError

#: k = −10 MPa/GPa: τ(centre) > 0 below 2.67 GPa; the centre slips first above 1.335 GPa
NEG = ContactParameters(k_mpa_per_gpa=-10.0)
#: the annular-stick regime with a local maximum below the saturation (the branch jumps)
JUMP = ContactParameters(k_mpa_per_gpa=-30.0, tau0_mpa=120.0, mu_mpa_per_gpa=15.0, sigma0_mpa=35.0)
JUMP_P0 = 2.35e9


# ------------------------------------------------------------------ where it is defined


def test_limits_of_the_model():
    assert NEG.p0_limit_gpa == pytest.approx(26.7 / 10.0)
    assert NEG.annular_stick_p0_gpa == pytest.approx(26.7 / 20.0)
    p = ContactParameters(mu_mpa_per_gpa=-5.0, sigma0_mpa=11.1)
    assert p.p0_limit_gpa == pytest.approx(11.1 / 5.0)
    assert ContactParameters().p0_limit_gpa == np.inf
    assert ContactParameters().annular_stick_p0_gpa == np.inf


def test_refuses_p0_where_tau_centre_is_negative():
    p = ContactParameters(k_mpa_per_gpa=-30.0, tau0_mpa=40.0)
    assert p.check_p0_gpa([0.5, 1.3]) == [0.5, 1.3]
    with pytest.raises(InputError) as err:
        p.check_p0_gpa([1.0, 2.0], "contact.p0_gpa")
    msg = str(err.value)
    assert "\n" not in msg
    for text in ("contact.p0_gpa = 2 GPa", "k_mpa_per_gpa = -30", "τ(centre)", "1.333 GPa"):
        assert text in msg
    # every entry point refuses before any work
    with pytest.raises(InputError, match=r"τ0/\|k\|"):
        m.lateral_force(1e-10, 2.0e9, p)
    with pytest.raises(InputError, match=r"τ0/\|k\|"):
        m.peak_force(np.array([1.0e9, 2.0e9]), p)
    with pytest.raises(InputError, match=r"τ0/\|k\|"):
        osc.stiffness_curve(2.0e9, p)
    with pytest.raises(InputError, match=r"^my_p0 = 2 GPa"):
        analyse([1.0, 2.0], p, p0_name="my_p0")
    # at the limit itself τ(centre) = 0: refused too (strict)
    with pytest.raises(InputError, match=r"τ0/\|k\|"):
        p.check_p0_gpa(40.0 / 30.0 * (1 + 1e-12))


def test_refuses_p0_where_sigma_centre_is_negative():
    p = ContactParameters(mu_mpa_per_gpa=-10.0, sigma0_mpa=10.0)
    assert p.check_p0_gpa(1.0) == [1.0]  # σ(centre) = 0 is allowed
    with pytest.raises(InputError) as err:
        p.check_p0_gpa(2.0)
    assert "mu_mpa_per_gpa = -10" in str(err.value) and "σ0/|μ| = 1 GPa" in str(err.value)


@pytest.mark.parametrize(
    "fields,needle",
    [
        ({"k_mpa_per_gpa": -1.0, "tau0_mpa": 0.0}, "needs tau0_mpa > 0"),
        ({"mu_mpa_per_gpa": -1.0, "sigma0_mpa": 0.0}, "needs sigma0_mpa > 0"),
    ],
)
def test_negative_slope_needs_an_intercept(fields, needle):
    with pytest.raises(InputError, match=needle) as err:
        ContactParameters(**fields)
    assert "\n" not in str(err.value)


# ------------------------------------------------------------------ k across 0


def test_continuity_in_k_across_zero():
    p0 = np.array([0.5, 1.77, 3.0])[:, None] * 1e9
    u = np.linspace(0.0, 1.2, 301)[None, :] * m.full_slip_displacement(p0, NEG)
    out = []
    for k in (-1e-9, 0.0, 1e-9):
        prm = ContactParameters(k_mpa_per_gpa=k)
        pk = m.peak_force(p0[:, 0], prm)
        out.append(
            (
                m.lateral_force(u, p0, prm).lateral_force_n,
                pk.force_n,
                pk.displacement_m,
                m.displacement_on_rising_branch(0.7 * pk.force_n, p0[:, 0], prm),
                osc.lateral_stiffness(0.7 * pk.force_n, p0[:, 0], prm),
            )
        )
    # k = 1e-9 MPa/GPa changes τ by k·p0/τ0 ~ 1e-10 relative: the same to that order
    for a, b in zip(out[0], out[1], strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-12 * np.max(np.abs(b)))
    for a, b in zip(out[2], out[1], strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-12 * np.max(np.abs(b)))


# ------------------------------------------------------------------ the annular stick zone


def test_annulus_sticks_once_the_centre_slips():
    """p0 > τ0/(2|k|): after q0 reaches τ(centre) the centre slips, a ring still sticks,
    both its edges satisfy q = τ, and it vanishes at q0 = τ0²/(4|k| p0)."""
    p0 = 2.0e9
    a = float(m.contact_radius(p0, NEG))
    g = NEG.shear_modulus_pa
    tau_c = NEG.k * p0 + NEG.tau0_pa
    u_centre = np.pi * a * tau_c / g  # q0 = τ(centre)
    u_fs = float(m.full_slip_displacement(p0, NEG))
    assert u_fs == pytest.approx(np.pi * a * NEG.tau0_pa**2 / (4 * -NEG.k * p0 * g), rel=1e-14)
    assert u_fs > u_centre
    r = m.lateral_force(u_centre, p0, NEG)
    assert float(r.stick_inner_radius_m) == 0.0
    assert float(r.s) == pytest.approx(float(m.centre_slip_s(p0, NEG)), rel=1e-12)
    u = np.linspace(u_centre, u_fs, 12)[1:-1]
    r = m.lateral_force(u, p0, NEG)
    c_in, c = r.stick_inner_radius_m, r.stick_radius_m
    assert np.all((0.0 < c_in) & (c_in < c) & (c < a))
    for radius in (c_in, c):
        p = p0 * np.sqrt(1 - (radius / a) ** 2)
        np.testing.assert_allclose(
            m.full_stick_traction(radius, u, a, NEG), m.shear_strength(p, NEG), rtol=1e-10
        )
    # the ring shrinks monotonically onto the radius where k p0 s² + τ0 s is largest
    assert np.all(np.diff(c_in) > 0) and np.all(np.diff(c) < 0)
    t_star = NEG.tau0_pa / (2 * -NEG.k * p0)
    r_star = a * np.sqrt(1 - t_star**2)
    assert c_in[-1] < r_star < c[-1]
    # full slip: Q = Q_sat = ∫σ dA, no stick zone left
    end = m.lateral_force(u_fs * (1 + 1e-12), p0, NEG)
    assert float(end.lateral_force_n) == pytest.approx(float(m.saturated_force(p0, NEG)))
    assert float(end.stick_radius_m) == 0.0 and float(end.stick_force_n) == 0.0


def test_kink_where_the_centre_starts_to_slip():
    """Q(s) is continuous at s_c; its slope drops by 2π a² (τ(centre) − σ(centre)): the
    centre's traction falls from τ to σ when it slips."""
    p0 = 2.0e9
    a = float(m.contact_radius(p0, NEG))
    s_c = float(m.centre_slip_s(p0, NEG))
    eps = 1e-7
    q_lo, q_hi = m.force_at_s([s_c - eps, s_c + eps], p0, NEG)
    assert abs(q_hi - q_lo) < 1e-5 * float(m.force_at_s(s_c, p0, NEG))
    d_disc = float(m.force_slope_s(s_c, p0, NEG))
    d_ring = float(m.force_slope_s(s_c + 1e-12, p0, NEG))
    tau_c = NEG.k * p0 + NEG.tau0_pa
    sigma_c = NEG.mu * p0 + NEG.sigma0_pa
    assert d_disc - d_ring == pytest.approx(2 * np.pi * a**2 * (tau_c - sigma_c), rel=1e-6)
    # and both one-sided slopes are the derivatives of the paper's integrals
    du_ds = float(m.displacement_slope_s(s_c, p0, NEG))
    h = 1e-6 * float(m.full_slip_displacement(p0, NEG))
    u_c = float(m.displacement_from_s(s_c, p0, NEG))

    def q_ref(u):
        _, st_, sl = paper_integrals(u, p0, NEG, epsabs=0.0, epsrel=1e-13)
        return st_ + sl

    assert (q_ref(u_c) - q_ref(u_c - h)) / h == pytest.approx(d_disc / du_ds, rel=1e-4)
    assert (q_ref(u_c + h) - q_ref(u_c)) / h == pytest.approx(d_ring / du_ds, rel=1e-4)


@pytest.mark.parametrize("p0_gpa", [1.0, 2.0, 2.6])
def test_peak_for_negative_k(p0_gpa):
    p0 = p0_gpa * 1e9
    pk = m.peak_force(p0, NEG)
    u = np.linspace(0, 1.0, 200_001) * float(pk.full_slip_displacement_m)
    q = m.lateral_force(u, p0, NEG).lateral_force_n
    assert np.max(q) <= float(pk.force_n) * (1 + 1e-12)
    assert np.max(q) == pytest.approx(float(pk.force_n), rel=1e-8)
    assert u[np.argmax(q)] == pytest.approx(float(pk.displacement_m), rel=1e-3)
    assert bool(pk.overshoot) and float(pk.force_n) > float(pk.saturated_force_n)
    # the peak is a stationary point of the paper's integrals: Q(u_peak ± δ) <= Q_peak
    d = 1e-4 * float(pk.displacement_m)
    for up in (float(pk.displacement_m) - d, float(pk.displacement_m) + d):
        _, st_, sl = paper_integrals(up, p0, NEG, epsabs=0.0, epsrel=1e-13)
        assert st_ + sl <= float(pk.force_n) * (1 + 1e-10)


def test_vectorised_across_regimes():
    p0 = np.array([0.5, 1.5, 2.5]) * 1e9  # disc; annulus; annulus with τ(centre) small
    u = np.linspace(0, 1.1, 9)[None, :] * m.full_slip_displacement(p0, NEG)[:, None]
    r = m.lateral_force(u, p0[:, None], NEG)
    pk = m.peak_force(p0, NEG)
    q = 0.8 * pk.force_n
    inv = m.displacement_on_rising_branch(q, p0, NEG)
    for i in range(3):
        np.testing.assert_array_equal(
            r.lateral_force_n[i], m.lateral_force(u[i], p0[i], NEG).lateral_force_n
        )
        assert float(m.peak_force(p0[i], NEG).force_n) == pk.force_n[i]
        assert float(m.displacement_on_rising_branch(q[i], p0[i], NEG)) == pytest.approx(inv[i])


def test_jump_on_the_rising_branch():
    """A local maximum of Q(u) lower than the saturation: under load control u jumps at it
    to the later point of equal force, and the first crossing is still the inverse."""
    pk = m.peak_force(JUMP_P0, JUMP)
    assert float(pk.first_local_max_s) < float(pk.s)
    brk = m.rising_branch_breaks(JUMP_P0, JUMP)
    q_j, u_lo, u_hi = brk.force_n[0], brk.displacement_below_m[0], brk.displacement_above_m[0]
    assert u_hi > u_lo
    for u in (u_lo, u_hi):
        assert float(m.lateral_force(u, JUMP_P0, JUMP).lateral_force_n) == pytest.approx(
            q_j, rel=1e-12
        )
    # everything between lies below the local maximum
    mid = np.linspace(u_lo, u_hi, 1001)[1:-1]
    assert np.all(m.lateral_force(mid, JUMP_P0, JUMP).lateral_force_n < q_j)
    below, above = m.displacement_on_rising_branch(
        q_j * np.array([1 - 1e-9, 1 + 1e-9]), JUMP_P0, JUMP
    )
    assert below == pytest.approx(u_lo, rel=1e-3) and above == pytest.approx(u_hi, rel=1e-3)


# ------------------------------------------------------------------ oscillatory stiffness


def _u_first_crossing(q, p0, prm):
    """Smallest u with Q(u) = q: a dense scan of Q(u) for the bracket, brentq inside."""
    if q <= 0:
        return 0.0
    u = np.linspace(0, float(m.full_slip_displacement(p0, prm)), 4001)
    i = int(np.argmax(m.lateral_force(u, p0, prm).lateral_force_n >= q))
    return brentq(
        lambda x: float(m.lateral_force(x, p0, prm).lateral_force_n) - q, u[i - 1], u[i], xtol=1e-25
    )


def _mean_u_direct(qmax, p0, prm):
    breaks = [np.arcsin(f / qmax) for f in m.rising_branch_breaks(p0, prm).force_n if f < qmax]
    val = quad(
        lambda t: _u_first_crossing(qmax * np.sin(t), p0, prm) ** 2,
        0,
        np.pi / 2,
        epsabs=0,
        epsrel=1e-10,
        points=breaks or None,
        limit=200,
    )[0]
    return np.sqrt(2 / np.pi * val)


@pytest.mark.parametrize(
    "prm,p0,frac",
    [
        (NEG, 1.0e9, 0.9),  # k < 0, stick disc throughout
        (NEG, 2.0e9, 0.6),  # below the kink
        (NEG, 2.0e9, 0.95),  # past the kink (annulus)
        (JUMP, JUMP_P0, 0.97),  # past the jump
    ],
)
def test_mean_displacement_against_direct_integration(prm, p0, frac):
    qmax = frac * float(m.peak_force(p0, prm).force_n)
    ours, _ = osc.mean_displacement(qmax, p0, prm)
    assert float(ours) == pytest.approx(_mean_u_direct(qmax, p0, prm), rel=1e-8)


@pytest.mark.parametrize(
    "prm,p0,fracs", [(NEG, 2.0e9, (0.3, 0.8, 0.9, 0.99)), (JUMP, JUMP_P0, (0.5, 0.95, 0.99))]
)
def test_stiffness_is_the_derivative_of_the_mean_curve(prm, p0, fracs):
    """Including the kink and, for JUMP, the moving jump (its boundary term)."""
    qpk = float(m.peak_force(p0, prm).force_n)
    for frac in fracs:
        q, h = frac * qpk, 1e-5 * qpk
        up, _ = osc.mean_displacement(q + h, p0, prm)
        um, _ = osc.mean_displacement(q - h, p0, prm)
        k_fd = (2 * h / np.sqrt(2)) / float(up - um)
        assert float(osc.lateral_stiffness(q, p0, prm)) == pytest.approx(k_fd, rel=1e-4)


@pytest.mark.parametrize("p0_gpa", [1.0, 2.0, 2.6])
def test_stiffness_curve_for_negative_k(p0_gpa):
    p0 = p0_gpa * 1e9
    c = osc.stiffness_curve(p0, NEG)
    a = c.contact_radius_m
    assert c.initial_stiffness_n_per_m == pytest.approx(2 * NEG.shear_modulus_pa * a)
    assert c.stiffness_n_per_m[0] == pytest.approx(c.initial_stiffness_n_per_m, rel=1e-9)
    assert np.all(np.isfinite(c.stiffness_n_per_m)) and np.all(c.stiffness_n_per_m >= 0)
    assert c.stiffness_n_per_m[-1] == 0.0
    pk = m.peak_force(p0, NEG)
    assert c.collapse_force_n == pytest.approx(float(pk.force_n))
    kq = float(osc.lateral_stiffness(c.knee_stress_amplitude_pa * np.pi * a**2, p0, NEG))
    assert kq == pytest.approx(0.5 * c.initial_stiffness_n_per_m, rel=1e-8)


@settings(max_examples=25, deadline=None)
@given(
    st.floats(0.05, 0.99),  # k as a fraction of its limit −τ0/p0
    st.floats(0.0, 0.99),  # μ as a fraction of its limit −σ0/p0
    st.floats(0.2, 5.0),
    st.floats(0.05, 0.95),
)
def test_stiffness_property_negative_slopes(k_frac, mu_frac, p0_gpa, frac):
    prm = ContactParameters(
        k_mpa_per_gpa=-k_frac * 26.7 / p0_gpa, mu_mpa_per_gpa=-mu_frac * 11.1 / p0_gpa
    )
    p0 = p0_gpa * 1e9
    qpk = float(m.peak_force(p0, prm).force_n)
    q, h = frac * qpk, 1e-6 * qpk
    brk = m.rising_branch_breaks(p0, prm).force_n
    if np.any(np.abs(brk - q) < 1e3 * h):
        return  # a finite difference straddling a kink or jump does not test anything
    up, _ = osc.mean_displacement(q + h, p0, prm)
    um, _ = osc.mean_displacement(q - h, p0, prm)
    k = float(osc.lateral_stiffness(q, p0, prm))
    assert k == pytest.approx((2 * h / np.sqrt(2)) / float(up - um), rel=1e-4)
    # k > 0 on the rising branch; it may exceed k0 = 2 G* a: where the centre slips with
    # σ(centre) > τ(centre) the slip traction is larger than the stuck one (steeper Q(u))
    assert k > 0.0


# ------------------------------------------------------------------ inverse τ0


def test_fit_tau0_with_negative_k():
    p0 = 1.77e9
    truth = NEG.replace(tau0_mpa=50.0)
    cs = ex.model_collapse_stress(p0, truth)
    assert ex.fit_tau0(cs, p0, NEG) == pytest.approx(50.0, rel=1e-6)
    # near the smallest admissible τ0 (> |k| p0 = 17.7 MPa) the peak is the saturation,
    # ∫σ dA, whatever τ0: a collapse below that is refused, naming the bound
    lowest = ex.model_collapse_stress(p0, NEG.replace(tau0_mpa=17.7 * (1 + 1e-6)))
    assert lowest == pytest.approx(
        float(m.saturated_force(p0, NEG)) / (np.pi * float(m.contact_radius(p0, NEG)) ** 2)
    )
    with pytest.raises(InputError, match=r"no tau0 > \|k\|·p0 = 17.7 MPa fits"):
        ex.fit_tau0(0.9 * lowest, p0, NEG)


@pytest.mark.parametrize("prm, p0", [(JUMP, JUMP_P0), (ContactParameters(), 1.77e9)])
def test_breaks_given_once_equal_breaks_per_call(prm, p0):
    """amplitude_at_stiffness_fraction computes the rising-branch breaks of its p0 once and
    passes them to every stiffness evaluation: the same numbers as computing them per call,
    over a grid of amplitudes (one p0 broadcast) and at one amplitude; and its root is k =
    fraction·k0, found here by brentq on the per-call stiffness."""
    brk = m.rising_branch_breaks(p0, prm)
    q = np.linspace(0.0, 1.0, 41)[1:-1] * float(m.peak_force(p0, prm).force_n)
    np.testing.assert_array_equal(
        osc.lateral_stiffness(q, p0, prm, brk), osc.lateral_stiffness(q, p0, prm)
    )
    for qi in q[::7]:
        assert float(osc.lateral_stiffness(qi, p0, prm, brk)) == float(
            osc.lateral_stiffness(qi, p0, prm)
        )
    target = 0.5 * float(m.initial_lateral_stiffness(p0, prm))
    got = osc.amplitude_at_stiffness_fraction(p0, prm, 0.5)
    k = osc.lateral_stiffness(q, p0, prm)
    i = int(np.argmax(k < target))
    want = brentq(
        lambda x: float(osc.lateral_stiffness(x, p0, prm)) - target, q[i - 1], q[i], rtol=1e-12
    )
    assert got == pytest.approx(want, rel=1e-9)
