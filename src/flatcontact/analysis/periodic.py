"""Exact periodic (trigonometric) interpolation of a lattice-periodic surface.

A landscape sampled on the contract's fractional grid ``s_a = i/N_a``,
``s_b = j/N_b`` (endpoint excluded) is represented by its 2-D discrete Fourier
series

.. math:: e(\\mathbf r) = \\sum_{k,l} c_{kl}\\, e^{2\\pi i (k s_a + l s_b)}
          = \\sum_{k,l} c_{kl}\\, e^{i \\mathbf G_{kl}\\cdot \\mathbf r},
          \\qquad \\mathbf G_{kl} = k\\mathbf b_1 + l\\mathbf b_2,

with ``c = fft2(values)/(N_a N_b)``, frequencies ``|k| <= N_a/2``, ``|l| <= N_b/2``
and, for even ``N``, the Nyquist coefficient split equally between ``+N/2`` and
``-N/2`` so the interpolant is real everywhere. It reproduces the samples exactly,
any trigonometric polynomial of lower degree exactly everywhere, and converges
spectrally for smooth periodic surfaces. Gradients and Hessians are analytic
(multiplication of ``c_kl`` by ``i G``), never finite differences.

Cartesian positions ``r = s_a a1 + s_b a2`` (Å) are the lateral shift of slab 2.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize

from flatcontact.foundation.errors import InputError

TWO_PI = 2.0 * np.pi


def lattice_matrix(a1: np.ndarray, a2: np.ndarray) -> np.ndarray:
    """2×2 matrix with columns ``a1``, ``a2`` (Å): ``r = L @ s``."""
    return np.column_stack([np.asarray(a1, float)[:2], np.asarray(a2, float)[:2]])


def _nyquist_split(coef: np.ndarray, freq: np.ndarray, axis: int) -> tuple[np.ndarray, np.ndarray]:
    n = coef.shape[axis]
    if n % 2:
        return coef, freq
    half = np.take(coef, [n // 2], axis=axis) * 0.5
    coef = coef.copy()
    sl = [slice(None)] * coef.ndim
    sl[axis] = n // 2
    coef[tuple(sl)] = np.squeeze(half, axis=axis)
    return np.concatenate([coef, half], axis=axis), np.append(freq, n // 2)


def _fold_to_zone(
    g: np.ndarray, c: np.ndarray, shape: tuple[int, int], inverse: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies ``g`` (n, 2) moved to their shortest aliases on an ``shape`` grid.

    The aliases of ``(k, l)`` are ``(k + i N_a, l + j N_b)``: equal at every sample
    ``(i_a/N_a, i_b/N_b)``. Length is Cartesian, ``|inverse.T @ g|`` (``inverse`` maps
    Cartesian points to fractional ones). A frequency with several shortest aliases (the
    zone's boundary) gives each an equal share of its coefficient, so the set is symmetric
    under every lattice operation that maps the grid onto itself, and under ``g → −g``
    (the interpolant stays real).
    """
    n_a, n_b = shape
    steps = np.array([(i * n_a, j * n_b) for i in (-2, -1, 0, 1, 2) for j in (-2, -1, 0, 1, 2)])
    out_g, out_c = [], []
    for gi, ci in zip(g, c, strict=True):
        cand = gi[None, :] + steps
        length = np.linalg.norm(cand @ inverse, axis=1)
        best = np.flatnonzero(length <= length.min() * (1 + 1e-9) + 1e-12)
        out_g.append(cand[best])
        out_c.append(np.full(best.size, ci / best.size))
    return np.concatenate(out_g), np.concatenate(out_c)


@dataclass(frozen=True)
class SurfaceValues:
    """Value (…), gradient (…, 2) and Hessian (…, 2, 2) in Cartesian coordinates."""

    value: np.ndarray
    gradient: np.ndarray
    hessian: np.ndarray


class PeriodicSurface:
    """Trigonometric interpolant of a surface on the fractional grid of a lattice.

    Parameters
    ----------
    values
        Samples at ``s_a = i/N_a``, ``s_b = j/N_b``, shape ``(N_a, N_b)``, finite.
    a1, a2
        Lattice vectors (Å).
    max_harmonic
        If given, drop Fourier terms with ``|k|`` or ``|l|`` above it (a low-pass
        filter for noisy data); ``None`` keeps the exact interpolant.
    """

    def __init__(
        self,
        values: np.ndarray,
        a1: np.ndarray,
        a2: np.ndarray,
        max_harmonic: int | None = None,
    ) -> None:
        values = np.asarray(values, dtype=float)
        if values.ndim != 2 or min(values.shape) < 1:
            raise InputError(
                f"surface values: expected a 2-D lateral grid, got shape {values.shape}"
            )
        if not np.all(np.isfinite(values)):
            raise InputError("surface values: NaN or infinite samples cannot be interpolated")
        self.values = values
        self.lattice = lattice_matrix(a1, a2)
        self.a1, self.a2 = self.lattice[:, 0].copy(), self.lattice[:, 1].copy()
        self.inverse = np.linalg.inv(self.lattice)  # s = inverse @ r
        n_a, n_b = values.shape
        coef = np.fft.fft2(values) / values.size
        k = np.fft.fftfreq(n_a, 1.0 / n_a)
        ll = np.fft.fftfreq(n_b, 1.0 / n_b)
        coef, k = _nyquist_split(coef, k, 0)
        coef, ll = _nyquist_split(coef, ll, 1)
        if max_harmonic is not None:
            coef = (
                coef * (np.abs(k)[:, None] <= max_harmonic) * (np.abs(ll)[None, :] <= max_harmonic)
            )
        self.coefficients = coef
        self.k = k
        self.l = ll

    # ------------------------------------------------------------------ symmetry
    def zone_folded(self) -> PeriodicSurface:
        """The same samples with every frequency moved to its shortest alias (:func:`_fold_to_zone`).

        The grid's own square frequency set ``|k| <= N_a/2``, ``|l| <= N_b/2`` is not closed
        under the rotations of a hexagonal lattice: on a grid whose samples are exactly
        three-fold symmetric, its interpolant is not (the corner terms rotate onto frequencies
        outside the set). Folded to the Cartesian-shortest aliases (ties share the
        coefficient equally), the frequency set is closed under every lattice operation that
        maps the grid onto itself, so samples that keep an operation give an interpolant that
        keeps it to round-off. The samples are reproduced exactly; only the interpolation
        between them changes.
        """
        ks, ls = np.meshgrid(self.k, self.l, indexing="ij")
        g = np.stack([ks.ravel(), ls.ravel()], -1)
        c = self.coefficients.ravel()
        keep = c != 0
        if not np.any(keep):
            return self
        g, c = _fold_to_zone(g[keep], c[keep], self.values.shape, self.inverse)
        gi = np.round(g).astype(int)
        kmax, lmax = int(np.max(np.abs(gi[:, 0]))), int(np.max(np.abs(gi[:, 1])))
        coef = np.zeros((2 * kmax + 1, 2 * lmax + 1), complex)
        np.add.at(coef, (gi[:, 0] + kmax, gi[:, 1] + lmax), c)
        out = object.__new__(PeriodicSurface)
        out.lattice, out.inverse = self.lattice, self.inverse
        out.a1, out.a2 = self.a1, self.a2
        out.values = self.values
        out.coefficients = coef
        out.k = np.arange(-kmax, kmax + 1, dtype=float)
        out.l = np.arange(-lmax, lmax + 1, dtype=float)
        return out

    def symmetrised(self, operations: list[tuple[np.ndarray, np.ndarray]]) -> PeriodicSurface:
        """The group average ``(1/|G|) Σ_g e(M_g s + t_g)`` of this interpolant.

        ``operations``: the shift-space group as ``(M, t)`` in the fractional basis
        (:func:`flatcontact.ispes.contract.symmetry_operations`). Since
        ``e(M s + t) = Σ c_G e^{2πi G·t} e^{2πi (MᵀG)·s}``, the average has the coefficient
        ``(1/|G|) Σ_g c_G e^{2πi G·t_g}`` at ``M_gᵀ G``: its frequency set is the union of the
        orbits of the grid's (a set closed under the group, unlike the grid's own square set
        on a hexagonal lattice), so symmetry-equal stackings are equal to round-off and no
        artefact of the square set appears. Each frequency is first replaced by its shortest
        alias on the grid (``G + (i N_a, j N_b)``, Cartesian length; ties share the
        coefficient equally: :func:`_fold_to_zone`): the same samples, and a frequency set the
        group maps onto itself, so the average adds no frequency beyond the grid's Nyquist
        zone (averaging the square set itself sends its corner terms to aliases twice as
        long, which interpolate the samples but wiggle between them: on Cu(111) 6×6 that
        raised the path's τ by 3 %). If the samples obey the group on the grid it
        still reproduces them exactly (each term interpolates the same samples); otherwise it
        interpolates their group average. ``values`` becomes that average.
        """
        if len(operations) <= 1:
            return self
        folded = self.zone_folded()
        ks, ls = np.meshgrid(folded.k, folded.l, indexing="ij")
        g = np.stack([ks.ravel(), ls.ravel()], -1)
        c = folded.coefficients.ravel()
        keep = c != 0
        g, c = g[keep], c[keep]
        mapped = [
            (g @ np.asarray(m, float), c * np.exp(1j * TWO_PI * (g @ np.asarray(t, float))))
            for m, t in operations
        ]
        kmax = int(max(np.max(np.abs(gm[:, 0])) for gm, _ in mapped))
        lmax = int(max(np.max(np.abs(gm[:, 1])) for gm, _ in mapped))
        coef = np.zeros((2 * kmax + 1, 2 * lmax + 1), complex)
        for gm, cm in mapped:
            gi = np.round(gm).astype(int)
            np.add.at(coef, (gi[:, 0] + kmax, gi[:, 1] + lmax), cm / len(operations))
        out = object.__new__(PeriodicSurface)
        out.lattice, out.inverse = self.lattice, self.inverse
        out.a1, out.a2 = self.a1, self.a2
        out.coefficients = coef
        out.k = np.arange(-kmax, kmax + 1, dtype=float)
        out.l = np.arange(-lmax, lmax + 1, dtype=float)
        n_a, n_b = self.values.shape
        out.values = out.sample(np.arange(n_a) / n_a, np.arange(n_b) / n_b)
        return out

    # ------------------------------------------------------------------ coordinates
    def fractional(self, xy: np.ndarray) -> np.ndarray:
        """Fractional coordinates of Cartesian points (Å)."""
        return np.asarray(xy, dtype=float) @ self.inverse.T

    def cartesian(self, s: np.ndarray) -> np.ndarray:
        """Cartesian points (Å) of fractional coordinates."""
        return np.asarray(s, dtype=float) @ self.lattice.T

    # ------------------------------------------------------------------ evaluation
    def _phases(self, xy: np.ndarray) -> tuple[np.ndarray, np.ndarray, tuple[int, ...]]:
        xy = np.asarray(xy, dtype=float)
        shape = xy.shape[:-1]
        s = self.fractional(xy.reshape(-1, 2))
        ea = np.exp(1j * TWO_PI * np.outer(s[:, 0], self.k))
        eb = np.exp(1j * TWO_PI * np.outer(s[:, 1], self.l))
        return ea, eb, shape

    def __call__(self, xy: np.ndarray) -> np.ndarray:
        """Value at Cartesian points ``xy`` (…, 2)."""
        ea, eb, shape = self._phases(xy)
        return np.real(np.sum((ea @ self.coefficients) * eb, axis=1)).reshape(shape)

    def evaluate(self, xy: np.ndarray) -> SurfaceValues:
        """Value, Cartesian gradient and Hessian at points ``xy`` (…, 2)."""
        ea, eb, shape = self._phases(xy)
        ik = 1j * TWO_PI * self.k
        il = 1j * TWO_PI * self.l
        c = self.coefficients
        t0 = ea @ c
        ta = (ea * ik) @ c
        taa = (ea * ik**2) @ c
        v = np.real(np.sum(t0 * eb, 1))
        ga = np.real(np.sum(ta * eb, 1))
        gb = np.real(np.sum(t0 * eb * il, 1))
        haa = np.real(np.sum(taa * eb, 1))
        hab = np.real(np.sum(ta * eb * il, 1))
        hbb = np.real(np.sum(t0 * eb * il**2, 1))
        grad_s = np.stack([ga, gb], -1)
        hess_s = np.stack([np.stack([haa, hab], -1), np.stack([hab, hbb], -1)], -2)
        inv = self.inverse
        grad = grad_s @ inv
        hess = np.einsum("ia,nab,bj->nij", inv.T, hess_s, inv)
        return SurfaceValues(v.reshape(shape), grad.reshape(*shape, 2), hess.reshape(*shape, 2, 2))

    def gradient(self, xy: np.ndarray) -> np.ndarray:
        """Cartesian gradient (…, 2) at ``xy``."""
        return self.evaluate(xy).gradient

    def hessian(self, xy: np.ndarray) -> np.ndarray:
        """Cartesian Hessian (…, 2, 2) at ``xy``."""
        return self.evaluate(xy).hessian

    def sample(self, s_a: np.ndarray, s_b: np.ndarray) -> np.ndarray:
        """Values on the fractional grid ``s_a × s_b`` (any, e.g. finer or shifted)."""
        sa, sb = np.meshgrid(np.asarray(s_a, float), np.asarray(s_b, float), indexing="ij")
        return self(self.cartesian(np.stack([sa, sb], -1)))

    # ------------------------------------------------------------------ minima
    def local_minimum(self, xy0: np.ndarray) -> tuple[np.ndarray, float]:
        """Refine a minimum from ``xy0`` with a trust-region Newton method (analytic derivatives).

        Near a stationary start scipy's exact trust-region subproblem turned gradients of
        1e-12 … 2e-11 (just above its absolute tolerance) into a NaN and an error (a toy
        landscape with its minimum on a grid point; ``tests/analysis/test_periodic.py``).
        There the start is polished by Newton steps instead (:meth:`_newton_polish`), and the
        caller's tests (stationary, positive definite) decide as for any other candidate;
        wherever scipy succeeds its result is kept, bit for bit as before.
        """
        x0 = np.asarray(xy0, float)

        def fun(x: np.ndarray) -> float:
            return float(self(x))

        try:
            res = minimize(
                fun,
                x0,
                jac=lambda x: self.evaluate(x).gradient,
                hess=lambda x: self.evaluate(x).hessian,
                method="trust-exact",
                options={"gtol": 1e-12 * max(1.0, float(np.ptp(self.values)))},
            )
        except ValueError:  # scipy's subproblem met a NaN (above)
            x = self._newton_polish(x0)
            return x, float(self(x))
        return res.x, float(res.fun)

    def local_minima(self, refine: int = 2) -> list[tuple[np.ndarray, float]]:
        """All inequivalent local minima of the interpolant in the cell, lowest first.

        Starts from every periodic discrete minimum of the interpolant sampled on
        a grid ``refine`` times finer than the data (so a minimum between two
        data points is not missed), refines each with :meth:`local_minimum`
        (analytic gradient and Hessian), keeps the stationary points whose
        Hessian is positive definite, reduces them into the cell and drops
        duplicates (points less than ``1e-6`` × the shortest lattice vector
        apart modulo the lattice). Ordered by value, then by fractional
        position (deterministic order for exact ties).

        Stationary means ``|∇e| · a_min <= 1e-7 · ptp(e)`` (``a_min`` the shortest
        lattice vector). The trust-region refinement judges its steps by the
        decrease of the *value*; on a landscape whose constant offset is large
        against its corrugation (the enthalpy form at a load, ``e ≈ 0.055 eV/Å²``
        with a 1.3e-3 eV/Å² corrugation) that decrease falls below the round-off
        of the value near the minimum and it stops short of the test. A candidate
        it leaves unconverged is therefore polished by Newton steps on the
        analytic gradient (:meth:`_newton_polish`, blind to the offset) and tested
        again; it is added only if it is not a duplicate of a minimum found
        directly, so landscapes where every minimum converges are unaffected.

        Returns
        -------
        list of ``(xy, value)``
            Cartesian positions (Å) in the cell and the surface values there.
        """
        n_a, n_b = self.values.shape
        f_a, f_b = max(1, refine) * n_a, max(1, refine) * n_b
        v = self.sample(np.arange(f_a) / f_a, np.arange(f_b) / f_b)
        is_min = np.ones(v.shape, bool)
        for axis in (0, 1):
            for shift in (1, -1):
                is_min &= v <= np.roll(v, shift, axis=axis)
        cand = np.argwhere(is_min)
        scale = float(np.min(np.linalg.norm(self.lattice, axis=0)))
        spread = max(float(np.ptp(self.values)), 1e-300)
        found: list[tuple[np.ndarray, np.ndarray, float]] = []  # (s in cell, xy, value)

        def stationary(sv: SurfaceValues) -> bool:
            return bool(np.linalg.norm(sv.gradient) * scale <= 1e-7 * spread)

        def add(xy: np.ndarray, val: float, sv: SurfaceValues) -> None:
            if not np.all(np.linalg.eigvalsh(sv.hessian) > 0):
                return  # a flat direction or a saddle, not a minimum
            s = self.fractional(xy)
            s = s - np.floor(s)
            for s_known, _, _ in found:
                ds = s - s_known
                ds -= np.round(ds)
                if np.linalg.norm(self.cartesian(ds)) < 1e-6 * scale:
                    return  # a duplicate modulo the lattice
            found.append((s, self.cartesian(s), float(val)))

        stalled = []
        for i, j in cand:
            xy, val = self.local_minimum(self.cartesian(np.array([i / f_a, j / f_b])))
            sv = self.evaluate(xy)
            if stationary(sv):
                add(xy, val, sv)
            else:
                stalled.append(xy)
        for xy in stalled:  # after the directly converged ones: those are kept bit for bit
            xy = self._newton_polish(xy)
            sv = self.evaluate(xy)
            if stationary(sv):
                add(xy, float(sv.value), sv)
        found.sort(key=lambda m: (m[2], round(float(m[0][0]), 9), round(float(m[0][1]), 9)))
        return [(xy, val) for _, xy, val in found]

    def _newton_polish(self, xy: np.ndarray, max_steps: int = 20) -> np.ndarray:
        """Newton steps ``x ← x − H⁻¹∇e`` from ``xy`` while the Hessian is positive definite.

        Uses only the analytic gradient and Hessian, not the value, so a constant offset
        of the surface does not limit it. Each step is capped at 5 % of the shortest
        lattice vector; stops when a step is below ``1e-13`` of it, at an indefinite
        Hessian or after ``max_steps``. Returns the last point (Å).
        """
        scale = float(np.min(np.linalg.norm(self.lattice, axis=0)))
        x = np.asarray(xy, float).copy()
        for _ in range(max_steps):
            sv = self.evaluate(x)
            if not np.all(np.linalg.eigvalsh(sv.hessian) > 0):
                break
            step = np.linalg.solve(sv.hessian, sv.gradient)
            length = float(np.linalg.norm(step))
            if length > 0.05 * scale:
                step *= 0.05 * scale / length
            x = x - step
            if length < 1e-13 * scale:
                break
        return x

    def global_minimum(self, n_starts: int = 4) -> tuple[np.ndarray, float]:
        """Lowest minimum of the interpolant, reduced into the cell (Å, value).

        Starts from the ``n_starts`` lowest grid points that are local minima of
        the samples (periodic neighbours) and keeps the lowest refined one.
        """
        v = self.values
        is_min = np.ones(v.shape, bool)
        for axis in (0, 1):
            for shift in (1, -1):
                is_min &= v <= np.roll(v, shift, axis=axis)
        cand = np.argwhere(is_min)
        if cand.size == 0:
            cand = np.argwhere(v == v.min())
        order = np.argsort(v[tuple(cand.T)])[:n_starts]
        best = None
        for i, j in cand[order]:
            s0 = np.array([i / v.shape[0], j / v.shape[1]])
            xy, val = self.local_minimum(self.cartesian(s0))
            if best is None or val < best[1]:
                best = (xy, val)
        assert best is not None
        s = self.fractional(best[0])
        return self.cartesian(s - np.floor(s)), best[1]


def lattice_vectors(a1: np.ndarray, a2: np.ndarray, max_index: int = 6) -> np.ndarray:
    """All lattice vectors ``m a1 + n a2`` with ``|m|, |n| <= max_index`` (Å), shape (K, 2)."""
    m, n = np.meshgrid(np.arange(-max_index, max_index + 1), np.arange(-max_index, max_index + 1))
    mn = np.column_stack([m.ravel(), n.ravel()])
    return mn @ lattice_matrix(a1, a2).T


def rectangular_supercell(
    a1: np.ndarray, a2: np.ndarray, max_index: int = 4, rtol: float = 1e-6
) -> tuple[np.ndarray, np.ndarray] | None:
    """Smallest rectangular supercell (two orthogonal lattice vectors, Å) of the lattice.

    For a hexagonal lattice this is the paper's 1×2 cell ``(a1, a1 + 2 a2)``
    (twice the primitive area). Returns ``None`` if no rectangular cell with
    indices up to ``max_index`` exists (a generic oblique lattice). The first
    vector is the one closer to the x axis.
    """
    lat = lattice_matrix(a1, a2)
    scale = float(np.max(np.linalg.norm(lat, axis=0)))
    vecs = lattice_vectors(a1, a2, max_index)
    vecs = vecs[np.linalg.norm(vecs, axis=1) > 1e-9 * scale]
    area0 = abs(np.linalg.det(lat))
    best = None
    for u in vecs:
        for v in vecs[np.abs(vecs @ u) <= rtol * scale**2]:
            area = abs(u[0] * v[1] - u[1] * v[0])
            if area < 0.5 * area0:
                continue
            tilt = min(abs(u[1]) / np.linalg.norm(u), abs(v[1]) / np.linalg.norm(v))
            key = (round(area / area0, 6), round(tilt, 9), np.linalg.norm(u) + np.linalg.norm(v))
            if best is None or key < best[0]:
                best = (key, u, v)
    if best is None:
        return None
    u, v = best[1], best[2]
    # orient: first vector closer to x, both with non-negative leading components
    if abs(u[0]) < abs(v[0]):
        u, v = v, u
    u = u if u[0] > 0 or (u[0] == 0 and u[1] > 0) else -u
    v = v if v[1] > 0 or (v[1] == 0 and v[0] > 0) else -v
    return u, v
