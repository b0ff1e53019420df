"""The interpolant averaged over a shift-space group (:meth:`PeriodicSurface.symmetrised`)."""

import numpy as np

from flatcontact.analysis.periodic import PeriodicSurface

A1, A2 = np.array([1.0, 0.0]), np.array([-0.5, np.sqrt(3) / 2])
L = np.column_stack([A1, A2])
B = 2 * np.pi * np.linalg.inv(L).T
STAR = [B[:, 0], B[:, 1] - B[:, 0], -B[:, 1]]  # a C3-closed star of reciprocal vectors
C3 = [np.eye(2, dtype=int), np.array([[0, -1], [1, -1]]), np.array([[-1, 1], [-1, 0]])]


def landscape(xy):
    """C3-invariant, not centrosymmetric, with a third-harmonic (Nyquist of a 6-grid) term."""
    return sum(np.cos(xy @ g) + 0.3 * np.sin(xy @ g) + 0.2 * np.cos(xy @ (3 * g)) for g in STAR)


def test_symmetrised_interpolant_keeps_c3_and_the_samples():
    n = 6
    s = np.stack(np.meshgrid(np.arange(n) / n, np.arange(n) / n, indexing="ij"), -1)
    values = landscape(s @ L.T)
    plain = PeriodicSurface(values, A1, A2)
    sym = plain.symmetrised([(m, np.zeros(2)) for m in C3])
    xy = np.random.default_rng(0).random((64, 2)) @ L.T
    rot = np.array([[-0.5, -np.sqrt(3) / 2], [np.sqrt(3) / 2, -0.5]])
    assert np.abs(landscape(xy @ rot.T) - landscape(xy)).max() < 1e-12  # the truth is C3
    assert np.abs(plain(xy @ rot.T) - plain(xy)).max() > 1e-2  # the square set breaks C3
    assert np.abs(sym(xy @ rot.T) - sym(xy)).max() < 1e-12
    assert np.abs(sym.values - values).max() < 1e-12  # still interpolates the samples
    assert np.abs(plain.symmetrised(C3[:1]).values - values).max() == 0.0  # identity: no-op
