"""The in-house L-BFGS takes ASE's LBFGS steps (to round-off), with one evaluation per step."""

from __future__ import annotations

import numpy as np
import pytest
from ase.build import fcc111
from ase.calculators.calculator import Calculator, all_changes
from ase.calculators.emt import EMT
from ase.constraints import FixAtoms, FixCartesian
from ase.optimize import LBFGS
from hypothesis import given, settings
from hypothesis import strategies as st

from flatcontact.ispes.lbfgs import TwoLoopMemory, lbfgs_relax


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
