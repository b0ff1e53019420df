"""Sliding path, τ, σ_MSS and shear stiffness against closed-form landscapes."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize_scalar

from flatcontact.analysis import synthetic as syn
from flatcontact.analysis.diagnostics import PathNotPeriodicWarning
from flatcontact.analysis.friction import friction_along_path
from flatcontact.analysis.path import minimum_energy_path, zero_perpendicular_force_path
from flatcontact.analysis.periodic import PeriodicSurface

V = 1e-3  # eV/Å²


def _surface(pattern, a1, a2, n=32, scale=V):
    sa = np.arange(n) / n
    s = np.stack(np.meshgrid(sa, sa, indexing="ij"), -1)
    return PeriodicSurface(scale * pattern(s)[0], a1, a2)


def test_winding_canyon_path_follows_the_floor_exactly():
    a, b, m, lam, w = 4.0, 6.0, 1, 0.08, 0.5
    a1, a2 = syn.rectangular_cell(a, b)
    path = zero_perpendicular_force_path(_surface(syn.canyon(m, lam, w), a1, a2), 90.0)
    x, y = path.xy_angstrom.T
    floor = a * (m * y / b + lam * np.sin(2 * np.pi * y / b))
    assert np.max(np.abs((x - x[0]) - (floor - floor[0]))) < 1e-10
    assert np.ptp(x - m * a * y / b) > 0.5  # not a straight line
    np.testing.assert_allclose(path.period_vector, a1 + a2)  # tilted: ends one cell to the side
    fr = friction_along_path(path)
    k = 2 * np.pi / b
    assert fr.tau_ev_per_a3 == pytest.approx(V * w * k, rel=1e-10)
    assert fr.sigma_ev_per_a3 == pytest.approx(2 * V * w / b, rel=1e-10)
    assert fr.shear_stiffness_ev_per_a4 == pytest.approx(V * w * k**2, rel=1e-10)
    # the curvature along t of the relaxed path is the Schur complement, not e_tt
    assert fr.tau_position_angstrom == pytest.approx(b / 4, abs=1e-8)


def test_double_well_profile_gives_analytic_barriers_tau_and_stiffness():
    a, b, beta = 4.0, 6.0, 0.6
    a1, a2 = syn.rectangular_cell(a, b)
    pattern = syn.cosine_sum([(1, 0, -0.8), (0, 1, -1.0), (0, 2, -beta)])
    fr = friction_along_path(zero_perpendicular_force_path(_surface(pattern, a1, a2), 90.0))
    # two barriers per period: V(1 + 2β + 1/8β) and V(2β - 1 + 1/8β)
    heights = sorted(bb.height for bb in fr.barriers)
    assert heights == pytest.approx(
        sorted([V * (1 + 2 * beta + 1 / (8 * beta)), V * (2 * beta - 1 + 1 / (8 * beta))]),
        rel=1e-10,
    )
    assert fr.minima_t_angstrom == pytest.approx([0.0, b / 2], abs=1e-9)
    assert fr.sigma_ev_per_a3 == pytest.approx(V * (4 * beta + 1 / (4 * beta)) / b, rel=1e-10)

    def force(y):
        return (
            -V
            * (2 * np.pi / b)
            * (np.sin(2 * np.pi * y / b) + 2 * beta * np.sin(4 * np.pi * y / b))
        )

    y_top = b * np.arccos(-1 / (4 * beta)) / (2 * np.pi)
    best = minimize_scalar(force, bounds=(0, y_top), method="bounded", options={"xatol": 1e-12})
    assert fr.tau_ev_per_a3 == pytest.approx(-best.fun, rel=1e-10)
    assert fr.tau_limited_by == "barrier top"
    assert fr.shear_stiffness_ev_per_a4 == pytest.approx(
        V * (2 * np.pi / b) ** 2 * (1 + 4 * beta), rel=1e-10
    )


@pytest.mark.parametrize("rotation, direction", [(0.0, 0.0), (90.0, 90.0), (37.0, 37.0)])
def test_hexagonal_three_cosine_pulled_along_a_lattice_vector(rotation, direction):
    a = 4.916
    a1, a2 = syn.hexagonal_cell(a, rotation)
    path = zero_perpendicular_force_path(
        _surface(syn.three_cosine(a1, a2), a1, a2, scale=-V), direction
    )
    fr = friction_along_path(path)
    # straight along a1 through lattice points (minima, -3V) and bond midpoints (saddles, +V)
    assert np.ptp(path.n_angstrom) < 1e-9
    np.testing.assert_allclose(path.period_vector, a1, atol=1e-9)
    assert fr.tau_ev_per_a3 == pytest.approx(4 * np.pi * V / a, rel=1e-10)
    assert fr.sigma_ev_per_a3 == pytest.approx(4 * V / a, rel=1e-10)
    assert fr.shear_stiffness_ev_per_a4 == pytest.approx(2 * V * (2 * np.pi / a) ** 2, rel=1e-10)


def test_pulling_across_the_lattice_jumps_between_valleys():
    a1, a2 = syn.hexagonal_cell()
    surf = _surface(syn.three_cosine(a1, a2), a1, a2, scale=-V)
    path = zero_perpendicular_force_path(surf, 90.0)  # y is not a lattice direction of a1 ∥ x
    fr = friction_along_path(path)
    assert len(path.jumps) == 1 and fr.tau_limited_by == "jump"
    jump = path.jumps[0]
    assert jump.energy_after < jump.energy_before  # a slip dissipates energy
    assert path.period_vector @ np.array([0.0, 1.0]) == pytest.approx(path.length_angstrom)
    # equivalent end, and more dissipation than pulling along the valley
    assert fr.sigma_ev_per_a3 > 4 * V / 4.916


def test_minimum_energy_path_barrier_is_the_saddle_whatever_the_direction():
    a1, a2 = syn.hexagonal_cell()
    surf = _surface(syn.three_cosine(a1, a2), a1, a2, scale=-V)
    r0, _ = surf.global_minimum()
    for end in (r0 + a1, r0 + a1 + 2 * a2):  # along a valley, and across (zigzag via a minimum)
        mep = minimum_energy_path(surf, r0, end)
        assert mep.converged
        assert mep.barrier == pytest.approx(4 * V, rel=1e-9)
        s = surf.fractional(mep.saddle_xy_angstrom) * 2  # saddles at half lattice vectors
        np.testing.assert_allclose(s - np.round(s), 0, atol=1e-7)
    # the zero-perpendicular-force path across y passes (within its fold resolution) the same
    # saddle: it cannot climb less than the MEP
    zpf = zero_perpendicular_force_path(surf, 90.0)
    assert np.max(zpf.energy) - zpf.energy[0] == pytest.approx(mep.barrier, rel=1e-5)


def test_path_that_does_not_close_warns_and_reports_tracked_length():
    a1, a2 = syn.hexagonal_cell()
    surf = _surface(syn.three_cosine(a1, a2), a1, a2, scale=-V)
    with pytest.warns(PathNotPeriodicWarning, match="no minimum equivalent"):
        path = zero_perpendicular_force_path(surf, 0.0, max_length_angstrom=3.0)
    assert not path.periodic and path.length_angstrom == pytest.approx(3.0)


def _ratchet(beta, phi, extra=()):
    """Separable landscape: confinement across y, an asymmetric two-barrier profile along y."""
    return syn.cosine_sum([(1, 0, -2.0), (0, 1, -1.0), (0, 2, -beta, phi), *extra])


def _profile_reference(pattern, b, n=200_001):
    """Force per area along y (at s_a = 0), sampled densely from the global minimum on."""
    s_b = np.linspace(0.0, 1.0, n)
    s = np.stack([np.zeros_like(s_b), s_b], -1)
    g, grad, _ = pattern(s)
    start = int(np.argmin(g))
    order = (np.arange(n - 1) + start) % (n - 1)
    return V * grad[order, 1] / b


def test_period_shear_strength_exceeds_tau_when_the_second_barrier_is_harder():
    a, b = 4.0, 6.0
    a1, a2 = syn.rectangular_cell(a, b)
    pattern = _ratchet(beta=0.9, phi=2.2)
    fr = friction_along_path(zero_perpendicular_force_path(_surface(pattern, a1, a2), 90.0))
    force = _profile_reference(pattern, b)
    first_top = int(np.argmax(np.diff(np.sign(force)) < 0))  # first force zero going down
    assert fr.tau_ev_per_a3 == pytest.approx(force[: first_top + 1].max(), rel=1e-6)
    assert fr.tau_period_ev_per_a3 == pytest.approx(force.max(), rel=1e-6)
    # the case is meaningful: escaping the global minimum is easier than crossing the period
    assert fr.tau_period_ev_per_a3 > 1.2 * fr.tau_ev_per_a3
    assert fr.tau_period_mpa == pytest.approx(fr.tau_period_ev_per_a3 * 160217.6634, rel=1e-9)


@settings(max_examples=25, deadline=None)
@given(
    beta=st.floats(0.0, 1.5),
    phi=st.floats(0.0, 2 * np.pi),
    gamma=st.floats(0.0, 0.6),
    psi=st.floats(0.0, 2 * np.pi),
)
def test_period_shear_strength_bounds_tau_and_sigma(beta, phi, gamma, psi):
    a1, a2 = syn.rectangular_cell(4.0, 6.0)
    pattern = _ratchet(beta, phi, extra=[(0, 3, -gamma, psi)])
    fr = friction_along_path(zero_perpendicular_force_path(_surface(pattern, a1, a2), 90.0))
    tol = 1e-9 * V
    assert fr.tau_ev_per_a3 <= fr.tau_period_ev_per_a3 + tol
    # each barrier is the integral of the force over a climb shorter than the minima spacing
    assert fr.sigma_ev_per_a3 <= fr.tau_period_ev_per_a3 + tol
