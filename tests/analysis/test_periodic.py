"""Trigonometric interpolation on the lattice: exactness, derivatives, supercell."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from flatcontact.analysis import synthetic as syn
from flatcontact.analysis.periodic import PeriodicSurface, rectangular_supercell
from flatcontact.foundation.errors import InputError

A1, A2 = syn.hexagonal_cell()


def _grid(n_a, n_b):
    sa, sb = np.arange(n_a) / n_a, np.arange(n_b) / n_b
    return np.stack(np.meshgrid(sa, sb, indexing="ij"), -1)


def _cartesian_derivatives(pattern, s, a1, a2):
    g, gs, hs = pattern(s)
    inv = np.linalg.inv(np.column_stack([a1, a2]))
    return g, gs @ inv, np.einsum("ia,nab,bj->nij", inv.T, hs, inv)


@pytest.mark.parametrize("shape", [(5, 5), (6, 6), (7, 4), (8, 10)])
def test_trigonometric_polynomial_is_reproduced_exactly_with_derivatives(shape):
    pattern = syn.cosine_sum([(1, 0, 0.7, 0.3), (0, 1, -1.1), (-1, 1, 0.4, 1.0), (1, 1, 0.2)])
    surf = PeriodicSurface(pattern(_grid(*shape))[0], A1, A2)
    s = np.random.default_rng(3).random((40, 2)) * 3 - 1  # also outside the cell
    g, grad, hess = _cartesian_derivatives(pattern, s, A1, A2)
    ev = surf.evaluate(surf.cartesian(s))
    np.testing.assert_allclose(ev.value, g, atol=1e-13)
    np.testing.assert_allclose(ev.gradient, grad, atol=1e-12)
    np.testing.assert_allclose(ev.hessian, hess, atol=1e-11)


def test_even_grid_nyquist_term_is_split_into_a_real_cosine():
    # samples (-1)^i of cos(π N s) on an even grid: the interpolant is that cosine, real everywhere
    n = 6
    pattern = syn.cosine_sum([(n // 2, 0, 1.0), (0, 1, 0.5)])
    surf = PeriodicSurface(pattern(_grid(n, n))[0], A1, A2)
    s = np.random.default_rng(0).random((30, 2))
    np.testing.assert_allclose(surf(surf.cartesian(s)), pattern(s)[0], atol=1e-13)


@pytest.mark.parametrize("n", [4, 5, 8])
def test_samples_are_reproduced_at_the_nodes(n):
    values = np.random.default_rng(n).normal(size=(n, n + 1))
    surf = PeriodicSurface(values, A1, A2)
    np.testing.assert_allclose(
        surf.sample(np.arange(n) / n, np.arange(n + 1) / (n + 1)), values, atol=1e-13
    )


def test_spectral_convergence_for_a_smooth_non_band_limited_surface():
    a1, a2 = syn.rectangular_cell(4.0, 6.0)
    pattern = syn.canyon(1, 0.08, 0.5)
    s = np.random.default_rng(1).random((200, 2))
    errors = []
    for n in (8, 16, 32):
        surf = PeriodicSurface(pattern(_grid(n, n))[0], a1, a2)
        errors.append(np.max(np.abs(surf(surf.cartesian(s)) - pattern(s)[0])))
    assert errors[1] < 1e-2 * errors[0] and errors[2] < 1e-9


@settings(max_examples=20, deadline=None)
@given(shift=st.tuples(st.floats(-2, 2), st.floats(-2, 2)))
def test_translation_of_the_samples_translates_the_interpolant(shift):
    pattern = syn.cosine_sum([(1, 0, 0.7), (0, 1, -1.1), (-1, 1, 0.4)])
    moved = syn.shifted(pattern, shift)
    surf = PeriodicSurface(pattern(_grid(9, 9))[0], A1, A2)
    surf_moved = PeriodicSurface(moved(_grid(9, 9))[0], A1, A2)
    s = np.random.default_rng(2).random((20, 2))
    np.testing.assert_allclose(
        surf_moved(surf.cartesian(s + np.asarray(shift))), surf(surf.cartesian(s)), atol=1e-12
    )


def test_global_minimum_of_three_cosine_is_a_lattice_point():
    surf = PeriodicSurface(-syn.three_cosine(A1, A2)(_grid(12, 12))[0], A1, A2)
    xy, value = surf.global_minimum()
    assert value == pytest.approx(-3.0, abs=1e-12)
    s = surf.fractional(xy)
    np.testing.assert_allclose(s - np.round(s), 0.0, atol=1e-9)


def test_rectangular_supercell_of_hexagonal_lattice_is_the_papers_1x2_cell():
    u, v = rectangular_supercell(A1, A2)
    np.testing.assert_allclose(u, A1, atol=1e-12)
    np.testing.assert_allclose(v, A1 + 2 * A2, atol=1e-12)
    assert abs(u @ v) < 1e-9
    assert abs(u[0] * v[1] - u[1] * v[0]) == pytest.approx(2 * abs(A1[0] * A2[1] - A1[1] * A2[0]))
    assert rectangular_supercell([3.0, 0.0], [1.0, 2.7], max_index=2) is None


def test_nan_samples_are_refused():
    values = np.zeros((4, 4))
    values[1, 2] = np.nan
    with pytest.raises(InputError, match="NaN"):
        PeriodicSurface(values, A1, A2)


def _well_with_tilt(tilt):
    """A well at the origin, e = 1e-3 (2 - cos 2πs_a - cos 2πs_b) + tilt · sin 2πs_b, on 4 × 4."""
    sa, sb = np.moveaxis(_grid(4, 4), -1, 0)
    return PeriodicSurface(
        1e-3 * (2 - np.cos(2 * np.pi * sa) - np.cos(2 * np.pi * sb))
        + tilt * np.sin(2 * np.pi * sb),
        A1,
        A2,
    )


@pytest.mark.parametrize("tilt", [0.0, 1e-12, 5e-12, 1e-11, 1e-9, 1e-6])
def test_a_start_at_or_next_to_the_minimum_is_refined_without_error(tilt):
    """Scipy's exact trust-region step turned gradients of 1e-12 … 2e-11 at the start (a
    minimum on a grid point, as a toy scan gave) into a NaN and a ValueError. The minimum of
    the tilted well is at s_b ≈ -tilt/(1e-3 · 2π) · … : within |∇e|/λ_min of the origin."""
    surf = _well_with_tilt(tilt)
    start = surf.evaluate(np.zeros(2))
    xy, value = surf.local_minimum(np.zeros(2))
    lam = float(np.linalg.eigvalsh(start.hessian).min())
    assert np.linalg.norm(xy) <= 2 * np.linalg.norm(start.gradient) / lam + 1e-12
    assert value <= float(start.value) + 1e-18
    (found,) = surf.local_minima()  # reduced into the cell: compare modulo the lattice
    ds = surf.fractional(found[0]) - surf.fractional(xy)
    assert np.linalg.norm(surf.cartesian(ds - np.round(ds))) < 1e-6


def test_where_scipy_fails_the_start_is_polished_by_newton_steps(monkeypatch):
    from flatcontact.analysis import periodic

    def fails(*args, **kwargs):
        raise ValueError("array must not contain infs or NaNs")

    monkeypatch.setattr(periodic, "minimize", fails)
    surf = _well_with_tilt(0.0)
    xy, value = surf.local_minimum(np.array([0.3, -0.2]))  # 0.36 Å away: not stationary
    assert np.linalg.norm(xy) < 1e-9 and value == pytest.approx(0.0, abs=1e-15)
