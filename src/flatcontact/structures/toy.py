"""A cheap two-slab model interface that follows the interface contract.

Two identical fcc(111) slabs (one atom per layer in the primitive hexagonal
cell), bonded strongly inside each slab and weakly across the interface by
shifted-force Lennard-Jones pairs. It mimics the physics of a van der Waals
bonded interface (stiff slabs, soft and corrugated interfacial potential) at a
cost of well under a millisecond per force call, so that the scan machinery
(relaxation, warm starts, store, executors, resume) can be tested and
benchmarked without an interatomic potential file.

Conventions (the ``interface.extxyz`` contract,
:mod:`flatcontact.structures.interface_contract`): ``slab`` ∈ {1, 2},
``surface`` ∈ {0, 1, 2, 3, 4}; surfaces 1 and 4 are the outer faces; the
reference has slab 2 continuing the ABC stacking of slab 1 (the fcc stacking
across the interface, the lowest-energy registry) and is relaxed along z.

The scan's calculator target for this model is
``flatcontact.ispes.toy:toy_calculator`` (:mod:`flatcontact.ispes.toy`).
"""

from __future__ import annotations

import json
from typing import ClassVar

import numpy as np
from ase import Atoms
from ase.build import fcc111
from ase.calculators.calculator import Calculator, all_changes
from ase.constraints import FixedLine
from ase.optimize import BFGS

#: default model parameters (eV, Å)
EPS_INTRA_EV = 0.10
EPS_CROSS_EV = 0.02
SIGMA_ANGSTROM = 2.5
CUTOFF_SIGMA = 2.5


def lj_shifted_force(
    r: np.ndarray, eps: np.ndarray, sigma: float, rc: float
) -> tuple[np.ndarray, np.ndarray]:
    """Shifted-force Lennard-Jones pair energy and its radial derivative.

    V_sf(r) = V(r) - V(rc) - (r - rc) V'(rc) for r < rc, 0 beyond, with
    V(r) = 4 ε [(σ/r)^12 - (σ/r)^6] (Allen & Tildesley, *Computer Simulation of
    Liquids*, 2nd ed., §2.7): energy and force both go continuously to zero at rc.

    Returns
    -------
    (energy, dV_dr)
        Arrays like ``r`` in eV and eV/Å.
    """

    def v(x):
        s6 = (sigma / x) ** 6
        return 4.0 * eps * (s6 * s6 - s6)

    def dv(x):
        s6 = (sigma / x) ** 6
        return 4.0 * eps * (-12.0 * s6 * s6 + 6.0 * s6) / x

    inside = r < rc
    e = np.where(inside, v(r) - v(rc) - (r - rc) * dv(rc), 0.0)
    de = np.where(inside, dv(r) - dv(rc), 0.0)
    return e, de


def _pairs(atoms: Atoms, rc: float):
    """All pairs (i, j, |d|, d = r_j + image - r_i) closer than ``rc``, images along pbc x, y.

    Brute force over lattice images: the toy cell holds a handful of atoms, where this
    is an order of magnitude faster than a cell-list neighbour search.
    """
    cell = atoms.cell.array
    pos = atoms.positions
    area = abs(np.cross(cell[0], cell[1])[2])
    reach = [int(np.ceil(rc * np.linalg.norm(cell[1 - k][:2]) / area)) + 1 for k in (0, 1)]
    na = np.arange(-reach[0], reach[0] + 1) if atoms.pbc[0] else np.array([0])
    nb = np.arange(-reach[1], reach[1] + 1) if atoms.pbc[1] else np.array([0])
    shifts = (na[:, None, None] * cell[0] + nb[None, :, None] * cell[1]).reshape(-1, 3)
    d = pos[None, :, None, :] + shifts[None, None, :, :] - pos[:, None, None, :]  # i, j, image
    r = np.linalg.norm(d, axis=-1)
    i, j, m = np.nonzero((r < rc) & (r > 1e-8))
    return i, j, r[i, j, m], d[i, j, m]


class ToyPairCalculator(Calculator):
    """Shifted-force LJ with one ε inside each slab and another across the interface.

    Pair (i, j) uses ``eps_intra_ev`` if ``slab[i] == slab[j]`` else ``eps_cross_ev``;
    one σ and cutoff ``cutoff_sigma * σ`` for all pairs. Energy in eV, forces in eV/Å.
    """

    implemented_properties = ("energy", "free_energy", "forces")
    default_parameters: ClassVar[dict[str, float]] = {
        "eps_intra_ev": EPS_INTRA_EV,
        "eps_cross_ev": EPS_CROSS_EV,
        "sigma_angstrom": SIGMA_ANGSTROM,
        "cutoff_sigma": CUTOFF_SIGMA,
    }

    def calculate(self, atoms=None, properties=("energy",), system_changes=all_changes):
        super().calculate(atoms, properties, system_changes)
        p = self.parameters
        sigma = float(p["sigma_angstrom"])
        rc = float(p["cutoff_sigma"]) * sigma
        i, j, d, vec = _pairs(self.atoms, rc)
        slab = np.asarray(self.atoms.arrays["slab"])
        eps = np.where(slab[i] == slab[j], float(p["eps_intra_ev"]), float(p["eps_cross_ev"]))
        e, de = lj_shifted_force(d, eps, sigma, rc)
        # each pair appears twice: (i, j) and (j, i)
        energy = 0.5 * float(e.sum())
        fvec = (de / d)[:, None] * vec  # force on i from j: +dV/dr along r_j - r_i
        n = len(self.atoms)
        forces = np.stack(
            [np.bincount(i, weights=fvec[:, k], minlength=n) for k in range(3)], axis=1
        )
        self.results = {"energy": energy, "free_energy": energy, "forces": forces}


def toy_interface(
    layers: int = 3,
    gap_factor: float = 1.0,
    relax_fmax_ev_per_angstrom: float = 1e-5,
    **params: float,
) -> Atoms:
    """Build the toy two-slab interface and relax it along z (reference structure).

    Parameters
    ----------
    layers
        Atomic layers per slab (>= 3: an outer face, inner atoms, an inner face).
    gap_factor
        Initial interfacial gap in units of the in-slab layer spacing before relaxing.
    relax_fmax_ev_per_angstrom
        Force tolerance of the initial relaxation (every atom free along z only), eV/Å.
    params
        Overrides of :class:`ToyPairCalculator` parameters.
    """
    if layers < 3:
        raise ValueError("layers: at least 3 per slab (outer face, inner atoms, inner face)")
    sigma = float(params.get("sigma_angstrom", SIGMA_ANGSTROM))
    nn = 2.0 ** (1.0 / 6.0) * sigma  # nearest-neighbour distance of the LJ pair minimum
    a_fcc = np.sqrt(2.0) * nn
    slab = fcc111("Ar", size=(1, 1, layers), a=a_fcc, vacuum=0.0, orthogonal=False)
    slab.positions -= slab.positions[0]
    spacing = a_fcc / np.sqrt(3.0)
    top = slab.copy()
    # continue the ABC stacking into slab 2: layer k of slab 2 sits where layer `layers + k` would
    shift = (layers % 3) * (slab.positions[1] - slab.positions[0])
    shift[2] = layers * spacing + (gap_factor - 1.0) * spacing
    top.positions += shift
    atoms = slab + top
    atoms.cell[2] = [0.0, 0.0, 2 * layers * spacing + 20.0]
    atoms.pbc = [True, True, False]
    n = layers
    surface = np.zeros(2 * n, dtype=int)
    surface[0], surface[n - 1], surface[n], surface[2 * n - 1] = 1, 2, 3, 4
    atoms.arrays["slab"] = np.repeat([1, 2], n)
    atoms.arrays["surface"] = surface
    atoms.wrap()
    atoms.info["a1"] = atoms.cell[0][:2].tolist()
    atoms.info["a2"] = atoms.cell[1][:2].tolist()
    # the builder label names the module the toy was first built in; kept so that the
    # recipe, and with it interface.extxyz, stays byte-identical
    atoms.info["recipe"] = json.dumps(
        {"builder": "flatcontact.ispes.toy", "layers": layers, **params}
    )
    atoms.calc = ToyPairCalculator(**params)
    # initial optimisation: only z may relax (the lateral registry is the reference stacking)
    atoms.set_constraint([FixedLine(list(range(len(atoms))), [0, 0, 1])])
    BFGS(atoms, logfile=None).run(fmax=relax_fmax_ev_per_angstrom, steps=1000)
    atoms.set_constraint()
    atoms.calc = None
    return atoms
