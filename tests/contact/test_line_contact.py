"""Line contact: Hertz, Cattaneo's closed form as the classical limit, the pointwise model."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from flatcontact.contact import line_contact as lc
from flatcontact.foundation.errors import InputError

A = 2.0e-9
P0 = 3.0e9
MU = 0.3


def test_hertz_line_load_and_half_width_round_trip():
    load = np.pi * A * P0 / 2
    val, _ = quad(lambda x: lc.line_pressure(x, A, P0), -A, A)
    assert val == pytest.approx(load, rel=1e-9)
    radius, e_star = 10e-9, 60e9
    a = lc.line_half_width(load, radius, e_star)
    # p0 = E* a / (2R) for the line contact (Johnson Eq. 4.45)
    assert float(lc.line_peak_pressure(load, a)) == pytest.approx(
        e_star * a / (2 * radius), rel=1e-12
    )
    assert lc.hertz_profile(A, P0).load_n_per_m() == pytest.approx(load, rel=1e-6)


@settings(max_examples=10, deadline=None)
@given(fraction=st.floats(0.02, 0.98))
def test_classical_limit_of_the_elastic_model_is_cattaneo(fraction):
    profile = lc.hertz_profile(A, P0)
    limit = MU * np.pi * A * P0 / 2
    q = fraction * limit
    res = lc.elastic_response(profile, lc.PointLaws.coulomb(MU), q)
    c_closed = A * float(lc.cattaneo_stick_ratio(q, limit))
    assert res.stick_half_width_m == pytest.approx(c_closed, rel=2e-4, abs=1e-5 * A)
    closed = lc.cattaneo_traction(res.x_m, A, P0, MU, c_closed)
    assert np.max(np.abs(res.traction_pa - closed)) < 2e-4 * MU * P0
    # Cattaneo's stick zone is admissible: q <= μ p inside it
    assert res.stick_margin <= 1.0 + 1e-3


def test_cattaneo_closed_form_integrates_to_q():
    c = 0.6 * A
    val, _ = quad(lambda x: lc.cattaneo_traction(x, A, P0, MU, c), -A, A, points=[-c, c])
    assert val == pytest.approx(MU * np.pi * A * P0 / 2 * (1 - 0.36), rel=1e-9)


def test_elastic_model_with_offsets_rises_to_the_sliding_force():
    laws = lc.PointLaws(k=0.05, tau0_pa=0.4e9, mu=0.02, sigma0_pa=0.2e9)
    profile = lc.hertz_profile(A, P0)
    q_sat = lc.sliding_force(profile, laws)
    assert q_sat == pytest.approx(np.pi * A * P0 / 2 * 0.02 + 2 * A * 0.2e9, rel=1e-5)
    cs = [lc.elastic_response(profile, laws, f * q_sat).stick_half_width_m for f in (0.1, 0.5, 0.9)]
    assert cs[0] > cs[1] > cs[2] > 0
    # force balance: the traction integrates to Q'
    res = lc.elastic_response(profile, laws, 0.5 * q_sat)
    assert np.trapezoid(res.traction_pa, res.x_m) == pytest.approx(0.5 * q_sat, rel=2e-3)
    with pytest.raises(InputError, match="lateral_n_per_m"):
        lc.elastic_response(profile, laws, 1.01 * q_sat)


def test_slip_displacement_of_cattaneo_grows_from_zero():
    profile = lc.hertz_profile(A, P0)
    limit = MU * np.pi * A * P0 / 2
    laws = lc.PointLaws.coulomb(MU)
    d = [
        lc.elastic_slip_displacement(profile, lc.elastic_response(profile, laws, f * limit), 60e9)
        for f in (0.01, 0.5, 0.9)
    ]
    assert abs(d[0]) < 1e-3 * abs(d[2])
    assert 0 < d[1] < d[2]


def test_pointwise_classical_limit_peaks_at_mu_p_and_starts_fully_stuck():
    profile = lc.hertz_profile(A, P0)
    curve = lc.pointwise_peak(profile, lc.PointLaws.coulomb(MU))
    limit = MU * np.pi * A * P0 / 2
    assert curve.peak_n_per_m == pytest.approx(limit, rel=1e-3)
    assert curve.sliding_n_per_m == pytest.approx(limit, rel=1e-5)
    # initial slope 1: Q' = Q'_fs while (nearly) everything sticks
    small = lc.pointwise_response(profile, lc.PointLaws.coulomb(MU), [1e-4 * limit])
    assert small.lateral_n_per_m[0] == pytest.approx(1e-4 * limit, rel=2e-2)


def test_pointwise_peak_above_sliding_when_tau_exceeds_sigma():
    # τ = σ + Δ everywhere: the stuck centre carries more than σ, so Q'_peak > Q'_sat;
    # the stick edge at Q'_fs obeys q_fs(c) = τ(p(c)) (closed form for k = 0)
    laws = lc.PointLaws(k=0.0, tau0_pa=0.5e9, mu=0.1, sigma0_pa=0.1e9)
    profile = lc.hertz_profile(A, P0)
    curve = lc.pointwise_peak(profile, laws)
    assert curve.peak_n_per_m > curve.sliding_n_per_m
    qfs = 0.6 * np.pi * A * 0.5e9
    one = lc.pointwise_response(profile, laws, [qfs])
    c = A * np.sqrt(1 - (qfs / (np.pi * A * 0.5e9)) ** 2)
    assert one.stick_half_width_m[0] == pytest.approx(c, rel=2e-3)
    expect = (
        2 * qfs / np.pi * np.arcsin(c / A)
        + 2 * quad(lambda x: 0.1 * lc.line_pressure(x, A, P0) + 0.1e9, c, A)[0]
    )
    assert one.lateral_n_per_m[0] == pytest.approx(expect, rel=2e-3)


def test_measured_profile_of_hertz_samples_gives_the_hertz_answers():
    x = np.linspace(-1.2 * A, 1.2 * A, 121)
    profile = lc.measured_profile(x, lc.line_pressure(x, A, P0), A)
    assert profile.load_n_per_m() == pytest.approx(np.pi * A * P0 / 2, rel=2e-3)
    res = lc.elastic_response(profile, lc.PointLaws.coulomb(MU), 0.5 * MU * np.pi * A * P0 / 2)
    assert res.stick_half_width_m == pytest.approx(A * np.sqrt(0.5), rel=5e-3)
    with pytest.raises(InputError, match="half_width_m"):
        lc.measured_profile(x, x, -1.0)
