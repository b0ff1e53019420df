"""Elastic constants of a bulk crystal and the contact moduli E*, G* they imply.

Conventions
-----------
* Voigt notation, ASE order (1..6 = xx, yy, zz, yz, xz, xy), engineering shear
  strains (``e_4 = 2 eps_yz``), stress with ASE's sign (positive = tensile), so
  ``sigma_i = sum_j C_ij e_j`` and ``C_ij = d sigma_i / d e_j``.
* Finite strain, central differences: ``C_ij = [sigma_i(+h e_j) - sigma_i(-h e_j)] / (2h)``
  on the zero-stress reference cell, ions relaxed at every strained cell
  ("relaxed-ion" constants; the clamped-ion ones with ``relax_ions=False``).
* Moduli in GPa.

Polycrystal averages (Hill, Proc. Phys. Soc. A 65, 349 (1952))::

    9 K_V = (C11 + C22 + C33) + 2 (C12 + C13 + C23)
    15 G_V = (C11 + C22 + C33) - (C12 + C13 + C23) + 3 (C44 + C55 + C66)
    1/K_R = (S11 + S22 + S33) + 2 (S12 + S13 + S23)
    15/G_R = 4 (S11 + S22 + S33) - 4 (S12 + S13 + S23) + 3 (S44 + S55 + S66)
    K = (K_V + K_R)/2,  G = (G_V + G_R)/2,  E = 9KG/(3K + G),  nu = (3K - 2G)/(2(3K + G))

Contact moduli of two identical isotropic bodies (Johnson, *Contact Mechanics*,
1985, eqs. 4.22 and 7.43)::

    1/E*     = 2 (1 - nu^2) / E
    1/G*_J   = 2 (2 - nu) / G          (full stick: q0 = 4 G*_J u / (pi a))
    G*_paper = 4 G*_J                  (the paper's q0 = G* u / (pi a))
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
from ase import Atoms
from ase.optimize import BFGS

from flatcontact.foundation.errors import require
from flatcontact.foundation.units import EV_PER_A3_TO_GPA
from flatcontact.potentials.engines import bulk_calculator
from flatcontact.potentials.model import InteractionModel
from flatcontact.structures.lattice import relax_cell  # the build's lattice relaxation

_VOIGT_PAIRS = ((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))


def strain_matrix(voigt_strain: np.ndarray) -> np.ndarray:
    """Symmetric strain tensor of an engineering Voigt strain vector."""
    e = np.asarray(voigt_strain, dtype=float)
    return np.array(
        [[e[0], e[5] / 2, e[4] / 2], [e[5] / 2, e[1], e[3] / 2], [e[4] / 2, e[3] / 2, e[2]]]
    )


def deformed(atoms: Atoms, voigt_strain: np.ndarray) -> Atoms:
    """Copy of ``atoms`` with cell and positions deformed by ``(1 + eps)``."""
    out = atoms.copy()
    out.set_cell(
        np.asarray(atoms.cell) @ (np.eye(3) + strain_matrix(voigt_strain)), scale_atoms=True
    )
    return out


def _stress(atoms: Atoms, calc, relax_ions: bool, fmax: float, steps: int) -> np.ndarray:
    a = atoms.copy()
    a.calc = calc
    if relax_ions and len(a) > 1:
        BFGS(a, logfile=None).run(fmax=fmax, steps=steps)
    return a.get_stress(voigt=True)


def elastic_tensor(
    atoms: Atoms,
    calc,
    strain: float = 0.005,
    relax_ions: bool = True,
    fmax: float = 1e-4,
    steps: int = 500,
) -> np.ndarray:
    """6x6 elastic tensor (GPa) by central finite strains of ``±strain`` about ``atoms``.

    ``atoms`` should be at zero stress (see :func:`relax_cell`); otherwise the
    result is the stress-strain coefficient at its stress.
    """
    require(0 < strain < 0.05, f"strain={strain}: expected 0 < strain < 0.05")
    c = np.zeros((6, 6))
    for j in range(6):
        e = np.zeros(6)
        e[j] = strain
        sp = _stress(deformed(atoms, e), calc, relax_ions, fmax, steps)
        sm = _stress(deformed(atoms, -e), calc, relax_ions, fmax, steps)
        c[:, j] = (sp - sm) / (2 * strain)
    return c * EV_PER_A3_TO_GPA


def trigonal_constants(c: np.ndarray) -> dict:
    """The seven independent constants of a trigonal (32, 3m, -3m) crystal, symmetry-averaged.

    For the x axis along a 2-fold axis: C22 = C11, C23 = C13, C24 = -C14,
    C56 = C14, C55 = C44, C66 = (C11 - C12)/2. The sign of C14 depends on the
    handedness and on which of the +/- a directions is +x; a 60° rotation about
    z flips it.
    """
    c = 0.5 * (np.asarray(c) + np.asarray(c).T)
    return {
        "C11": (c[0, 0] + c[1, 1]) / 2,
        "C12": c[0, 1],
        "C13": (c[0, 2] + c[1, 2]) / 2,
        "C14": (c[0, 3] - c[1, 3] + c[4, 5]) / 3,
        "C33": c[2, 2],
        "C44": (c[3, 3] + c[4, 4]) / 2,
        "C66": c[5, 5],
    }


@dataclass(frozen=True)
class IsotropicModuli:
    """Voigt-Reuss-Hill averages and contact moduli (all GPa except nu)."""

    bulk_voigt: float
    bulk_reuss: float
    shear_voigt: float
    shear_reuss: float
    bulk_modulus: float
    shear_modulus: float
    youngs_modulus: float
    poisson_ratio: float
    e_star: float
    g_star_johnson: float
    g_star_paper: float

    def as_dict(self) -> dict:
        return asdict(self)


def voigt_reuss_hill(c: np.ndarray) -> tuple[float, float, float, float]:
    """``(K_V, K_R, G_V, G_R)`` of a 6x6 stiffness (GPa); see the module docstring."""
    c = 0.5 * (np.asarray(c, dtype=float) + np.asarray(c, dtype=float).T)
    s = np.linalg.inv(c)
    kv = (c[0, 0] + c[1, 1] + c[2, 2] + 2 * (c[0, 1] + c[0, 2] + c[1, 2])) / 9
    gv = (
        c[0, 0]
        + c[1, 1]
        + c[2, 2]
        - (c[0, 1] + c[0, 2] + c[1, 2])
        + 3 * (c[3, 3] + c[4, 4] + c[5, 5])
    ) / 15
    kr = 1 / (s[0, 0] + s[1, 1] + s[2, 2] + 2 * (s[0, 1] + s[0, 2] + s[1, 2]))
    gr = 15 / (
        4 * (s[0, 0] + s[1, 1] + s[2, 2])
        - 4 * (s[0, 1] + s[0, 2] + s[1, 2])
        + 3 * (s[3, 3] + s[4, 4] + s[5, 5])
    )
    return float(kv), float(kr), float(gv), float(gr)


def contact_moduli(
    youngs_modulus: float, poisson_ratio: float, shear_modulus: float
) -> tuple[float, float, float]:
    """``(E*, G*_Johnson, G*_paper)`` of two identical isotropic bodies (GPa).

    ``1/E* = 2(1 - nu^2)/E``; ``1/G*_J = 2(2 - nu)/G``; ``G*_paper = 4 G*_J``.
    """
    e_star = youngs_modulus / (2 * (1 - poisson_ratio**2))
    g_j = shear_modulus / (2 * (2 - poisson_ratio))
    return e_star, g_j, 4 * g_j


def isotropic_moduli(c: np.ndarray) -> IsotropicModuli:
    """Hill-averaged K, G, E, nu and the contact moduli E*, G* from a 6x6 stiffness (GPa)."""
    kv, kr, gv, gr = voigt_reuss_hill(c)
    k, g = (kv + kr) / 2, (gv + gr) / 2
    e = 9 * k * g / (3 * k + g)
    nu = (3 * k - 2 * g) / (2 * (3 * k + g))
    e_star, g_j, g_p = contact_moduli(e, nu, g)
    return IsotropicModuli(kv, kr, gv, gr, k, g, e, nu, e_star, g_j, g_p)


def _calculator(model, atoms: Atoms):
    """A bulk calculator from a model (InteractionModel, its name) or an ASE calculator."""
    if isinstance(model, str | InteractionModel):
        return bulk_calculator(model, atoms)
    return model  # already an ASE calculator


def _relaxed_tensor(atoms: Atoms, model, strain: float) -> tuple[Atoms, np.ndarray]:
    calc = _calculator(model, atoms)
    relaxed = relax_cell(atoms, calc, fmax=1e-4)
    return relaxed, elastic_tensor(relaxed, calc, strain=strain, relax_ions=True, fmax=2e-4)


_CONVENTIONS = (
    "Voigt (xx,yy,zz,yz,xz,xy), relaxed ions, Hill averages; "
    "1/E* = 2(1-nu^2)/E, 1/G*_J = 2(2-nu)/G, G*_paper = 4 G*_J"
)


def crystal_contact_moduli(atoms: Atoms, model, strain: float = 0.005) -> dict:
    """Self-consistent contact moduli of any bulk crystal for any interaction model.

    ``model`` is an :class:`~flatcontact.potentials.InteractionModel` or a potential's name
    (their bulk calculator: :func:`flatcontact.potentials.engines.bulk_calculator`), or an
    ASE calculator. Relaxes cell and ions, computes the relaxed-ion C_ij by
    ±``strain`` central differences and returns a JSON-ready dict: ``cellpar`` (a, b, c in Å,
    angles in degrees), ``tensor_gpa`` and ``moduli_gpa`` (Hill K, G, E, nu; E*, G*_Johnson,
    G*_paper = 4 G*_Johnson for two identical isotropic bodies; see the module docstring).
    The Hill average treats the crystal as an isotropic polycrystal, which for strongly
    anisotropic (layered) crystals is a convention to state, not a property of the contact.
    """
    relaxed, c = _relaxed_tensor(atoms, model, strain)
    return {
        "cellpar": [float(v) for v in relaxed.cell.cellpar()],
        "strain": strain,
        "tensor_gpa": np.round(c, 3).tolist(),
        "moduli_gpa": isotropic_moduli(c).as_dict(),
        "conventions": _CONVENTIONS,
    }


def quartz_contact_moduli(potential="sio2-snap", strain: float = 0.005) -> dict:
    """Self-consistent contact moduli of alpha-quartz for a potential.

    ``potential``: a name or .snapcoeff path, or an :class:`~flatcontact.potentials.InteractionModel`.
    Relaxes alpha-quartz (cell and ions) with the potential, computes the relaxed-ion Cij by
    ±``strain`` finite strains, and returns a JSON-ready dict with ``a_angstrom``,
    ``c_angstrom``, ``cij_gpa`` (trigonal set), ``tensor_gpa`` and ``moduli_gpa`` (Hill
    K, G, E, nu; E*, G*_Johnson, G*_paper = 4 G*_Johnson for two identical bodies).
    These replace the paper's E* = 52.5 GPa and G* = 29 GPa when self-consistent moduli
    are asked for.
    """
    from flatcontact.structures.bulk import alpha_quartz

    q, c = _relaxed_tensor(alpha_quartz(), potential, strain)
    cp = q.cell.cellpar()
    return {
        "potential": potential if isinstance(potential, str) else potential.label,
        "a_angstrom": float(cp[0]),
        "c_angstrom": float(cp[2]),
        "strain": strain,
        "cij_gpa": {k: float(v) for k, v in trigonal_constants(c).items()},
        "tensor_gpa": np.round(c, 3).tolist(),
        "moduli_gpa": isotropic_moduli(c).as_dict(),
        "conventions": _CONVENTIONS,
    }
