"""Modified Mindlin model: closed forms against the paper's integrals, limits, properties."""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from flatcontact.contact import cattaneo_mindlin as cm
from flatcontact.contact import mindlin as m
from flatcontact.contact import moduli
from flatcontact.contact.classical_limit import classical_limit_of_paper_model
from flatcontact.contact.parameters import ContactParameters
from flatcontact.contact.quadrature import paper_integrals, stick_zone_by_root_finding
from flatcontact.foundation import units
from flatcontact.foundation.errors import InputError

P = ContactParameters()
P0 = 1.0e9
#: k < 0 with an annular stick zone where Q(s) has a local maximum below the final
#: saturation: the load-controlled rising branch jumps (found by a random search)
JUMP = ContactParameters(k_mpa_per_gpa=-30.0, tau0_mpa=120.0, mu_mpa_per_gpa=15.0, sigma0_mpa=35.0)
JUMP_P0_GPA = 2.35
A = float(m.contact_radius(P0, P))


@st.composite
def params_and_p0(draw):
    """(ContactParameters, p0_gpa) with k in [−X, 50], μ in [−Y, 50] (MPa/GPa), where
    X = 0.999 τ0/p0 and Y = σ0/p0 keep τ > 0 and σ >= 0 on the contact at the drawn p0.
    Negative k beyond τ0/(2 p0) gives the annular stick zone (the centre slips first)."""
    p0_gpa = draw(st.floats(0.05, 5.0))
    tau0 = draw(st.floats(1.0, 300.0))
    sigma0 = draw(st.one_of(st.just(0.0), st.floats(1e-6, 100.0)))  # no subnormal σ0
    prm = ContactParameters(
        k_mpa_per_gpa=draw(st.floats(-0.999 * tau0 / p0_gpa, 50.0)),
        tau0_mpa=tau0,
        mu_mpa_per_gpa=draw(st.floats(-sigma0 / p0_gpa, 50.0)),
        sigma0_mpa=sigma0,
        shear_modulus_gpa=draw(st.floats(1.0, 200.0)),
    )
    prm.check_p0_gpa(p0_gpa)
    return prm, p0_gpa


# force fractions are 0 or >= 1e-12: below that Q is subnormal-small and a relative
# tolerance means nothing (CI once drew 2e-311)
fraction_st = st.one_of(st.just(0.0), st.floats(1e-12, 1.0))


def test_full_stick_integral():
    # ∫ q dA over the full-stick contact = 2π a² q0 = 2 G* a u (paper's G*) = 8 G*_J a u (Johnson)
    u = 0.05e-9
    q0 = float(m.full_stick_q0(u, A, P))
    # q(r) 2πr = 2π r q0 a / √((a−r)(a+r)): algebraic weight (a−r)^(-1/2)
    val, _ = quad(
        lambda r: 2 * np.pi * r * q0 * A / np.sqrt(A + r), 0, A, weight="alg", wvar=(0, -0.5)
    )
    assert val == pytest.approx(2 * P.shear_modulus_pa * A * u, rel=1e-10)
    gj = float(moduli.johnson_shear_modulus_from_paper(P.shear_modulus_pa))
    assert val == pytest.approx(8 * gj * A * u, rel=1e-10)


def test_shear_modulus_conversion():
    g, nu = 30e9, 0.2
    gj = moduli.johnson_effective_shear_modulus(g, nu, g, nu)
    assert gj == pytest.approx(g / (2 * (2 - nu)))
    assert float(moduli.paper_shear_modulus_from_johnson(gj)) == pytest.approx(4 * gj)
    assert float(
        moduli.johnson_shear_modulus_from_paper(moduli.paper_shear_modulus_from_johnson(gj))
    ) == pytest.approx(gj)


def _paper_integrals(u, p0, prm):
    """The paper's Q_stick and Q_slip integrals by quadrature, c from q(c) = τ(c) by brentq."""
    return paper_integrals(u, p0, prm, epsabs=0.0, epsrel=1e-12)


@pytest.mark.filterwarnings("ignore::scipy.integrate.IntegrationWarning")
@settings(max_examples=60, deadline=None)
@given(params_and_p0(), st.one_of(st.just(0.0), st.floats(1e-12, 1.3)))
@example((ContactParameters(k_mpa_per_gpa=-10.0), 2.0), 0.9)  # annulus sticks, centre slips
@example((ContactParameters(k_mpa_per_gpa=-10.0, mu_mpa_per_gpa=-3.0), 2.5), 0.99)
def test_closed_forms_match_paper_integrals(prm_p0, u_frac):
    prm, p0_gpa = prm_p0
    p0 = p0_gpa * 1e9
    u = u_frac * float(m.full_slip_displacement(p0, prm))
    c, stick, slip = _paper_integrals(u, p0, prm)
    c_in, c_out = stick_zone_by_root_finding(u, p0, prm)
    assert c_out == c
    r = m.lateral_force(u, p0, prm)
    a = float(m.contact_radius(p0, prm))
    # the stick zone (disc or annulus) has the same edges; at full slip a ring of zero
    # width may be seen by one method and not the other: then both widths are ~0
    width, width_ref = float(r.stick_radius_m - r.stick_inner_radius_m), c_out - c_in
    if max(width, width_ref) > 1e-6 * a:
        assert float(r.stick_radius_m) == pytest.approx(c_out, abs=1e-7 * a)
        assert float(r.stick_inner_radius_m) == pytest.approx(c_in, abs=1e-7 * a)
    scale = float(m.peak_force(p0, prm).force_n)
    assert float(r.stick_force_n) == pytest.approx(stick, abs=1e-7 * scale)
    assert float(r.slip_force_n) == pytest.approx(slip, abs=1e-7 * scale)


def test_stick_boundary_condition_and_k_zero():
    u = 0.2e-9
    r = m.lateral_force(u, P0, P)
    c = float(r.stick_radius_m)
    p_c = P0 * np.sqrt(1 - (c / A) ** 2)
    assert float(m.full_stick_traction(c, u, A, P)) == pytest.approx(
        float(m.shear_strength(p_c, P)), rel=1e-12
    )
    # paper Fig. 4a: u = 0.2 nm at 1 GPa has a stick zone covering most of the contact
    assert 0.5 * A < c < A
    # k = 0: s = q0/τ0 exactly
    p = P.replace(k_mpa_per_gpa=0.0)
    q0 = float(m.full_stick_q0(u, A, p))
    assert float(m.stick_boundary_s(q0, P0, p)) == pytest.approx(q0 / p.tau0_pa, rel=1e-14)


def test_saturation_is_integral_of_sigma():
    val = quad(
        lambda r: 2 * np.pi * r * float(m.slip_friction(P0 * np.sqrt(1 - (r / A) ** 2), P)), 0, A
    )[0]
    assert float(m.saturated_force(P0, P)) == pytest.approx(val, rel=1e-9)
    u_big = 3 * float(m.full_slip_displacement(P0, P))
    assert float(m.lateral_force(u_big, P0, P).lateral_force_n) == pytest.approx(val, rel=1e-9)
    assert float(m.lateral_force(u_big, P0, P).stick_radius_m) == 0.0


def test_q_of_u_shape_paper_parameters():
    u = np.linspace(0, 1.5, 20001) * float(m.full_slip_displacement(P0, P))
    r = m.lateral_force(u, P0, P)
    q = r.lateral_force_n
    pk = m.peak_force(P0, P)
    # stick contribution rises then falls; slip contribution is monotone
    i = int(np.argmax(r.stick_force_n))
    assert 0 < i < u.size - 1
    assert np.all(np.diff(r.stick_force_n[: i + 1]) >= 0) and np.all(
        np.diff(r.stick_force_n[i:]) <= 0
    )
    assert np.all(np.diff(r.slip_force_n) >= 0)
    # continuous (no jumps bigger than the local slope allows) and bounded by the peak
    assert np.max(np.abs(np.diff(q))) < 0.01 * float(pk.force_n)
    assert np.max(q) <= float(pk.force_n) * (1 + 1e-12)
    assert np.max(q) == pytest.approx(float(pk.force_n), rel=1e-6)
    assert u[np.argmax(q)] == pytest.approx(float(pk.displacement_m), rel=2e-3)
    # overshoot: the paper's parameters have Q_peak > Q_sat (τ > σ at the centre)
    assert bool(pk.overshoot) and float(pk.force_n) > float(pk.saturated_force_n)
    # stick radius decreases with u
    assert np.all(np.diff(r.stick_radius_m) <= 0)


def test_no_overshoot_when_friction_exceeds_strength():
    p = P.replace(tau0_mpa=5.0, sigma0_mpa=20.0)  # σ(centre) > τ(centre)
    pk = m.peak_force(P0, p)
    assert not bool(pk.overshoot)
    assert float(pk.force_n) == pytest.approx(float(pk.saturated_force_n))
    assert float(pk.s) == 1.0


def test_paper_statement_effective_strength_below_uniform():
    # "nonuniform pressure substantially lowers the effective static friction"
    for p0 in np.array([0.5, 1.0, 1.77, 3.0]) * 1e9:
        a = float(m.contact_radius(p0, P))
        eff = float(m.peak_force(p0, P).force_n) / (np.pi * a**2)
        uniform = float(m.shear_strength(2 * p0 / 3, P))
        assert eff < 0.7 * uniform


@settings(max_examples=60, deadline=None)
@given(params_and_p0(), fraction_st)
@example((ContactParameters(k_mpa_per_gpa=-10.0), 2.0), 0.9)  # past the kink (centre slips)
@example((JUMP, JUMP_P0_GPA), 0.97)  # past a local maximum: the branch jumps
def test_inverse_on_rising_branch(prm_p0, frac):
    # fractions below 1e-12 of the peak would put Q in the subnormal range (CI once drew
    # 2e-311), where a relative tolerance means nothing; the absolute floor below covers it
    prm, p0_gpa = prm_p0
    p0 = p0_gpa * 1e9
    pk = m.peak_force(p0, prm)
    q = frac * float(pk.force_n)
    tol = {"rel": 1e-9, "abs": 1e-12 * float(pk.force_n)}
    s = float(m.s_on_rising_branch(q, p0, prm))
    assert float(m.force_at_s(s, p0, prm)) == pytest.approx(q, **tol)
    u = float(m.displacement_on_rising_branch(q, p0, prm))
    assert u == float(m.displacement_from_s(s, p0, prm))
    # Q(u) itself: where a stick annulus vanishes Q − Q_sat ∝ √(u_fs − u) (vertical
    # tangent), so one rounding of u moves Q by ~1e-8; q must lie within Q(u(1 ± 1e-14))
    q_near = m.lateral_force(u * np.array([1 - 1e-14, 1.0, 1 + 1e-14]), p0, prm).lateral_force_n
    assert np.min(q_near) - 1e-9 * q - tol["abs"] <= q <= np.max(q_near) + 1e-9 * q + tol["abs"]
    assert 0.0 <= u <= float(pk.displacement_m) * (1 + 1e-9)
    # it is the first crossing: Q(u') < q for u' < u
    up = np.linspace(0, u, 200)[:-1]
    floor = 1e-12 * float(pk.force_n)
    assert np.all(m.lateral_force(up, p0, prm).lateral_force_n <= q * (1 + 1e-9) + floor)


def test_vectorised_over_u_and_p0():
    p0 = np.array([0.5, 1.0, 2.0])[:, None] * 1e9
    u = np.linspace(0, 1e-9, 7)[None, :]
    r = m.lateral_force(u, p0, P)
    assert r.lateral_force_n.shape == (3, 7)
    for i in range(3):
        np.testing.assert_allclose(
            r.lateral_force_n[i], m.lateral_force(u[0], p0[i, 0], P).lateral_force_n
        )


# ---------------------------------------------------------------- classical limit


def _classical():
    # k = μ, τ0 = σ0 = 0; μ = 0.3 (300 MPa/GPa)
    return ContactParameters(
        k_mpa_per_gpa=300.0, mu_mpa_per_gpa=300.0, tau0_mpa=0.0, sigma0_mpa=0.0
    )


def test_classical_limit_agreements():
    prm = _classical()
    a = float(m.contact_radius(P0, prm))
    load = 2 / 3 * np.pi * a**2 * P0
    mup = prm.mu * load
    gj = float(moduli.johnson_shear_modulus_from_paper(prm.shear_modulus_pa))
    # full slip: Q = μP in both
    assert float(m.saturated_force(P0, prm)) == pytest.approx(mup, rel=1e-12)
    assert float(cm.force(1.0, mup, a, gj)) == pytest.approx(mup)
    # initial stiffness 8 G*_J a in both
    du = 1e-7 * float(m.full_slip_displacement(P0, prm))
    k_paper = float(m.lateral_force(du, P0, prm).lateral_force_n) / du
    k_cm = float(cm.force(du, mup, a, gj)) / du
    assert k_paper == pytest.approx(8 * gj * a, rel=1e-3)
    assert k_cm == pytest.approx(8 * gj * a, rel=1e-3)
    # CM: c/a and δ formulas are consistent with each other (δ <-> Q round trip)
    q = np.linspace(0, 1, 11) * mup
    d = cm.displacement(q, mup, a, gj)
    np.testing.assert_allclose(cm.force(d, mup, a, gj), q, rtol=1e-10, atol=1e-20)


def test_classical_limit_exact_relation_of_paper_model():
    """The paper keeps the full-stick traction in the stick zone, so in the classical limit
    Q/μP = 3s² − 2s³ (not 1 − (c/a)³) and u = 2 δ_CM at the same stick radius c."""
    prm = _classical()
    a = float(m.contact_radius(P0, prm))
    mup = prm.mu * 2 / 3 * np.pi * a**2 * P0
    gj = float(moduli.johnson_shear_modulus_from_paper(prm.shear_modulus_pa))
    u = np.linspace(0, 1, 101)[1:-1] * float(m.full_slip_displacement(P0, prm))
    r = m.lateral_force(u, P0, prm)
    s = np.sqrt(1 - (r.stick_radius_m / a) ** 2)
    np.testing.assert_allclose(r.lateral_force_n / mup, 3 * s**2 - 2 * s**3, rtol=1e-10)
    # CM displacement for the Q that gives CM the same c: Q_CM/μP = 1 − (c/a)³
    q_cm = mup * (1 - (r.stick_radius_m / a) ** 3)
    np.testing.assert_allclose(u / cm.displacement(q_cm, mup, a, gj), 2.0, rtol=1e-9)
    # the two models differ in between: max |ΔQ|/μP = 2/9 at u = (8/9) δ*_CM (exact)
    cmp = classical_limit_of_paper_model()
    assert cmp.max_force_deviation == pytest.approx(2 / 9, abs=1e-9)
    assert cmp.displacement_of_max_deviation == pytest.approx(8 / 9, abs=1e-5)
    assert cmp.max_stick_radius_deviation == pytest.approx(1 - np.sqrt(3) / 2, abs=1e-6)
    assert cmp.displacement_ratio_at_equal_stick_radius == pytest.approx(2.0, rel=1e-9)
    # the same deviation from the real functions
    dstar = 3 * mup / (16 * gj * a)
    uu = np.linspace(0, 2, 4001) * dstar
    dev = np.abs(m.lateral_force(uu, P0, prm).lateral_force_n - cm.force(uu, mup, a, gj)) / mup
    assert dev.max() == pytest.approx(2 / 9, abs=1e-6)


@pytest.mark.parametrize(
    "field,value",
    [
        ("radius_um", 0.0),
        ("contact_modulus_gpa", -1.0),
        ("shear_modulus_gpa", float("nan")),
        ("k_mpa_per_gpa", float("nan")),
        ("mu_mpa_per_gpa", float("-inf")),
        ("tau0_mpa", float("inf")),
        ("sigma0_mpa", -1.0),
    ],
)
def test_parameters_reject_bad_values(field, value):
    with pytest.raises(InputError, match=field):
        ContactParameters(**{field: value})


def test_parameters_reject_no_strength():
    with pytest.raises(InputError, match="k_mpa_per_gpa and tau0_mpa"):
        ContactParameters(k_mpa_per_gpa=0.0, tau0_mpa=0.0)


def test_units_of_parameters():
    assert P.k == pytest.approx(4.52e-3)
    assert P.tau0_pa == pytest.approx(26.7e6)
    assert P.radius_m == pytest.approx(5 * units.UM_TO_M)
