"""The preconditioned L-BFGS (a fixed H0 = L L) and the reference Hessian it takes.

Checked against independent computations written here: Newton's step on a quadratic (H0 the
exact inverse Hessian: the first step lands on the minimum), the textbook two-loop recursion
with a matrix H0 (Nocedal & Wright, Algorithm 7.4) step for step, the unpreconditioned
iteration for L = I/√α, and exact central differences of a quadratic energy.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from ase.calculators.emt import EMT
from hypothesis import given, settings
from hypothesis import strategies as st
from tests.ispes.test_lbfgs import cu_slab, own_trajectory

from flatcontact.ispes.lbfgs import lbfgs_relax
from flatcontact.ispes.precondition import finite_difference_hessian, inverse_hessian_root
from flatcontact.ispes.relax import RelaxSettings, constraint_projector


def spd(rng, k, lo=0.5, hi=60.0):
    """A random symmetric positive definite k × k matrix with eigenvalues in [lo, hi]."""
    q, _ = np.linalg.qr(rng.normal(size=(k, k)))
    return (q * rng.uniform(lo, hi, k)) @ q.T


def quadratic(a_full, x_min):
    """E = ½ (x - x*)ᵀ A (x - x*) on flat coordinates; forces as (n, 3)."""

    def evaluate(x):
        d = x.ravel() - x_min.ravel()
        return 0.5 * d @ a_full @ d, -(a_full @ d).reshape(x.shape)

    return evaluate


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 10_000), n_atoms=st.integers(2, 8))
def test_exact_inverse_hessian_lands_on_the_minimum_in_one_step(seed, n_atoms):
    """H0 = A⁻¹ on the free coordinates of a quadratic: the first step is Newton's,
    x1 = x0 - A⁻¹ g0 = x*; two force calls, converged, held atoms untouched."""
    rng = np.random.default_rng(seed)
    held = np.zeros(n_atoms, dtype=bool)
    held[0] = True
    free = np.flatnonzero(np.repeat(~held, 3))
    n = 3 * n_atoms
    a_full = np.zeros((n, n))
    a_full[np.ix_(free, free)] = spd(rng, free.size)
    x_min = rng.normal(size=(n_atoms, 3))
    x0 = x_min + 0.03 * rng.normal(size=(n_atoms, 3))  # within the 0.2 Å step cap
    x0[held] = x_min[held]
    root = inverse_hessian_root(a_full[np.ix_(free, free)], free, n, 70.0, floor_fraction=0.0)
    project = constraint_projector(held, "full", [])
    out = lbfgs_relax(quadratic(a_full, x_min), x0, project, 1e-6, 50, preconditioner=root)
    assert out.converged and out.force_calls == 2
    np.testing.assert_allclose(out.positions, x_min, atol=1e-9)
    assert np.array_equal(out.positions[held], x0[held])


def textbook_path(evaluate, x0, held, h0, fmax, steps, scaled, maxstep=0.2):
    """L-BFGS with a matrix H0 (Nocedal & Wright Algorithm 7.4, the two loops written out;
    scaled: H0 → γ H0, γ = s·y/(y·H0 y)), no line search, ASE's cap on the longest atomic
    step: the positions before every evaluation."""
    keep = np.repeat(~held, 3).astype(float)

    def gradient(x):
        return -np.asarray(evaluate(x.reshape(-1, 3))[1]).ravel() * keep

    x = x0.ravel().copy()
    g, pairs, gamma, path = gradient(x), [], 1.0, [x.copy()]
    for _ in range(steps):
        if np.sqrt((g.reshape(-1, 3) ** 2).sum(axis=1).max()) < fmax:
            break
        q, a = g.copy(), []
        for s, y in reversed(pairs):
            a.append((s @ q) / (y @ s))
            q -= a[-1] * y
        r = gamma * (h0 @ q)
        for (s, y), ai in zip(pairs, reversed(a), strict=True):
            r += (ai - (y @ r) / (y @ s)) * s
        p = -r * keep
        longest = np.sqrt((p.reshape(-1, 3) ** 2).sum(axis=1).max())
        if longest >= maxstep:
            p *= maxstep / longest
        x_new = x + p
        g_new = gradient(x_new)
        s, y = x_new - x, g_new - g
        pairs = [*pairs, (s, y)][-100:]
        if scaled and s @ y > 0.0:
            gamma = (s @ y) / (y @ h0 @ y)
        x, g = x_new, g_new
        path.append(x.copy())
    return [v.reshape(-1, 3) for v in path]


@pytest.mark.parametrize("scaled", [False, True])
def test_preconditioned_steps_equal_the_textbook_iteration(scaled):
    """On the Cu slab with EMT (held bottom layer), H0 from a random SPD matrix on the free
    coordinates: the built-in iteration in u = L⁻¹x visits the positions of the written-out
    two-loop recursion with the matrix H0, to round-off, and converges."""
    atoms, held = cu_slab()
    rng = np.random.default_rng(3)
    free = np.flatnonzero(np.repeat(~held, 3))
    n = atoms.positions.size
    root = inverse_hessian_root(spd(rng, free.size, 2.0, 40.0), free, n, 70.0)
    h0 = root @ root
    project = constraint_projector(held, "full", [])
    path, out = own_trajectory(atoms, EMT(), project, 1e-4, 300, preconditioner=root, scaled=scaled)

    probe = atoms.copy()
    probe.calc = EMT()

    def evaluate(x):
        probe.positions = x
        return probe.get_potential_energy(), probe.get_forces()

    expected = textbook_path(evaluate, atoms.positions, held, h0, 1e-4, 300, scaled)
    assert out.converged and out.force_calls == len(path) == len(expected) > 5
    assert max(np.abs(a - b).max() for a, b in zip(expected, path, strict=True)) < 1e-9
    assert np.array_equal(out.positions[held], atoms.positions[held])


def test_identity_preconditioner_takes_the_unpreconditioned_steps():
    """L = I/√α: H0 = I/α, ASE's iteration (the built-in path without a preconditioner)."""
    atoms, held = cu_slab()
    project = constraint_projector(held, "full", [])
    root = np.eye(atoms.positions.size) / np.sqrt(70.0)
    path, out = own_trajectory(atoms, EMT(), project, 1e-4, 300, preconditioner=root)
    plain, ref = own_trajectory(atoms, EMT(), project, 1e-4, 300)
    assert out.force_calls == ref.force_calls == len(path) == len(plain) > 10
    assert max(np.abs(a - b).max() for a, b in zip(plain, path, strict=True)) < 1e-9


def test_finite_differences_are_exact_on_a_quadratic():
    """Central differences of a quadratic energy's forces give its Hessian to round-off,
    over the coordinates asked for, in their order, 2 calls per coordinate."""
    rng = np.random.default_rng(5)
    a_full = spd(rng, 12)
    calls = []
    evaluate = quadratic(a_full, rng.normal(size=(4, 3)))
    coords = np.array([11, 2, 3, 7])

    def counted(x):
        calls.append(1)
        return evaluate(x)

    k = finite_difference_hessian(counted, rng.normal(size=(4, 3)), coords)
    np.testing.assert_allclose(k, a_full[np.ix_(coords, coords)], atol=1e-9)
    assert len(calls) == 2 * coords.size


def test_the_hook_between_columns_runs_after_each_and_leaves_the_hessian_alone():
    """``between_columns`` (a scan's driver feeding its workers) is called once per column,
    after that column's two force calls, and K is bit for bit the same without it."""
    rng = np.random.default_rng(6)
    evaluate = quadratic(spd(rng, 9), rng.normal(size=(3, 3)))
    x0, coords = rng.normal(size=(3, 3)), np.array([0, 4, 8])
    events = []

    def counted(x):
        events.append("call")
        return evaluate(x)

    k = finite_difference_hessian(
        counted, x0, coords, between_columns=lambda: events.append("between")
    )
    assert events == ["call", "call", "between"] * coords.size
    np.testing.assert_array_equal(k, finite_difference_hessian(evaluate, x0, coords))


def test_root_is_the_floored_inverse_and_commutes_with_the_projector():
    rng = np.random.default_rng(2)
    free = np.array([3, 4, 5, 9, 10, 11])
    hessian = spd(rng, 6, 0.01, 50.0)
    root = inverse_hessian_root(hessian, free, 12, 70.0, floor_fraction=0.1)
    lam, vec = np.linalg.eigh(hessian)
    floored = (vec / np.maximum(lam, 0.1 * lam.max())) @ vec.T
    np.testing.assert_allclose((root @ root)[np.ix_(free, free)], floored, rtol=1e-10)
    mask = np.zeros(12)
    mask[free] = 1.0
    np.testing.assert_allclose(root * mask[None, :], mask[:, None] * root, atol=1e-15)
    held = np.setdiff1d(np.arange(12), free)
    np.testing.assert_allclose(np.diag(root)[held], 1 / np.sqrt(70.0))
    assert np.allclose(root, root.T)
    with pytest.raises(ValueError, match="positive curvature"):
        inverse_hessian_root(-hessian, free, 12, 70.0)


def test_the_preconditioner_applies_where_it_can_and_enters_the_store_only_there():
    """On by default; for the built-in L-BFGS in modes full and normal the store fingerprint
    says so, with the slip guard (a store written by the unguarded preconditioner, whose
    fingerprint said ``True``, is not resumed into); off, it is not in the fingerprint (a store
    of the plain iteration resumes); for other optimizers and modes the iterates do not depend
    on it, so it is not in the fingerprint and a store of that optimizer or mode resumes
    whatever the setting."""
    assert RelaxSettings().precondition and RelaxSettings().uses_reference_hessian
    guarded = "reference-hessian, slip-guarded"
    assert RelaxSettings().as_dict()["precondition"] == guarded
    assert "precondition" not in RelaxSettings(precondition=False).as_dict()
    assert RelaxSettings(mode="normal", optimizer="LBFGS", precondition=True).uses_reference_hessian
    for other in (
        RelaxSettings(optimizer="FIRE", precondition=True),
        RelaxSettings(mode="rigid-layers", precondition=True),
        RelaxSettings(optimizer="lammps-cg", precondition=True),
    ):
        assert not other.uses_reference_hessian
        assert "precondition" not in other.as_dict()
        off = dataclasses.replace(other, precondition=False)
        assert off.as_dict() == other.as_dict()


def test_the_cache_computes_once_per_calculator_and_key():
    """Per calculator and key once; other calculators (threads) do not evict it; a
    calculator's entries go with it."""
    import gc

    from flatcontact.ispes import precondition

    class Calc:
        pass

    computed = []

    def compute(tag):
        return lambda: computed.append(tag) or np.full((1, 1), float(len(computed)))

    precondition._CACHE.clear()
    a, others = Calc(), [Calc() for _ in range(4)]
    first = precondition.cached_root(a, "k", compute("a"))
    for i, other in enumerate(others):
        precondition.cached_root(other, "k", compute(i))
    assert precondition.cached_root(a, "k", compute("again")) is first
    assert computed == ["a", 0, 1, 2, 3]
    precondition.cached_root(a, "k2", compute("a2"))
    precondition.cached_root(a, "k3", compute("a3"))  # a keeps its last two keys
    precondition.cached_root(a, "k", compute("a again"))
    assert computed[-3:] == ["a2", "a3", "a again"]
    del others, other
    gc.collect()
    precondition.cached_root(a, "k", compute("no"))
    assert all(ref() is a for ref, _ in precondition._CACHE.values())
