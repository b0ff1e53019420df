"""The amplitude ramp's lock-in stiffness k' = Q_amp/u'_1 (flatcontact.contact.cycle's
definition) on synthetic loops against closed forms, and the model's element rule against the
contact stage's steady cycle."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from flatcontact.asperity import ramp
from flatcontact.contact import cycle, mindlin
from flatcontact.contact import line_contact as lc
from flatcontact.contact.parameters import ContactParameters
from flatcontact.foundation.errors import InputError


def _loop(branch_down, u_amp, n=2001):
    """A loop from +U down to −U and back, the rising branch the falling one's mirror image
    (Masing): Q_down(u) given, Q_up(u) = −Q_down(−u)."""
    u_down = np.linspace(u_amp, -u_amp, n)
    u_up = -u_down[1:]
    return np.concatenate([u_down, u_up]), np.concatenate(
        [branch_down(u_down), -branch_down(-u_up)]
    )


@settings(max_examples=30, deadline=None)
@given(
    k=st.floats(0.1, 1e3),
    u_amp=st.floats(1e-3, 10.0),
    q_offset=st.floats(-100.0, 100.0),
    u_offset=st.floats(-5.0, 5.0),
)
def test_a_linear_cycle_reads_its_spring_and_no_loss(k, u_amp, q_offset, u_offset):
    theta = np.linspace(0.0, 2 * np.pi, 361)
    u = u_amp * np.cos(theta)
    li = ramp.loop_lockin(u + u_offset, k * u + q_offset)
    assert li.stiffness == pytest.approx(k, rel=1e-12)
    assert li.in_phase == pytest.approx(u_amp, rel=1e-12)
    assert li.displacement_amplitude == pytest.approx(u_amp, rel=1e-12)
    assert abs(li.loss_tangent) < 1e-9


def _bilinear_closed_form(k1, k2, u_y, u_amp):
    """A Masing loop of the hardening element (spring k1 + (spring k2 ‖ slider k2·u_y))...
    virgin Q = (k1+k2) u up to u_y, then k1 u + k2 u_y; the return branch
    Q = Q_amp − 2 f((U − u)/2). u'_1 = (2/π)∫_0^{2U} √(1 − r²) dΔ, r(Δ) = 1 − 2f(Δ/2)/Q_amp,
    piecewise linear: each piece (Q_amp/slope)[F(r_start) − F(r_end)], F = ∫√(1 − r²)dr."""

    def f(x):
        return np.where(x <= u_y, (k1 + k2) * x, k1 * x + k2 * u_y)

    q_amp = float(f(u_amp))

    def F(r):
        return 0.5 * (r * math.sqrt(1 - r * r) + math.asin(r))

    r_kink = 1 - 2 * float(f(u_y)) / q_amp
    piece1 = q_amp / (k1 + k2) * (F(1.0) - F(r_kink))
    piece2 = q_amp / k1 * (F(r_kink) - F(-1.0))
    in_phase = (2 / math.pi) * (piece1 + piece2)
    # W = loop area: Masing loop of a bilinear element, 4 k2 u_y (U − u_y) (the slider's)
    work = 4 * k2 * u_y * (u_amp - u_y)
    return f, q_amp, in_phase, work


def test_a_bilinear_masing_cycle_against_its_closed_form():
    k1, k2, u_y, u_amp = 2.0, 5.0, 0.3, 1.0
    f, q_amp, in_phase, work = _bilinear_closed_form(k1, k2, u_y, u_amp)
    u, q = _loop(lambda u: q_amp - 2 * f((u_amp - u) / 2), u_amp)
    li = ramp.loop_lockin(u, q)
    assert li.force_amplitude == pytest.approx(q_amp, rel=1e-12)
    assert li.in_phase == pytest.approx(in_phase, rel=1e-6)
    assert li.stiffness == pytest.approx(q_amp / in_phase, rel=1e-6)
    # the secant Q_amp/U is below k' (the loop bulges) and above the hardening slope k1
    assert k1 < q_amp / u_amp < li.stiffness < k1 + k2
    assert li.quadrature * math.pi * q_amp == pytest.approx(work, rel=1e-6)


def test_the_cattaneo_mindlin_loop_reads_the_contact_stages_lockin_stiffness():
    """The classical loop of contact/cycle.py (closed forms, Masing) through loop_lockin gives
    the k' and the loss of steady_cycle (its own Gauss quadrature)."""
    params = ContactParameters()
    p0 = 1e9
    mdl = cycle.CycleModel("classical", p0, params)
    amps = np.array([0.3, 0.7, 0.95]) * mdl.gross
    ref = cycle.steady_cycle(amps, p0, params, "classical")
    for i, lp in enumerate(cycle.loops(amps, p0, params, "classical", n_points=4001)):
        # loops() starts at the bottom: rotate it to start at the top
        top = int(np.argmax(lp.displacement_m))
        u = np.concatenate([lp.displacement_m[top:], lp.displacement_m[1 : top + 1]])
        q = np.concatenate([lp.force_n[top:], lp.force_n[1 : top + 1]])
        li = ramp.loop_lockin(u, q)
        assert li.stiffness == pytest.approx(ref.lockin_stiffness_n_per_m[i], rel=2e-5)
        assert li.loss_tangent == pytest.approx(ref.loss_tangent[i], rel=1e-3)


def test_a_load_controlled_reading_jumps_over_a_force_drop():
    """Under load control u jumps where the displacement-controlled force falls back: a loop
    with a dip on each branch reads as the same loop with the dip filled (the envelope)."""
    theta = np.linspace(0.0, np.pi, 401)
    u_down = np.cos(theta)
    q_down = 3.0 * u_down + 0.5 * np.sin(theta)
    dip = q_down.copy()
    dip[150:170] += np.linspace(0, 0.4, 20)  # falling branch rises back for a while
    u = np.concatenate([u_down, -u_down[1:]])
    filled = ramp.loop_lockin(u, np.concatenate([np.minimum.accumulate(dip), -q_down[1:]]))
    raw = ramp.loop_lockin(u, np.concatenate([dip, -q_down[1:]]))
    assert raw.stiffness == pytest.approx(filled.stiffness, rel=1e-12)


def test_the_element_rule_on_a_hertz_sphere_is_the_contact_stages_modified_cycle():
    """ramp.model_lockin (the element rule, numerical, on a pressure profile) against
    contact.cycle.steady_cycle (the modified model's closed forms): k'/k0 at Q_amp/Q_peak."""
    params = ContactParameters()
    p0 = 1e9
    a = float(mindlin.contact_radius(p0, params))
    peak_ref = float(mindlin.peak_force(p0, params).force_n)
    fractions = np.array([0.2, 0.5, 0.8, 0.95])
    ref = cycle.steady_cycle(fractions * peak_ref, p0, params, "modified")
    laws = lc.PointLaws(
        k=params.k_mpa_per_gpa * 1e-3,
        tau0_pa=params.tau0_mpa * 1e6,
        mu=params.mu_mpa_per_gpa * 1e-3,
        sigma0_pa=params.sigma0_mpa * 1e6,
    )
    x = a * np.sin(np.linspace(0, np.pi / 2, 4001))
    el = ramp.elements("sphere", x, p0 * np.sqrt(np.clip(1 - (x / a) ** 2, 0, None)), a, laws, 0)
    peak, k = ramp.model_lockin(el, fractions, k0_n_per_m=1.0)
    assert peak == pytest.approx(peak_ref, rel=2e-3)
    expected = ref.lockin_stiffness_n_per_m / ref.initial_stiffness_n_per_m
    assert np.array(k) == pytest.approx(expected, rel=2e-3)
    # k' falls with amplitude (the Fig. 6 softening)
    assert np.all(np.diff(k) < 0)
    assert ramp.model_lockin(el, [None, 1.2], 1.0)[1] == [None, None]


def test_the_ramp_path_cycles_each_amplitude_in_small_steps():
    path, loops = ramp.ramp_path([0.1, 0.25], 0.05)
    assert np.max(np.abs(np.diff(path))) <= 0.05 + 1e-12
    assert path[0] == 0
    for (first, last), amp in zip(loops, [0.1, 0.25], strict=True):
        assert path[first] == pytest.approx(amp)
        assert path[last] == pytest.approx(amp)
        assert path[first : last + 1].min() == pytest.approx(-amp)
    assert loops[0][1] < loops[1][0]


@pytest.mark.parametrize("amps", [[0.2, 0.1], [0.1, 0.1], [-0.1], [float("nan")]])
def test_a_ramp_that_is_not_increasing_and_positive_is_refused(amps):
    with pytest.raises(InputError, match="ramp_amplitudes_angstrom"):
        ramp.check_amplitudes(amps)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (
            "asperity: {ramp_amplitudes_angstrom: [0.2, 0.1]}\n",
            "c.yaml: asperity.ramp_amplitudes_angstrom: expected strictly increasing amplitudes",
        ),
        (
            "asperity: {ramp_amplitudes_angstrom: [0.1, 20]}\n",
            "c.yaml: asperity.ramp_amplitudes_angstrom.1: expected 0.001 <= value <= 10 Å, got 20",
        ),
        ("asperity: {ramp_amplitudes_angstrom: []}\n", "asperity.ramp_amplitudes_angstrom"),
        ("asperity: {tip: slab3}\n", "c.yaml: asperity.tip: expected 'slab2' or 'slab1'"),
    ],
)
def test_bad_ramp_settings_are_one_line_naming_the_field(tmp_path, text, message):
    from flatcontact.config import load_config

    path = tmp_path / "c.yaml"
    path.write_text(text)
    with pytest.raises(InputError) as info:
        load_config(path)
    assert message in str(info.value)
    assert "\n" not in str(info.value)


def test_compare_ramp_on_a_linear_atom_loop_and_a_hertz_line_contact():
    """Atoms that are a linear spring K0 read k' = K0 at every amplitude; the model (the
    element rule on a Hertz line contact, u = Q_fs/K0) starts at K0 and softens, and the
    ratios are atoms/model; the figure draws both."""
    from flatcontact.plots.asperity import fig_lockin_ramp

    k0 = 40.0
    path, loops = ramp.ramp_path([0.1, 0.2, 0.3], 0.05)
    q = k0 * path * 1e-10 + 3e-12  # an offset at u = 0 (fcc(111)'s Q0) changes nothing
    a = 2e-9
    prof = lc.hertz_profile(a, 1e9)
    laws = lc.PointLaws(k=0.1, tau0_pa=50e6, mu=0.05, sigma0_pa=20e6)
    el = ramp.elements("cylinder", prof.x_m, prof.p_pa, a, laws, axis_m=5e-10)
    peak, _ = ramp.model_lockin(el, [0.5], k0)
    # τ > σ everywhere: the pointwise model peaks above its sliding force ∫σ dx
    sliding = lc.sliding_force(prof, laws) * 5e-10
    assert sliding < peak < 1.5 * sliding
    q_peak = 1.5 * k0 * 0.3e-10  # the atoms' slide peaked above the ramp
    out = ramp.compare_ramp(path, q, loops, q_peak, k0, {"hertz": el})
    rows = out["amplitudes"]
    for r, amp in zip(rows, [0.1, 0.2, 0.3], strict=True):
        assert r["atoms_lockin_n_per_m"] == pytest.approx(k0, rel=1e-9)
        assert r["q_amp_over_q_peak"] == pytest.approx(k0 * amp * 1e-10 / q_peak, rel=1e-9)
        assert r["ratio_atoms_over_model_hertz"] == pytest.approx(
            k0 / r["model_hertz_lockin_n_per_m"], rel=1e-12
        )
    k_model = [r["model_hertz_lockin_n_per_m"] for r in rows]
    assert np.all(np.diff(k_model) < 0) and k_model[0] < k0
    curve = out["model_curve"]["model_hertz_lockin_n_per_m"]
    assert curve[0] == pytest.approx(k0, rel=0.02)  # Q_amp -> 0: all stuck, the fitted K0
    assert np.all(np.diff(curve) < 0)
    fig = fig_lockin_ramp([out], [1.0])
    assert len(fig.axes[0].lines) == 3  # atoms, the model's points, the model's curve
