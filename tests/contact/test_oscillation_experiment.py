"""Oscillatory stiffness, collapse, knee; measured-data CSV, collapse detection, inverse τ0."""

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

from flatcontact.contact import experiment as ex
from flatcontact.contact import mindlin as m
from flatcontact.contact import oscillation as osc
from flatcontact.contact.measured import load_stiffness_csv, parse_unit
from flatcontact.contact.parameters import ContactParameters
from flatcontact.foundation.errors import InputError

P = ContactParameters()
P0 = 1.77e9


def _u_brentq(q, p0, prm):
    pk = m.peak_force(p0, prm)
    if q <= 0:
        return 0.0
    return brentq(
        lambda u: float(m.lateral_force(u, p0, prm).lateral_force_n) - q,
        0.0,
        float(pk.displacement_m),
        xtol=1e-24,
    )


def _mean_u_quad(qmax, p0, prm):
    val = quad(
        lambda t: _u_brentq(qmax * np.sin(t), p0, prm) ** 2, 0, np.pi / 2, epsabs=0, epsrel=1e-10
    )[0]
    return np.sqrt(2 / np.pi * val)


@pytest.mark.parametrize("frac", [0.1, 0.6, 0.95])
def test_mean_displacement_against_direct_integration(frac):
    qpk = float(m.peak_force(P0, P).force_n)
    mu, _ = osc.mean_displacement(frac * qpk, P0, P)
    assert float(mu) == pytest.approx(_mean_u_quad(frac * qpk, P0, P), rel=1e-8)


def test_stiffness_is_derivative_of_mean_curve():
    qpk = float(m.peak_force(P0, P).force_n)
    for frac in (0.2, 0.7, 0.99):
        q, h = frac * qpk, 1e-4 * qpk
        up, _ = osc.mean_displacement(q + h, P0, P)
        um, _ = osc.mean_displacement(q - h, P0, P)
        k_fd = (2 * h / np.sqrt(2)) / float(up - um)
        assert float(osc.lateral_stiffness(q, P0, P)) == pytest.approx(k_fd, rel=1e-5)


def test_initial_stiffness_is_full_stick():
    a = float(m.contact_radius(P0, P))
    k0 = 2 * P.shear_modulus_pa * a  # = 8 G*_J a
    assert float(m.initial_lateral_stiffness(P0, P)) == pytest.approx(k0)
    qpk = float(m.peak_force(P0, P).force_n)
    assert float(osc.lateral_stiffness(1e-7 * qpk, P0, P)) == pytest.approx(k0, rel=1e-5)
    assert float(osc.lateral_stiffness(0.0, P0, P)) == pytest.approx(k0)


def test_curve_collapse_and_knee():
    c = osc.stiffness_curve(P0, P)
    a = c.contact_radius_m
    pk = m.peak_force(P0, P)
    # decreasing stiffness, vanishing at the peak of Q(u)
    assert np.all(np.diff(c.stiffness_n_per_m) <= 1e-9 * c.initial_stiffness_n_per_m)
    assert c.stiffness_n_per_m[-1] == 0.0
    assert c.stiffness_n_per_m[-2] < 0.1 * c.initial_stiffness_n_per_m
    assert c.collapse_stress_amplitude_pa == pytest.approx(float(pk.force_n) / (np.pi * a**2))
    assert c.collapse_stress_rms_pa == pytest.approx(c.collapse_stress_amplitude_pa / np.sqrt(2))
    np.testing.assert_allclose(c.stress_rms_pa, c.stress_amplitude_pa / np.sqrt(2))
    np.testing.assert_allclose(c.mean_force_n, c.q_max_n / np.sqrt(2))
    # knee: k = 0.5 k0 there, below the collapse
    kq = float(osc.lateral_stiffness(c.knee_stress_amplitude_pa * np.pi * a**2, P0, P))
    assert kq == pytest.approx(0.5 * c.initial_stiffness_n_per_m, rel=1e-8)
    assert c.knee_stress_amplitude_pa < c.collapse_stress_amplitude_pa


def test_monotone_q_collapses_at_saturation_by_a_drop():
    prm = P.replace(tau0_mpa=5.0, sigma0_mpa=20.0)
    c = osc.stiffness_curve(P0, prm)
    pk = m.peak_force(P0, prm)
    assert c.collapse_force_n == pytest.approx(float(pk.saturated_force_n))
    assert c.stiffness_n_per_m[-2] > 0.1 * c.initial_stiffness_n_per_m
    assert c.stiffness_n_per_m[-1] == 0.0


def test_amplitude_above_peak_rejected():
    qpk = float(m.peak_force(P0, P).force_n)
    with pytest.raises(InputError, match="peak"):
        osc.mean_displacement(1.01 * qpk, P0, P)


# ------------------------------------------------------------------ measured data


def test_csv_units_and_column_order(tmp_path):
    f1 = tmp_path / "a.csv"
    f1.write_text("mean shear stress [MPa],lateral stiffness [N/m]\n1,1000\n2,900\n3,500\n4,10\n")
    f2 = tmp_path / "b.csv"
    f2.write_text(
        "# comment\nlateral_stiffness_un_per_nm,mean_shear_stress_kpa\n1,1000\n0.9,2000\n0.5,3000\n0.01,4000\n"
    )
    d1, d2 = load_stiffness_csv(f1), load_stiffness_csv(f2)
    np.testing.assert_allclose(d1.stress_pa, [1e6, 2e6, 3e6, 4e6])
    np.testing.assert_allclose(d1.stiffness_n_per_m, d2.stiffness_n_per_m)
    np.testing.assert_allclose(d1.stress_pa, d2.stress_pa)
    assert parse_unit("µN/nm") == ("stiffness", pytest.approx(1e3))
    assert parse_unit("mN/m") == ("stiffness", pytest.approx(1e-3))
    assert parse_unit("GPa") == ("stress", 1e9)


@pytest.mark.parametrize(
    "text,match",
    [
        ("stress [MPa]\n1\n2\n3\n4\n", "expected 2 columns"),
        ("stress,stiffness [N/m]\n1,2\n", "no unit"),
        ("stress [MPa],stiffness [N/s]\n1,2\n", "unknown unit"),
        ("stress [MPa],other [GPa]\n1,2\n", "one stress column and one stiffness"),
        ("stress [MPa],k [N/m]\n1,2\n2,nan\n3,1\n4,1\n", "NaN"),
        ("stress [MPa],k [N/m]\n1,2\n2,x\n3,1\n4,1\n", "not numeric"),
        ("stress [MPa],k [N/m]\n1,2\n", "at least 4"),
    ],
)
def test_csv_rejects_bad_files(tmp_path, text, match):
    f = tmp_path / "bad.csv"
    f.write_text(text)
    with pytest.raises(InputError, match=match) as err:
        load_stiffness_csv(f)
    assert "\n" not in str(err.value)


def test_collapse_stress_definition():
    s = np.array([1, 2, 3, 4, 5, 6.0])
    k = np.array([100, 100, 100, 90, 10, 0.0])
    c = ex.collapse_stress(s, k, fraction=0.2)
    # threshold 20, between (4, 90) and (5, 10): 4 + 70/80
    assert c.stress_pa == pytest.approx(4 + 70 / 80)
    assert c.plateau_n_per_m == 100
    with pytest.raises(InputError, match="no collapse"):
        ex.collapse_stress(s, np.full(6, 50.0))


def test_model_collapse_close_to_peak_and_monotone_in_tau0():
    a = float(m.contact_radius(P0, P))
    peak_stress = float(m.peak_force(P0, P).force_n) / (np.pi * a**2)
    c = ex.model_collapse_stress(P0, P)
    assert 0.98 * peak_stress < c < peak_stress
    tau0 = np.linspace(1.0, 300.0, 12)
    vals = [ex.model_collapse_stress(P0, P.replace(tau0_mpa=t)) for t in tau0]
    assert np.all(np.diff(vals) > 0)


@pytest.mark.parametrize(
    "measure,tau0_true", [("amplitude", 26.7), ("amplitude", 145.0), ("rms", 60.0)]
)
def test_inverse_round_trip_on_synthetic_data(measure, tau0_true):
    """Synthetic data made by the model (+2% noise) give back τ0."""
    rng = np.random.default_rng(7)
    truth = P.replace(tau0_mpa=tau0_true)
    cs = ex.model_collapse_stress(P0, truth, measure=measure)
    stress = np.sort(
        np.concatenate([np.linspace(0.01, 1.3, 50) * cs, cs * (1 + 0.002 * np.arange(-3, 4))])
    )
    k = ex.model_stiffness_at_stress(stress, P0, truth, measure) * (
        1 + 0.02 * rng.normal(size=stress.size)
    )
    measured = ex.collapse_stress(stress, k)
    fitted = ex.fit_tau0(measured.stress_pa, P0, P, measure=measure)
    assert fitted == pytest.approx(tau0_true, rel=0.02)


def test_fit_tau0_rejects_unreachable():
    with pytest.raises(InputError, match="below the model"):
        ex.fit_tau0(1e3, P0, P)
