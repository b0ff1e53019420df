"""Symmetry report: kept and broken point operations about the best centre."""

import numpy as np
import pytest

from flatcontact.analysis import synthetic as syn
from flatcontact.analysis.periodic import PeriodicSurface
from flatcontact.analysis.symmetry import lattice_point_operations, symmetry_report

A1, A2 = syn.hexagonal_cell()


def _surface(pattern, n=18, a1=A1, a2=A2):
    sa = np.arange(n) / n
    s = np.stack(np.meshgrid(sa, sa, indexing="ij"), -1)
    return PeriodicSurface(pattern(s)[0], a1, a2)


def test_hexagonal_lattice_has_the_eleven_operations_of_6mm():
    assert len(lattice_point_operations(A1, A2)) == 11
    assert len(lattice_point_operations(*syn.rectangular_cell(3.0, 4.0))) == 3


@pytest.mark.parametrize("shift", [(0.0, 0.0), (0.137, 0.291)])
def test_three_cosine_keeps_everything_about_its_shifted_centre(shift):
    rep = symmetry_report(_surface(syn.shifted(syn.three_cosine(A1, A2), shift)))
    assert len(rep.kept) == 11 and max(op.deviation for op in rep.operations) < 1e-6
    centre = next(op for op in rep.operations if op.name == "C6").centre_xy_angstrom
    s = np.linalg.solve(np.column_stack([A1, A2]), centre) - np.asarray(shift)
    np.testing.assert_allclose(s - np.round(s), 0.0, atol=1e-6)


def test_unequal_weights_break_six_fold_but_keep_inversion():
    rep = symmetry_report(_surface(syn.three_cosine(A1, A2, (1.0, 0.7, 1.2))))
    assert rep.kept == ["C2"]
    c6 = next(op for op in rep.operations if op.name == "C6")
    assert 0.2 < c6.deviation < 0.5
    # one weight changed: the mirror through that cosine's wave vector survives
    rep = symmetry_report(_surface(syn.three_cosine(A1, A2, (1.0, 1.0, 1.3))))
    assert set(rep.kept) == {
        "C2",
        *[op.name for op in rep.operations if op.kind == "mirror" and op.kept],
    }
    assert sum(op.kind == "mirror" for op in rep.operations if op.kept) == 2


def _gaussian_bumps(s: np.ndarray, width: float = 0.18) -> np.ndarray:
    """Gaussians at the lattice points: six-fold about the origin, and not band-limited."""
    lat = np.column_stack([A1[:2], A2[:2]])
    xy = s @ lat.T
    total = np.zeros(s.shape[:-1])
    for i in range(-3, 4):
        for j in range(-3, 4):
            d = xy - lat @ np.array([i, j])
            total += np.exp(-np.sum(d**2, axis=-1) / (2 * (width * np.linalg.norm(A1)) ** 2))
    return total


@pytest.mark.parametrize("n", [6, 12])
def test_samples_that_keep_the_rotations_report_them_kept_to_round_off(n):
    """An exactly six-fold grid (Gaussian bumps: energy at frequencies beyond the square set's
    closure) reports every operation kept to round-off: the report measures the samples, not
    the square frequency set's corner terms (which gave a percent-level C3 deviation)."""
    sa = np.arange(n) / n
    s = np.stack(np.meshgrid(sa, sa, indexing="ij"), -1)
    values = _gaussian_bumps(s)
    surface = PeriodicSurface(values, A1, A2)
    rep = symmetry_report(surface)
    assert max(op.deviation for op in rep.operations) < 1e-7, rep.summary()
    # the folded interpolant still reproduces the samples
    np.testing.assert_allclose(surface.zone_folded().sample(sa, sa), values, atol=1e-12)
