"""The relaxed noise floor (flatcontact.ispes.relax_noise): it is the relaxation's force
tolerance, measured: on the toy pair interface it rises with fmax, stays under the harmonic
bound n·fmax²/(2 λ_min) of the energy an optimiser leaves above a minimum (λ_min from a
finite-difference Hessian written here), and vanishes with fmax."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from flatcontact.ispes.geometry import fixed_mask, place_slab2
from flatcontact.ispes.relax import PointTask, RelaxSettings, relax_point
from flatcontact.ispes.relax_noise import relaxation_noise, relaxes_something
from flatcontact.ispes.shift_lattice import shift_lattice_of, translation_noise_ev_per_a2
from flatcontact.structures.interface_contract import in_plane_vectors, thickness
from flatcontact.structures.toy import ToyPairCalculator, toy_interface

FMAX = (1e-4, 1e-3, 1e-2, 1e-1)


@pytest.fixture(scope="module")
def toy():
    reference = toy_interface(layers=3)
    z0 = thickness(reference)
    return reference, ToyPairCalculator(), [z0 - 0.2, z0, z0 + 0.3]


def _softest_z_curvature(reference, calc, zs) -> float:
    """Smallest eigenvalue (eV/Å²) of the Hessian of E in the free atoms' heights, over a
    4 × 4 grid of shifts at each thickness: each point relaxed to 1e-8 eV/Å, then central
    differences of the forces (plain numpy)."""
    lowest = np.inf
    for a, b, z in itertools.product(np.arange(4) / 4, np.arange(4) / 4, zs):
        task = PointTask(index=(0, 0, 0), shift_a=a, shift_b=b, thickness=z)
        r = relax_point(reference, calc, task, RelaxSettings(1e-8, mode="normal"))
        atoms = place_slab2(reference, a, b, z)
        atoms.positions = r.positions
        free = np.flatnonzero(~fixed_mask(atoms))
        h, hess = 1e-4, np.zeros((free.size, free.size))
        for k, i in enumerate(free):
            f = []
            for sign in (1, -1):
                moved = atoms.copy()
                moved.positions[i, 2] += sign * h
                moved.calc = calc
                f.append(moved.get_forces()[free, 2])
            hess[:, k] = -(f[0] - f[1]) / (2 * h)
        lowest = min(lowest, float(np.linalg.eigvalsh(0.5 * (hess + hess.T))[0]))
    return lowest


def test_the_relaxation_floor_rises_with_fmax_under_the_harmonic_bound(toy):
    """Near a minimum with Hessian H an optimiser stopped at max |F_i| < fmax leaves
    ΔE = ½ Fᵀ H⁻¹ F ≤ n_free·fmax²/(2 λ_min) above it; three relaxations of one structure
    differ by at most that. The measured floor stays below it at every tolerance, rises with
    fmax, and is 1e4 times smaller at 1e-4 than at 1e-1 eV/Å (the bound: 1e6)."""
    reference, calc, zs = toy
    lattice = shift_lattice_of(reference)
    a1, a2 = in_plane_vectors(reference)
    area = abs(a1[0] * a2[1] - a1[1] * a2[0])
    n_free = int((~fixed_mask(reference)).sum())
    lam = _softest_z_curvature(reference, calc, zs)
    assert lam > 0
    floors = []
    for fmax in FMAX:
        noise = relaxation_noise(reference, calc, lattice, RelaxSettings(fmax, mode="normal"), zs)
        assert noise.relaxations == 12 and noise.unconverged == 0 and noise.force_calls > 12
        bound = n_free * fmax**2 / (2 * lam) / area
        assert 0 < noise.ev_per_a2 <= bound, (fmax, noise.ev_per_a2, bound)
        floors.append(noise.ev_per_a2)
    assert all(a < b for a, b in itertools.pairwise(floors)), floors
    assert floors[-1] / floors[0] > 1e4, floors
    # the rigid floor of the toy: s and s + (1, 0) are the same atoms to the bit
    assert translation_noise_ev_per_a2(reference, calc, lattice) <= floors[0]


@pytest.mark.parametrize("mode", ["full", "rigid-layers"])
def test_every_relaxing_mode_has_a_floor_that_rises_with_fmax(toy, mode):
    reference, calc, zs = toy
    lattice = shift_lattice_of(reference)
    loose, tight = (
        relaxation_noise(reference, calc, lattice, RelaxSettings(f, mode=mode), zs).ev_per_a2
        for f in (1e-2, 1e-4)
    )
    assert loose > 100 * tight > 0, (loose, tight)


def test_a_scan_that_relaxes_nothing_has_no_relaxation_floor(toy):
    reference, _, _ = toy
    assert relaxes_something(reference, RelaxSettings(0.01, mode="normal"))
    assert not relaxes_something(reference, RelaxSettings(0.01, mode="rigid"))
    held = reference.copy()
    held.arrays["held"] = np.ones(len(held), bool)
    assert not relaxes_something(held, RelaxSettings(0.01, mode="full"))


@pytest.mark.slow
def test_relaxed_twisted_graphene_has_a_tolerance_floor_far_above_its_round_off():
    """The (1, 2) twist of two 2-sheet graphene slabs, REBO + KC, ``normal``: the relaxation
    floor at the quick preset's 0.01 eV/Å is orders of magnitude above the engine's round-off
    (the rigid floor) and falls with the tolerance. Measured (shared machine): 7.9e-4, 1.4e-4,
    9.4e-5 meV/Å² at 0.01, 0.002, 5e-4 eV/Å, rigid 3e-12; ~20 s per tolerance."""
    from flatcontact.config.load import build_config
    from flatcontact.potentials.engines import make_calculator
    from flatcontact.structures.construct import build_interface

    cfg = build_config(
        {
            "structure": {"kind": "sheets", "sheet": "graphene", "layers": 2, "twist": [1, 2]},
            "potential": {"preset": "graphene-rebo-kc"},
            "elastic": {"enabled": True},
        }
    )
    atoms, _ = build_interface(cfg.section("structure"))
    calc = make_calculator(cfg.potential, atoms)
    lattice = shift_lattice_of(atoms)
    assert lattice.index == 49
    z = thickness(atoms)
    rigid = translation_noise_ev_per_a2(atoms, calc, lattice)
    loose, tight = (
        relaxation_noise(
            atoms, calc, lattice, RelaxSettings(f, mode="normal"), [z - 0.3, z, z + 0.3]
        )
        for f in (0.01, 0.0005)
    )
    assert loose.unconverged == tight.unconverged == 0
    assert loose.ev_per_a2 > 3 * tight.ev_per_a2 > 0, (loose, tight)
    assert tight.ev_per_a2 > 1e3 * rigid, (tight, rigid)
