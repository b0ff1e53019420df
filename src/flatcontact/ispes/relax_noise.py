"""The noise floor of a relaxed ISPES: round-off plus the relaxation's force tolerance.

A rigid scan's energies differ from exact arithmetic by the engine's round-off only
(:func:`flatcontact.ispes.shift_lattice.translation_noise_ev_per_a2`). A relaxed point
(``normal``, ``full``, ``rigid-layers``; :mod:`flatcontact.ispes.relax`) stops where the
largest projected force on a free atom is below ``fmax``, somewhere in a basin of size
set by that tolerance around the minimum: near a minimum with Hessian H the energy left
above it is ΔE ≈ ½ Fᵀ H⁻¹ F ≤ n_free · fmax² / (2 λ_min) (n_free the relaxed coordinates,
λ_min the softest eigenvalue of H, eV/Å²), and where in the basin a point stops depends on
where it started: a scan's warm start from its neighbour. Its landscape therefore carries
a point-to-point scatter the rigid floor does not see.

Measured, not assumed (:func:`relaxation_noise`): at ``samples`` random shifts s, each at
one of the scan's thicknesses (cycled in the order given), the stack at s, s + b1 and
s + b2 (b1, b2 the shift-lattice basis: the same structure in exact arithmetic) is relaxed
three times with the scan's own settings, each from the rigid placement with its own
random start perturbation of the free atoms (uniform in ±``perturbation_angstrom`` per
Cartesian component; the mode keeps only what it relaxes: z in ``normal``, each layer's
mean z in ``rigid-layers``). The floor is the largest spread (max − min) of the three
energies over the samples, divided by the supercell area (eV/Å²): the scatter of energies
of one structure at fixed thickness, round-off included. It is a floor for the energy per
area at fixed thickness; the constant-load landscape also carries the load's error
(:mod:`flatcontact.analysis.noise`), which this does not add.

It is the scatter a relaxation *may* leave at that tolerance, from a start that is not already
at the minimum. A scan's warm start from a neighbour on a nearly flat landscape can begin much
closer and stop much closer (measured, docs/incommensurate.md: the rigid-layers H-diamond(111)
/graphene cells' whole lateral range is 5–10× below this floor), but nothing in the scan
shows that it did; the floor is the tolerance's guarantee, not the scan's luck.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from flatcontact.ispes.geometry import fixed_mask, in_plane_vectors, place_slab2
from flatcontact.ispes.relax import PointTask, RelaxSettings, relax_point

#: Default amplitude (Å) of the random start perturbation of each free coordinate: far above
#: the change of the relaxed heights between neighbouring grid points (a scan's warm start),
#: so the optimiser approaches the minimum from an independent side each time.
PERTURBATION_ANGSTROM = 0.02


@dataclasses.dataclass(frozen=True)
class RelaxationNoise:
    """The relaxed noise floor and what it cost (see the module docstring)."""

    ev_per_a2: float  #: largest spread of one structure's relaxed energies per area (eV/Å²)
    fmax_ev_per_angstrom: float  #: the relaxation's force tolerance (eV/Å)
    mode: str  #: the relaxation mode
    relaxations: int  #: relaxations done (3 per sample)
    force_calls: int  #: force calls they took
    unconverged: int  #: relaxations that hit the step cap
    perturbation_angstrom: float  #: start perturbation per free coordinate (Å)

    def to_json(self) -> dict:
        """Plain numbers for ``study.json``; the floor in meV/Å²."""
        out = dataclasses.asdict(self)
        out["mev_per_a2"] = 1e3 * out.pop("ev_per_a2")
        return out


def relaxes_something(reference, relax: RelaxSettings) -> bool:
    """True when a scan point of ``reference`` relaxes anything in ``relax.mode`` (a mode other
    than ``rigid`` and at least one atom not held)."""
    return relax.mode != "rigid" and bool((~fixed_mask(reference)).any())


def relaxation_noise(
    reference,
    calculator,
    lattice,
    relax: RelaxSettings,
    thicknesses_angstrom,
    samples: int = 4,
    perturbation_angstrom: float = PERTURBATION_ANGSTROM,
    seed: int = 1,
) -> RelaxationNoise:
    """The noise floor of a relaxed scan of ``reference`` (module docstring).

    Parameters
    ----------
    reference
        The interface (``interface.extxyz`` contract).
    calculator
        Its calculator (reused for every relaxation).
    lattice
        The shift lattice (:class:`flatcontact.ispes.shift_lattice.ShiftLattice`): s and
        s + b are the same structure for b in ``lattice.basis``.
    relax
        The scan's per-point relaxation (tolerance, optimiser, step cap, mode).
    thicknesses_angstrom
        Thicknesses z (Å) to sample, cycled over the samples (the scan's grid).
    samples, perturbation_angstrom, seed
        Random shifts, start perturbation (Å per free coordinate) and the generator's seed.
    """
    zs = np.atleast_1d(np.asarray(thicknesses_angstrom, float))
    a1, a2 = in_plane_vectors(reference)
    area = float(abs(a1[0] * a2[1] - a1[1] * a2[0]))
    rng = np.random.default_rng(seed)
    worst, calls, count, unconverged = 0.0, 0, 0, 0
    for k in range(samples):
        s = rng.random(2)
        z = float(zs[k % len(zs)])
        energies = []
        for b in (np.zeros(2), *lattice.basis):
            t = s + np.asarray(b, float)
            placed = place_slab2(
                reference, float(t[0]), float(t[1]), z, spread_compression=relax.mode != "rigid"
            )
            free = ~fixed_mask(placed)
            start = placed.positions.copy()
            start[free] += rng.uniform(
                -perturbation_angstrom, perturbation_angstrom, (free.sum(), 3)
            )
            task = PointTask(
                index=(0, 0, 0),
                shift_a=float(t[0]),
                shift_b=float(t[1]),
                thickness=z,
                start_positions=start,
                start_shift=(float(t[0]), float(t[1])),
                start_thickness=z,
            )
            result = relax_point(reference, calculator, task, relax)
            energies.append(result.energy_ev)
            calls += result.force_calls
            count += 1
            unconverged += not result.converged
        worst = max(worst, max(energies) - min(energies))
    return RelaxationNoise(
        ev_per_a2=worst / area,
        fmax_ev_per_angstrom=relax.fmax_ev_per_angstrom,
        mode=relax.mode,
        relaxations=count,
        force_calls=calls,
        unconverged=unconverged,
        perturbation_angstrom=perturbation_angstrom,
    )
