"""The steady load-controlled cycle: Masing, Mindlin–Deresiewicz, first harmonic, limits."""

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.integrate import quad

from flatcontact.contact import cattaneo_mindlin as cm
from flatcontact.contact import cycle, cycle_output, mindlin, modified_cycle
from flatcontact.contact.cycle_reference import time_stepped_cycle
from flatcontact.contact.parameters import ContactParameters
from flatcontact.contact.summary import analyse
from flatcontact.foundation import units
from flatcontact.foundation.errors import InputError

P = ContactParameters()


def _loading(delta, p0, prm):
    return mindlin.lateral_force(delta, p0, prm).lateral_force_n


def _unloading_branch(lp, p0, prm):
    """(Δ, Q_amp − Q) along the unloading half of a loop."""
    n = (lp.displacement_m.size + 1) // 2
    u, q = lp.displacement_m[n - 1 :], lp.force_n[n - 1 :]
    return u[0] - u, lp.force_amplitude_n - q


@st.composite
def classical_limit(draw):
    """τ = σ: k = μ, τ0 = σ0 (τ0 = 0 allowed: then k > 0)."""
    k = draw(st.floats(0.5, 50.0))
    tau0 = draw(st.one_of(st.just(0.0), st.floats(1.0, 200.0)))
    prm = ContactParameters(k_mpa_per_gpa=k, tau0_mpa=tau0, mu_mpa_per_gpa=k, sigma0_mpa=tau0)
    return prm, draw(st.floats(0.1, 4.0)), draw(st.floats(0.02, 0.98))


@settings(max_examples=40, deadline=None)
@given(classical_limit())
def test_masing_rule_in_the_classical_limit(case):
    # τ = σ = k p + τ0: the return branch is the loading branch with Q and Δ doubled
    prm, p0_gpa, frac = case
    p0 = p0_gpa * units.GPA_TO_PA
    qa = frac * float(mindlin.peak_force(p0, prm).force_n)
    (lp,) = cycle.loops(qa, p0, prm, n_points=101)
    delta, drop = _unloading_branch(lp, p0, prm)
    np.testing.assert_allclose(
        drop, 2.0 * _loading(delta / 2.0, p0, prm), rtol=1e-9, atol=1e-12 * qa
    )
    # and the loop closes at the mirror point
    assert lp.displacement_m[0] == pytest.approx(
        -lp.displacement_m[-1 - (lp.displacement_m.size // 2)]
    )


def test_return_branch_is_the_loading_branch_of_the_doubled_contact():
    # σ < τ, k, μ >= 0: until all of S1 re-slips, Q_amp − Q(Δ) is the paper's Q(Δ) of a contact
    # with static strength τ + σ and slip traction 2σ; afterwards it is straight (elastic)
    p0 = 1.77e9
    eff = P.replace(
        k_mpa_per_gpa=P.k_mpa_per_gpa + P.mu_mpa_per_gpa,
        tau0_mpa=P.tau0_mpa + P.sigma0_mpa,
        mu_mpa_per_gpa=2 * P.mu_mpa_per_gpa,
        sigma0_mpa=2 * P.sigma0_mpa,
    )
    qa = 0.9 * float(mindlin.peak_force(p0, P).force_n)
    (lp,) = cycle.loops(qa, p0, P, n_points=401)
    delta, drop = _unloading_branch(lp, p0, P)
    u_amp = float(mindlin.displacement_on_rising_branch(qa, p0, P))
    s1 = float(mindlin.lateral_force(u_amp, p0, P).s)
    a = float(mindlin.contact_radius(p0, P))
    g2 = (P.k + P.mu) * p0 * s1**2 + (P.tau0_pa + P.sigma0_pa) * s1
    delta1 = np.pi * a * g2 / P.shear_modulus_pa
    first = delta <= delta1
    assert 0.2 < first.mean() < 0.95
    np.testing.assert_allclose(drop[first], _loading(delta[first], p0, eff), rtol=1e-9)
    # elastic tail: slope 2π a² (1 − s1)·G*/(π a) = 2 G* a (1 − s1)
    d, e = delta[~first], drop[~first]
    np.testing.assert_allclose(
        np.diff(e) / np.diff(d), 2 * P.shear_modulus_pa * a * (1 - s1), rtol=1e-9
    )


@st.composite
def sigma_below_tau(draw):
    """Any sign of k and μ with τ > 0, 0 <= σ <= τ on the contact at the drawn p0."""
    p0 = draw(st.floats(0.1, 4.0))
    tau0 = draw(st.floats(1.0, 200.0))
    sigma0 = draw(st.floats(0.0, 1.0)) * tau0
    k = draw(st.floats(-0.95 * tau0 / p0, 40.0))
    tau_c = k * p0 + tau0
    mu_lo = -sigma0 / p0
    mu_hi = (tau_c - sigma0) / p0
    mu = draw(st.floats(mu_lo, max(mu_lo, mu_hi)))
    prm = ContactParameters(k_mpa_per_gpa=k, tau0_mpa=tau0, mu_mpa_per_gpa=mu, sigma0_mpa=sigma0)
    prm.check_p0_gpa(p0)
    return prm, p0, draw(st.floats(0.02, 0.97))


@settings(max_examples=40, deadline=None)
@given(sigma_below_tau())
def test_loading_branch_of_the_element_rule_is_the_paper_q_of_u(case):
    prm, p0_gpa, frac = case
    p0 = p0_gpa * units.GPA_TO_PA
    u = frac * float(mindlin.full_slip_displacement(p0, prm)) * np.array([0.3, 1.0, 1.2])
    a = float(mindlin.contact_radius(p0, prm))
    x = prm.shear_modulus_pa * u / (np.pi * a)
    got = 2 * np.pi * a**2 * modified_cycle.loading_force_per_area(x, p0, prm)
    np.testing.assert_allclose(got, _loading(u, p0, prm), rtol=1e-9, atol=1e-15)


@settings(max_examples=40, deadline=None)
@given(sigma_below_tau())
@example(
    (
        ContactParameters(
            k_mpa_per_gpa=-2.2e-309, tau0_mpa=1.0, mu_mpa_per_gpa=0.0, sigma0_mpa=0.0
        ),
        1.0,
        0.5,
    )
)
def test_energy_equals_pi_qamp_quadrature_for_any_laws(case):
    # W from every element's own loop (closed form) = ∮Q du = π Q_amp u''_1 of the loop
    prm, p0_gpa, frac = case
    p0 = p0_gpa * units.GPA_TO_PA
    qa = frac * float(mindlin.peak_force(p0, prm).force_n)
    c = cycle.steady_cycle(qa, p0, prm)
    np.testing.assert_allclose(c.loop_area_j, c.dissipated_energy_j, rtol=2e-6, atol=0)
    assert np.all(c.dissipated_energy_j > 0)
    assert np.all(c.lockin_stiffness_n_per_m <= c.initial_stiffness_n_per_m * (1 + 1e-9))


def test_mindlin_deresiewicz_energy_against_johnson_and_the_loop():
    # Johnson Eq. 7.59 against the area between the closed-form branches (7.58 and mirror)
    mup, a, gj = 2.0e-6, 150e-9, 8e9
    for x in (0.05, 0.3, 0.7, 0.95):
        qa = x * mup

        def gap(q, qa=qa):
            down = cm.unloading_displacement(q, qa, mup, a, gj)
            up = -cm.unloading_displacement(-q, qa, mup, a, gj)
            return float(down - up)

        area, _ = quad(gap, -qa, qa, epsabs=0, epsrel=1e-12)
        assert float(cm.dissipated_energy(qa, mup, a, gj)) == pytest.approx(area, rel=1e-9)
    # the cycle module's classical model: same energy, and π Q_amp u''_1 of its loop
    c = cycle.cycles([1.0], P, "classical", amplitude_fractions=[0.1, 0.5, 0.9])[0]
    np.testing.assert_allclose(c.loop_area_j, c.dissipated_energy_j, rtol=1e-7)
    load = 2 / 3 * np.pi * c.contact_radius_m**2 * 1e9
    w = cm.dissipated_energy(
        c.force_amplitude_n, P.k * load, c.contact_radius_m, P.shear_modulus_pa / 4
    )
    np.testing.assert_allclose(c.dissipated_energy_j, w, rtol=1e-12)


def test_mindlin_deresiewicz_masing_and_closure():
    mup, a, gj = 1.0e-6, 100e-9, 5e9
    qa = 0.8 * mup
    q = np.linspace(-qa, qa, 11)
    d_top = cm.displacement(qa, mup, a, gj)
    # Masing: δ* − δ_unl(Q) = 2 δ_load((Q* − Q)/2)
    np.testing.assert_allclose(
        d_top - cm.unloading_displacement(q, qa, mup, a, gj),
        2 * cm.displacement((qa - q) / 2, mup, a, gj),
        rtol=1e-12,
        atol=1e-25,
    )
    assert float(cm.unloading_displacement(-qa, qa, mup, a, gj)) == pytest.approx(-d_top)
    back = cm.unloading_force(cm.unloading_displacement(q, qa, mup, a, gj), qa, mup, a, gj)
    np.testing.assert_allclose(back, q, rtol=1e-10, atol=1e-12 * qa)


def test_dissipation_vanishes_with_the_power_the_theory_gives():
    # modified, τ0 > 0: W ≈ (2π² a³/G*)(X/τ0)³ (τ0² + 4 τ0 σ0 − 3 σ0²)/3, X = Q_amp/(2π a²)
    p0 = 1.0e9
    a = float(mindlin.contact_radius(p0, P))
    q_peak = float(mindlin.peak_force(p0, P).force_n)
    qa = q_peak * np.array([1e-4, 1e-3])
    w = cycle.steady_cycle(qa, p0, P).dissipated_energy_j
    t0, s0 = P.tau0_pa, P.sigma0_pa
    x = qa / (2 * np.pi * a**2)
    lead = (
        2
        * np.pi**2
        * a**3
        / P.shear_modulus_pa
        * (x / t0) ** 3
        * (t0**2 + 4 * t0 * s0 - 3 * s0**2)
        / 3
    )
    # relative correction O(X/τ0) ~ Q_amp/Q_peak
    assert abs(w[0] / lead[0] - 1.0) < 1e-3
    assert abs(w[1] / lead[1] - 1.0) < 1e-2
    assert np.log(w[1] / w[0]) / np.log(10.0) == pytest.approx(3.0, abs=0.01)
    # Mindlin–Deresiewicz: W → Q*³/(36 G*_J a μP)
    c = cycle.cycles([1.0], P, "classical", amplitude_fractions=[1e-4, 1e-3])[0]
    load = 2 / 3 * np.pi * a**2 * p0
    gj = P.shear_modulus_pa / 4
    md_lead = c.force_amplitude_n**3 / (36 * gj * a * P.k * load)
    np.testing.assert_allclose(c.dissipated_energy_j / md_lead, 1.0, rtol=2e-3)
    # the paper's model in the classical limit with τ0 = σ0 = 0: W ∝ Q_amp^(5/2)
    lim = ContactParameters(k_mpa_per_gpa=200.0, tau0_mpa=0.0, mu_mpa_per_gpa=200.0, sigma0_mpa=0.0)
    qp = float(mindlin.peak_force(p0, lim).force_n)
    wl = cycle.steady_cycle(qp * np.array([1e-5, 1e-4]), p0, lim).dissipated_energy_j
    assert np.log(wl[1] / wl[0]) / np.log(10.0) == pytest.approx(2.5, abs=0.01)


def test_continuity_at_reversal_and_closure():
    for model in cycle.MODELS:
        p0 = 1.77e9
        c = cycle.cycles([1.77], P, model, amplitude_fractions=[0.6])[0]
        (lp,) = cycle.loops(c.force_amplitude_n, p0, P, model, n_points=2001)
        n = lp.force_n.size // 2
        u_top, q_top = lp.displacement_m[n], lp.force_n[n]
        assert q_top == pytest.approx(c.force_amplitude_n[0], rel=1e-12)
        assert u_top == pytest.approx(c.displacement_amplitude_m[0], rel=1e-12)
        assert lp.force_n[-1] == pytest.approx(-q_top, rel=1e-9)
        assert lp.displacement_m[-1] == pytest.approx(-u_top, rel=1e-9)
        # no jump anywhere: consecutive points differ by little
        assert np.max(np.abs(np.diff(lp.force_n))) < 5e-3 * q_top
        # right after the reversal every element re-sticks: slope = the initial stiffness
        du = lp.displacement_m[n] - lp.displacement_m[n + 1]
        dq = lp.force_n[n] - lp.force_n[n + 1]
        assert dq / du == pytest.approx(c.initial_stiffness_n_per_m, rel=1e-4)


@pytest.mark.parametrize(
    "prm, p0_gpa",
    # the second: k < 0, p0 > τ0/(2|k|): the centre slips first, an annulus sticks
    [(P, 1.77), (ContactParameters(k_mpa_per_gpa=-10.0, sigma0_mpa=2.0), 2.0)],
)
def test_closed_forms_against_direct_time_stepping(prm, p0_gpa):
    p0 = p0_gpa * units.GPA_TO_PA
    c = cycle.cycles([p0_gpa], prm, amplitude_fractions=[0.5, 0.9])[0]
    for i, qa in enumerate(c.force_amplitude_n):
        ref = time_stepped_cycle(qa, p0, prm, n_elements=1500, steps=360)
        assert ref.dissipated_energy_j == pytest.approx(c.dissipated_energy_j[i], rel=1e-2)
        assert ref.in_phase_displacement_m == pytest.approx(c.in_phase_displacement_m[i], rel=2e-3)
        assert ref.quadrature_displacement_m == pytest.approx(
            c.quadrature_displacement_m[i], rel=1e-2
        )


def test_slow_amplitude_ramp_reaches_the_same_steady_cycle():
    # the experiment ramps the amplitude up; a sudden start and a ramp give the same loop
    p0 = 1.77e9
    c = cycle.cycles([1.77], P, amplitude_fractions=[0.8])[0]
    ref = time_stepped_cycle(
        c.force_amplitude_n[0], p0, P, n_elements=1500, steps=360, ramp_cycles=3
    )
    assert ref.dissipated_energy_j == pytest.approx(c.dissipated_energy_j[0], rel=1e-2)
    assert ref.in_phase_displacement_m == pytest.approx(c.in_phase_displacement_m[0], rel=2e-3)
    # and the loop is centred (no offset from the history)
    assert np.max(ref.displacement_m) == pytest.approx(-np.min(ref.displacement_m), rel=2e-3)


def test_lockin_limits_and_paper_construction():
    c = cycle.lockin_curve(1.0e9, P)
    k0 = c.initial_stiffness_n_per_m
    tiny = cycle.steady_cycle(1e-6 * c.gross_sliding_force_n, 1.0e9, P)
    assert tiny.lockin_stiffness_n_per_m[0] == pytest.approx(k0, rel=1e-5)
    assert tiny.paper_stiffness_n_per_m[0] == pytest.approx(k0, rel=1e-5)
    assert tiny.loss_tangent[0] < 1e-5
    assert np.all(np.diff(c.lockin_stiffness_n_per_m) < 0)
    # the lock-in stiffness stays finite up to gross sliding; the paper's falls towards 0
    assert c.lockin_stiffness_n_per_m[-1] > 0.4 * k0
    assert c.paper_stiffness_n_per_m[-1] < 0.1 * k0  # → 0 logarithmically at Q_peak
    assert np.all(c.loss_tangent > 0)


def test_input_errors_name_the_parameter():
    q_peak = float(mindlin.peak_force(1e9, P).force_n)
    with pytest.raises(InputError, match=r"^lateral_force_amplitude_un = .* at or above gross"):
        cycle.steady_cycle(q_peak, 1e9, P)
    with pytest.raises(InputError, match="lateral_force_amplitude_un"):
        cycle.cycles([1.0], P, amplitudes_un=[q_peak * 1e6 * 1.01])
    with pytest.raises(InputError, match="amplitude_fraction"):
        cycle.cycles([1.0], P, amplitude_fractions=[1.0])
    with pytest.raises(InputError, match="sigma0_mpa"):
        cycle.steady_cycle(1e-7, 1e9, P.replace(sigma0_mpa=30.0))
    with pytest.raises(InputError, match="mu_mpa_per_gpa"):
        cycle.steady_cycle(1e-7, 1e9, P.replace(mu_mpa_per_gpa=40.0))
    with pytest.raises(InputError, match="k_mpa_per_gpa"):
        cycle.steady_cycle(1e-8, 1e9, P.replace(k_mpa_per_gpa=-1.0), model="classical")
    with pytest.raises(InputError, match="model must be one of"):
        cycle.steady_cycle(1e-8, 1e9, P, model="hertz")


def test_records_and_dataset_merge_with_contact_nc():
    import xarray as xr

    cyc = cycle.cycles([1.0, 1.77], P, amplitude_fractions=[0.5, 0.9])
    rows = cycle_output.cycle_records(cyc)
    assert len(rows) == 4
    for key in (
        "p0_gpa",
        "lateral_force_amplitude_un",
        "dissipated_energy_per_cycle_fj",
        "lockin_stiffness_n_per_m",
        "lockin_quadrature_nm",
    ):
        assert all(key in r for r in rows)
    r = rows[0]
    assert r["dissipated_energy_per_cycle_fj"] == pytest.approx(
        np.pi * r["lateral_force_amplitude_un"] * 1e-6 * r["lockin_quadrature_nm"] * 1e-9 * 1e15,
        rel=1e-5,
    )
    ds = cycle_output.cycle_dataset(cyc, P, n_points=21)
    assert ds["cycle_loop_force"].shape == (2, 2, 41)
    merged = xr.merge([analyse([1.0, 1.77], P).to_dataset(), ds])
    assert merged.sizes["p0"] == 2
    assert merged["cycle_loop_force"].attrs["units"] == "uN"


def test_figures_draw_what_they_say(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    from flatcontact.plots import cycle as pc

    fig = pc.fig_loops(P, p0_gpa=(1.0,), fractions=(0.3, 0.9))
    (ax,) = fig.axes
    lines = ax.get_lines()
    # two loops, the loading branch, and the two axis lines
    loops = [ln for ln in lines if ln.get_label().startswith("Q_amp")]
    assert len(loops) == 2
    u, q = loops[1].get_data()
    assert np.max(u) == pytest.approx(-np.min(u))
    assert np.max(q) == pytest.approx(-np.min(q))
    fig2 = pc.fig_lockin_overlay(P, p0_gpa=(1.0, 2.0))
    assert len(fig2.axes[0].get_lines()) == 4
    fig2.savefig(tmp_path / "overlay.png", dpi=40)
    assert (tmp_path / "overlay.png").stat().st_size > 0
