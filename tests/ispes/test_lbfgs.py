"""The in-house L-BFGS takes ASE's LBFGS steps (to round-off), with one evaluation per step."""

from __future__ import annotations

import numpy as np
import pytest
from ase.build import fcc111
from ase.calculators.calculator import Calculator, all_changes
from ase.calculators.emt import EMT
from ase.constraints import FixAtoms, FixCartesian
from ase.optimize import LBFGS
from hypothesis import example, given, settings
from hypothesis import strategies as st

from flatcontact.ispes.lbfgs import TwoLoopMemory, largest_atomic_norm, lbfgs_relax
from flatcontact.ispes.relax import constraint_projector


def ase_trajectory(atoms, fmax, steps, **kwargs):
    """Positions after every step of ASE's LBFGS, and its step count."""
    path = []  # the observer is called once before the first step and after each
    opt = LBFGS(atoms, logfile=None, **kwargs)
    opt.attach(lambda: path.append(atoms.positions.copy()))
    opt.run(fmax=fmax, steps=steps)
    return path, opt.nsteps


def own_trajectory(atoms, calc, project, fmax, steps, **kwargs):
    path = []

    def evaluate(x):
        path.append(x.copy())
        probe = atoms.copy()
        probe.set_constraint()
        probe.positions = x
        probe.calc = calc
        return probe.get_potential_energy(), probe.get_forces()

    out = lbfgs_relax(evaluate, atoms.positions, project, fmax, steps, **kwargs)
    return path, out


def cu_slab():
    atoms = fcc111("Cu", (2, 2, 4), vacuum=6.0)
    rng = np.random.default_rng(7)
    atoms.positions += rng.normal(0.0, 0.08, atoms.positions.shape)
    held = atoms.positions[:, 2] < atoms.positions[:, 2].min() + 0.5
    return atoms, held


@pytest.mark.parametrize("memory", [100, 3])
def test_same_steps_as_ase_with_held_atoms(memory):
    atoms, held = cu_slab()
    reference = atoms.copy()
    reference.set_constraint(FixAtoms(mask=held))
    reference.calc = EMT()
    path_ase, nsteps = ase_trajectory(reference, 1e-4, 200, memory=memory)

    def project(v):
        out = v.copy()
        out[held] = 0.0
        return out

    path, out = own_trajectory(atoms, EMT(), project, 1e-4, 200, memory=memory)
    assert nsteps > 20 and (memory == 100 or nsteps > memory)  # memory 3: the ring wraps
    assert out.converged and out.steps == nsteps
    assert out.force_calls == nsteps + 1 == len(path)  # one evaluation per step
    worst = max(np.abs(a - b).max() for a, b in zip(path_ase, path, strict=True))
    assert worst < 1e-11  # measured: 6e-14 Å over 91 steps, 9e-14 Å over 185 (memory 3)
    assert np.array_equal(out.positions[held], atoms.positions[held])


def test_same_steps_as_ase_along_z_only():
    atoms, held = cu_slab()
    free = np.flatnonzero(~held)
    reference = atoms.copy()
    reference.set_constraint([FixAtoms(mask=held), FixCartesian(free, mask=(True, True, False))])
    reference.calc = EMT()
    path_ase, nsteps = ase_trajectory(reference, 1e-4, 200)

    def project(v):
        out = v.copy()
        out[held] = 0.0
        out[:, :2] = 0.0
        return out

    path, out = own_trajectory(atoms, EMT(), project, 1e-4, 200)
    assert out.steps == nsteps
    assert max(np.abs(a - b).max() for a, b in zip(path_ase, path, strict=True)) < 1e-9
    assert np.array_equal(out.positions[:, :2], atoms.positions[:, :2])


@pytest.mark.parametrize("mode", ["full", "normal"])
def test_scan_projector_takes_ase_steps(mode):
    """The scan's own projector (``constraint_projector``: 0/1 factors written into
    lbfgs_relax's reused arrays) against ASE's FixAtoms (and FixCartesian in ``normal``)."""
    atoms, held = cu_slab()
    free = np.flatnonzero(~held)
    constraints = [FixAtoms(mask=held)]
    if mode == "normal":
        constraints.append(FixCartesian(free, mask=(True, True, False)))
    reference = atoms.copy()
    reference.set_constraint(constraints)
    reference.calc = EMT()
    path_ase, nsteps = ase_trajectory(reference, 1e-4, 200)
    project = constraint_projector(held, mode, [])
    path, out = own_trajectory(atoms, EMT(), project, 1e-4, 200)
    assert out.converged and out.steps == nsteps > 10
    assert max(np.abs(a - b).max() for a, b in zip(path_ase, path, strict=True)) < 1e-9
    assert np.array_equal(out.positions[held], atoms.positions[held])
    if mode == "normal":
        assert np.array_equal(out.positions[:, :2], atoms.positions[:, :2])


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(1, 300), scale=st.floats(-9.0, 3.0))
def test_largest_atomic_norm_is_ases(seed, n, scale):
    """ASE's norm, np.sqrt((v**2).sum(axis=1).max()), to the last bit, with or without the
    scratch array (which must not change the input)."""
    v = np.random.default_rng(seed).normal(size=(n, 3)) * 10.0**scale
    expected = float(np.sqrt((v**2).sum(axis=1).max()))
    before = v.copy()
    assert largest_atomic_norm(v) == expected
    assert largest_atomic_norm(v, np.empty_like(v)) == expected
    assert np.array_equal(v, before)


class Quadratic(Calculator):
    """E = ½ (x - x0)ᵀ K (x - x0) with K symmetric positive definite."""

    implemented_properties = ("energy", "forces")

    def __init__(self, k, x0):
        super().__init__()
        self.k, self.x0 = k, x0

    def calculate(self, atoms=None, properties=("energy",), system_changes=all_changes):
        super().calculate(atoms, properties, system_changes)
        d = (self.atoms.positions - self.x0).ravel()
        self.results = {"energy": 0.5 * d @ self.k @ d, "forces": -(self.k @ d).reshape(-1, 3)}


@settings(max_examples=25, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n_atoms=st.integers(2, 6),
    memory=st.integers(1, 8),
    stiffness=st.floats(0.5, 60.0),
)
def test_quadratic_steps_equal_ase(seed, n_atoms, memory, stiffness):
    """On random convex quadratics (eigenvalues 0.5-60 eV/Å², the maxstep cap active early)
    both take the same number of steps to the same minimum."""
    rng = np.random.default_rng(seed)
    n = 3 * n_atoms
    q, _ = np.linalg.qr(rng.normal(size=(n, n)))
    k = q @ np.diag(rng.uniform(0.5, stiffness, n)) @ q.T
    x0 = rng.normal(size=(n_atoms, 3))
    from ase import Atoms

    atoms = Atoms(f"H{n_atoms}", positions=x0 + rng.normal(0, 1.0, (n_atoms, 3)))
    reference = atoms.copy()
    reference.calc = Quadratic(k, x0)
    path_ase, nsteps = ase_trajectory(reference, 1e-6, 400, memory=memory)
    path, out = own_trajectory(
        atoms, Quadratic(k, x0), lambda v: v.copy(), 1e-6, 400, memory=memory
    )
    assert out.steps == nsteps
    assert np.abs(path[-1] - path_ase[-1]).max() < 1e-8
    if out.converged:  # the minimum of the quadratic
        assert np.abs(out.positions - x0).max() < 1e-6 / 0.5 * 1.01


def test_two_loop_memory_equals_the_loops():
    """H·g from the triangular solves equals ASE's two loops written out, with a wrapped ring."""
    rng = np.random.default_rng(3)
    n, memory = 12, 4
    mem = TwoLoopMemory(n, memory=memory, alpha=70.0)
    pairs = []
    for _ in range(7):
        s, y = rng.normal(size=n), rng.normal(size=n)
        mem.add(s, y)
        pairs = [*pairs, (s, y)][-memory:]
    g = rng.normal(size=n)
    q = g.copy()
    a = np.empty(len(pairs))
    for i in range(len(pairs) - 1, -1, -1):
        s, y = pairs[i]
        a[i] = np.dot(s, q) / np.dot(y, s)
        q -= a[i] * y
    z = q / 70.0
    for i, (s, y) in enumerate(pairs):
        b = np.dot(y, z) / np.dot(y, s)
        z += s * (a[i] - b)
    assert np.allclose(mem.inverse_hessian_times(g), z, rtol=1e-10, atol=1e-12)


def test_converged_start_costs_one_evaluation():
    atoms, _ = cu_slab()
    calls = []

    def evaluate(x):
        calls.append(1)
        return 0.0, np.zeros_like(x)

    out = lbfgs_relax(evaluate, atoms.positions, lambda v: v, 1e-3, 10)
    assert out.converged and out.steps == 0 and len(calls) == out.force_calls == 1


def explicit_loops(pairs, g, alpha):
    """ASE's two-loop recursion written out (Nocedal & Wright, Algorithm 7.4)."""
    q = g.copy()
    a = np.empty(len(pairs))
    for i in range(len(pairs) - 1, -1, -1):
        s, y = pairs[i]
        a[i] = np.dot(s, q) / np.dot(y, s)
        q -= a[i] * y
    z = q / alpha
    for i, (s, y) in enumerate(pairs):
        b = np.dot(y, z) / np.dot(y, s)
        z += s * (a[i] - b)
    return z


@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(3, 90),
    memory=st.integers(1, 12),
    steps=st.integers(1, 30),
    held=st.floats(0.0, 0.5),
)
@example(seed=121681, n=3, memory=1, steps=19, held=0.5)  # |d| 1e-9: cancellation
def test_push_equals_the_loops_on_random_histories(seed, n, memory, steps, held):
    """The step's path (four matrix-vector products, products of the new pair from the saved
    ones) equals the loops to 1e-12 of the operands' scale at every step of a random history: gradients of a random
    convex quadratic plus noise, steps s = t P(H g) with random scales t and a random set of
    held coordinates (P zeroes them), the ring wrapping when steps > memory."""
    rng = np.random.default_rng(seed)
    mask = rng.random(n) >= held
    mask[: n // 2] = True  # at least half the coordinates free
    q, _ = np.linalg.qr(rng.normal(size=(n, n)))
    k = q @ np.diag(rng.uniform(0.5, 60.0, n)) @ q.T

    def grad(x):
        return mask * (k @ x + 1e-3 * rng.normal(size=n))

    mem = TwoLoopMemory(n, memory=memory, alpha=70.0)
    x = rng.normal(size=n) * mask
    g = grad(x)
    d = mem.inverse_hessian_times(g)
    pairs = []
    for _ in range(steps):
        t = -rng.uniform(0.1, 1.0)
        x_new = x + t * (mask * d)
        g_new = grad(x_new)
        s, y = x_new - x, g_new - g
        pairs = [*pairs, (s, y)][-memory:]
        d = mem.push(s, y, g_new, t)
        want = explicit_loops(pairs, g_new, 70.0)
        # round-off against the scale of the operands: near convergence the loops cancel
        # (|d| << |g|), and 1e-12 of |d| alone is below a few ulps of the sums they add
        scale = max(np.abs(want).max(), np.abs(g_new).max())
        assert np.abs(d - want).max() <= 1e-12 * scale
        x, g = x_new, g_new


@settings(max_examples=30, deadline=None)
@given(
    seed=st.integers(0, 2**31 - 1),
    n=st.integers(3, 60),
    memory=st.integers(1, 8),
    steps=st.integers(1, 20),
)
def test_gradient_rows_path_equals_the_loops(seed, n, memory, steps):
    """lbfgs_relax's path: g kept in the memory's own gradient rows (alternating), the pair
    written into its slot, -H g from one product over the gradient row and the slots
    (``factor=-1``), equals minus the loops to 1e-12 at every step, the ring wrapping."""
    rng = np.random.default_rng(seed)
    q, _ = np.linalg.qr(rng.normal(size=(n, n)))
    k = q @ np.diag(rng.uniform(0.5, 60.0, n)) @ q.T
    mem = TwoLoopMemory(n, memory=memory, alpha=70.0)
    g, g_prev = mem.gradients
    x = rng.normal(size=n)
    g[...] = k @ x
    step = np.empty(n)
    mem.inverse_hessian_times(g, out=step, factor=-1.0)
    np.testing.assert_array_equal(step, -(g * (1.0 / 70.0)))  # H0 = I/α, as ASE multiplies
    pairs = []
    for _ in range(steps):
        t = rng.uniform(0.1, 1.0)
        x_new = x + t * step
        g, g_prev = g_prev, g
        g[...] = k @ x_new + 1e-3 * rng.normal(size=n)
        s, y = mem.next_pair()
        np.subtract(x_new, x, out=s)
        np.subtract(g, g_prev, out=y)
        pairs = [*pairs, (s.copy(), y.copy())][-memory:]
        mem.push_stored(g, -t, out=step, factor=-1.0)
        want = -explicit_loops(pairs, g, 70.0)
        assert np.abs(step - want).max() <= 1e-12 * np.abs(want).max()
        x = x_new


def test_memory_rule():
    """ASE's 100 pairs up to 1,000 atoms (every preset and example: their iterates stay);
    beyond, the stored coordinates m·n stay within the budget, never below the floor."""
    from flatcontact.ispes.lbfgs import (
        ASE_MEMORY,
        MIN_LARGE_CELL_MEMORY,
        PAIR_BUDGET_COORDS,
        memory_for,
    )

    assert memory_for(3 * 36) == memory_for(3 * 1000) == ASE_MEMORY
    sizes = [3 * a for a in (1001, 1536, 4704, 10_000, 20_184, 100_000)]
    got = [memory_for(n) for n in sizes]
    assert got == sorted(got, reverse=True) and got[0] < ASE_MEMORY
    for n, m in zip(sizes, got, strict=True):
        assert m * n <= PAIR_BUDGET_COORDS or m == MIN_LARGE_CELL_MEMORY
        assert (m + 1) * n > PAIR_BUDGET_COORDS
    assert memory_for(3 * 4704) == 21 and memory_for(3 * 20_184) == MIN_LARGE_CELL_MEMORY
    with pytest.raises(ValueError, match="n_coords"):
        memory_for(0)


@pytest.mark.parametrize("memory", [None, 3])
def test_converges_on_a_large_quadratic(memory):
    """E = ½ Σ k_i (x_i - x0_i)² on 4,000 atoms (the memory rule's regime: 12,000 coordinates,
    25 pairs): converged means every atomic force below fmax, so |x - x0| < fmax/k_min per
    component; held atoms stay put."""
    rng = np.random.default_rng(5)
    shape = (4000, 3)
    kk = rng.uniform(1.0, 30.0, shape)
    x0 = rng.normal(size=shape)
    held = np.zeros(shape, dtype=bool)
    held[:100] = True

    def evaluate(x):
        d = x - x0
        return 0.5 * float(np.sum(kk * d * d)), -kk * d

    def project(v):
        out = v.copy()
        out[held] = 0.0
        return out

    start = x0 + rng.normal(scale=0.3, size=shape)
    out = lbfgs_relax(evaluate, start, project, 1e-4, 500, memory=memory)
    assert out.converged and out.force_calls == out.steps + 1
    free = ~held
    assert np.abs(out.positions - x0)[free].max() < 1e-4 / 1.0
    np.testing.assert_array_equal(out.positions[held], start[held])


def test_converges_on_rosenbrock_pairs():
    """Σ over atoms of the Rosenbrock valley (1 - u)² + 10 (v - u²)² + w² (u, v, w the atom's
    coordinates): minimum at (1, 1, 0) for every atom, a curved valley that a fixed step
    would crawl along. Both ASE's memory and the large-cell floor reach it."""
    rng = np.random.default_rng(2)
    start = rng.uniform(-1.5, 1.5, (50, 3))

    def evaluate(x):
        u, v, w = x[:, 0], x[:, 1], x[:, 2]
        energy = np.sum((1 - u) ** 2 + 10 * (v - u * u) ** 2 + w * w)
        grad = np.stack([-2 * (1 - u) - 40 * u * (v - u * u), 20 * (v - u * u), 2 * w], axis=1)
        return float(energy), -grad

    for memory in (100, 20):
        out = lbfgs_relax(evaluate, start, lambda v: v.copy(), 1e-6, 2000, memory=memory)
        assert out.converged and out.steps < 2000
        np.testing.assert_allclose(out.positions, np.tile([1.0, 1.0, 0.0], (50, 1)), atol=1e-5)


def scaled_lbfgs_path(atoms, calc, held, fmax, steps, alpha=70.0, maxstep=0.2):
    """The textbook L-BFGS with H0 = γ_k I, γ_k = s·y/y·y of the newest pair (Nocedal &
    Wright, Algorithm 7.5, eq. 7.20; 1/α before the first pair), ASE's step-length rule,
    written out with the explicit loops: the positions before every evaluation."""
    probe = atoms.copy()
    probe.calc = calc

    def gradient(x):
        probe.positions = x.reshape(-1, 3)
        f = probe.get_forces().copy()
        f[held] = 0.0
        return -f.ravel()

    x = atoms.positions.ravel().copy()
    g = gradient(x)
    path, pairs, h0 = [x.copy()], [], 1.0 / alpha
    for _ in range(steps):
        if np.sqrt((g.reshape(-1, 3) ** 2).sum(axis=1).max()) < fmax:
            break
        p = -explicit_loops(pairs, g, 1.0 / h0)
        longest = np.sqrt((p.reshape(-1, 3) ** 2).sum(axis=1).max())
        if longest >= maxstep:
            p *= maxstep / longest
        x_new = x + p
        g_new = gradient(x_new)
        s, y = x_new - x, g_new - g
        pairs = [*pairs, (s, y)][-100:]
        if s @ y > 0.0:
            h0 = (s @ y) / (y @ y)
        x, g = x_new, g_new
        path.append(x.copy())
    return [v.reshape(-1, 3) for v in path]


def test_scaled_steps_equal_the_textbook_iteration():
    """``scaled=True`` (H0 = γ I) takes the steps of the written-out textbook L-BFGS to
    round-off, converges to ASE's minimum (same tolerance) and holds the held atoms."""
    atoms, held = cu_slab()

    def project(v):
        out = v.copy()
        out[held] = 0.0
        return out

    path, out = own_trajectory(atoms, EMT(), project, 1e-4, 300, scaled=True)
    expected = scaled_lbfgs_path(atoms, EMT(), held, 1e-4, 300)
    assert out.converged and out.force_calls == len(path) == len(expected) > 10
    assert max(np.abs(a - b).max() for a, b in zip(expected, path, strict=True)) < 1e-9
    assert np.array_equal(out.positions[held], atoms.positions[held])
    _, ase_out = own_trajectory(atoms, EMT(), project, 1e-4, 300)
    assert ase_out.converged and np.abs(out.positions - ase_out.positions).max() < 1e-3
    assert abs(out.energy_ev - ase_out.energy_ev) < 1e-6
