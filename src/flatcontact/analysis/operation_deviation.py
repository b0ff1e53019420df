"""How far a sampled landscape keeps one shift-space operation ``s ↦ M s + t``.

Conventions: fractional shifts ``s = (s_a, s_b)`` of the grid's lattice (``r = L s``), an
operation ``g = (M, t)`` with ``M`` a 2×2 integer matrix in that basis and ``t`` a fractional
translation, as :func:`flatcontact.ispes.contract.symmetry_operations` and
:meth:`.periodic.PeriodicSurface.symmetrised` take them. An operation that swaps the slabs
carries its sign in ``M`` (``g·s = −M' s + t``, :mod:`flatcontact.ispes.shift_symmetry`), so
every operation is applied the same way. A landscape keeps ``g`` when ``e(g·s) = e(s)``.

:func:`operation_deviation` measures

.. math:: \\delta_g = \\max_s |e(g\\cdot s) - e(s)| \\,/\\, (\\max e - \\min e),

the largest change under ``g`` as a fraction of the landscape's range (the max norm: a
symmetry broken at a few points, e.g. by planes slipping there, is not diluted by the
rest of the cell). Where it is exact:

- ``g`` maps the sampling grid onto itself (every ``M s_ij + t`` is a grid point, the usual
  case: C3/C6/mirrors on an N×N grid of a hexagonal cell with a translation on the grid):
  the samples at ``s`` and ``g·s`` are compared directly, over every grid point. No
  interpolation enters, so a landscape whose samples obey ``g`` gives 0 to round-off, on
  any grid, however coarse.
- otherwise the band-limited interpolant is compared with its image: ``e∘g`` has the
  coefficient ``c_G e^{2πi G·t}`` at ``MᵀG``. Only frequencies whose image is also in the
  interpolant's index set are compared (on an N×N grid of a hexagonal cell, C3 sends the
  edge and Nyquist frequencies outside the square set: they carry no information about
  the symmetry, and counting them as a mismatch reads a perfectly symmetric sampled
  landscape as broken by tens of percent); the difference is evaluated on the grid
  refined twice.
"""

from __future__ import annotations

import numpy as np

from flatcontact.analysis.periodic import PeriodicSurface

TWO_PI = 2.0 * np.pi
#: A mapped grid point counts as on the grid within this fraction of a grid step (the
#: structure's own operations carry the build relaxation's round-off: quartz's two-fold axis
#: translates by 1.5e-7 of a cell, 1.8e-6 of a step of the 12×12 grid; a thousandth of a
#: step moves a sample by a thousandth of its change to the neighbour).
GRID_ATOL = 1e-3


def grid_image(
    shape: tuple[int, int], matrix: np.ndarray, translation: np.ndarray
) -> np.ndarray | None:
    """Grid indices of ``g·s`` for every point of an ``n_a × n_b`` grid of fractional shifts
    (``out[ia, ib] = (ja, jb)``), or None if some image is not a grid point."""
    n_a, n_b = shape
    ia, ib = np.meshgrid(np.arange(n_a), np.arange(n_b), indexing="ij")
    s = np.stack([ia / n_a, ib / n_b], -1)
    g = (s @ np.asarray(matrix, float).T + np.asarray(translation, float)) * (n_a, n_b)
    if not np.allclose(g, np.round(g), atol=GRID_ATOL):
        return None
    g = np.round(g).astype(int)
    return np.stack([g[..., 0] % n_a, g[..., 1] % n_b], -1)


def maps_grid(shape: tuple[int, int], matrix: np.ndarray, translation: np.ndarray) -> bool:
    """Whether ``g`` maps the ``n_a × n_b`` grid onto itself (the exact comparison applies)."""
    return grid_image(shape, matrix, translation) is not None


def operation_deviation(
    surface: PeriodicSurface, matrix: np.ndarray, translation: np.ndarray
) -> float:
    """``δ_g`` of the module docstring: the largest ``|e(g·s) − e(s)|`` over the cell as a
    fraction of the range of ``surface.values`` (0 for a flat landscape).

    Parameters
    ----------
    surface
        The landscape: its samples (``values``, on the grid ``i/N_a, j/N_b``) and its
        interpolant (``coefficients`` on the frequencies ``k``, ``l``); any energy unit.
    matrix
        ``M``, 2×2 integer, fractional basis.
    translation
        ``t``, fractional.
    """
    values = np.asarray(surface.values, float)
    span = float(np.ptp(values))
    if span <= 0:
        return 0.0
    image = grid_image(values.shape, matrix, translation)
    if image is not None:
        return float(np.max(np.abs(values[image[..., 0], image[..., 1]] - values)) / span)
    return _interpolant_deviation(surface, matrix, translation) / span


def coefficient_image_difference(
    surface: PeriodicSurface, matrix: np.ndarray, translation: np.ndarray
) -> np.ndarray:
    """``c' − c`` on the interpolant's frequencies, where ``c'`` are the coefficients of
    ``e∘g``: at each frequency ``H = MᵀG`` that is the image of a frequency ``G`` of the index
    set and in it itself, ``c'_H = c_G e^{2πi G·t}``; 0 elsewhere (a frequency mapped outside
    the set, or one no frequency maps onto, carries no information about ``g``: module
    docstring). Same shape as ``surface.coefficients``; shared by :func:`operation_deviation`
    (the max norm on the doubled grid) and
    :func:`flatcontact.analysis.stackings.kept_operations` (the L2 norm, Parseval)."""
    k, ll = surface.k, surface.l
    c = surface.coefficients
    index = {(int(a), int(b)): (i, j) for i, a in enumerate(k) for j, b in enumerate(ll)}
    m = np.rint(np.asarray(matrix, float)).astype(int)
    t = np.asarray(translation, float)
    diff = np.zeros_like(c)
    for (a, b), (i, j) in index.items():
        target = index.get((int(a * m[0, 0] + b * m[1, 0]), int(a * m[0, 1] + b * m[1, 1])))
        if target is None:
            continue
        diff[target] += c[i, j] * np.exp(1j * TWO_PI * (a * t[0] + b * t[1]))
        diff[target] -= c[target]
    return diff


def _interpolant_deviation(
    surface: PeriodicSurface, matrix: np.ndarray, translation: np.ndarray
) -> float:
    """max |Σ_H (c'_H − c_H) e^{2πi H·s}| on the doubled grid
    (:func:`coefficient_image_difference`)."""
    k, ll = surface.k, surface.l
    diff = coefficient_image_difference(surface, matrix, translation)
    n_a, n_b = np.asarray(surface.values).shape
    ea = np.exp(1j * TWO_PI * np.outer(np.arange(2 * n_a) / (2 * n_a), k))
    eb = np.exp(1j * TWO_PI * np.outer(np.arange(2 * n_b) / (2 * n_b), ll))
    return float(np.max(np.abs(np.real(ea @ diff @ eb.T))))
