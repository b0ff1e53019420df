r"""Cross-interface Lennard-Jones parameters from van der Waals DFT (Tkatchenko–Scheffler).

Free-atom reference data
    C6 (Hartree·bohr⁶) and static dipole polarisability α (bohr³) from Chu & Dalgarno,
    J. Chem. Phys. 121, 4083 (2004), as tabulated by Tkatchenko & Scheffler, PRL 102,
    073005 (2009) (taken from ``ase.calculators.vdwcorrection.vdWDB_alphaC6``); free-atom
    van der Waals radii R0 (bohr) from the TS 2009 table; every element H–Ba, Hf–Rn in
    :data:`TS_FREE_ATOM`.

Effective (in-material) values, TS 2009 Eqs. (7)–(9)
    With a Hirshfeld volume ratio v = V_eff/V_free per element:
    C6_eff = v²·C6_free, α_eff = v·α_free, R0_eff = v^{1/3}·R0_free (v = 1: free atoms).

Combination rule, TS 2009 Eq. (4)
    C6_AB = 2·C6_A·C6_B / ((α_B/α_A)·C6_A + (α_A/α_B)·C6_B).

Mapping C6 → (ε, σ) (our stated choice)
    The LJ attraction equals the dispersion tail, 4εσ⁶ = C6_AB, and the LJ minimum sits
    at the vdW contact distance, r_min = 2^{1/6}σ = R0_A + R0_B; hence
    σ_AB = 2^{-1/6}(R0_A + R0_B) and ε_AB = C6_AB / (4σ_AB⁶). User-given effective C6
    per pair replace C6_AB; σ still comes from the radii.

Calibration to a Hamaker constant (optional)
    Free-atom C6 ignore that atoms in a solid are less polarisable than free ones (for Si in
    SiO₂, a cation, by far): with them the pairwise Hamaker constant of α-quartz,
    A = π² Σ_AB C6_AB ρ_A ρ_B (Hamaker 1937; ρ = number densities), is ≈ 410 zJ, against
    ≈ 88 zJ from Lifshitz theory with measured dielectric spectra (Bergström, Adv. Colloid
    Interface Sci. 70, 125 (1997)). :func:`hamaker_c6_scale` gives the one factor on every
    C6 that makes A equal a target value; σ (the radii) is unchanged, so the LJ minima stay
    where they are and only their depths scale.

Cutoff and shift
    U(r) = 4ε[(σ/r)¹² − (σ/r)⁶] − U_LJ(r_c) for r < r_c, 0 beyond (energy shifted to be
    continuous at r_c = ``cutoff_angstrom``; LAMMPS ``lj/cut`` with ``pair_modify shift yes``).
    The force jump at r_c, 6C6/r_c⁷ ≈ 1e-5 eV/Å for Si–Si at 10 Å, is below any relaxation
    tolerance we use.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from ase import Atoms, units

from flatcontact.foundation import units as units_conv
from flatcontact.foundation.errors import InputError

#: Hartree·bohr⁶ → eV·Å⁶.
HARTREE_BOHR6_TO_EV_A6 = units.Hartree * units.Bohr**6
#: bohr → Å.
BOHR_TO_ANGSTROM = units.Bohr

#: Tkatchenko–Scheffler free-atom reference data per element, (α in bohr³, C6 in
#: Hartree·bohr⁶, R0 in bohr): α and C6 from Chu & Dalgarno, J. Chem. Phys. 121, 4083 (2004)
#: (TS 2009 reference table; ASE's ``vdWDB_alphaC6`` differs in 13: :data:`ASE_ALPHA_C6`), R0 from
#: TS, PRL 102, 073005 (2009); 4d/5d metals from the extended TS table used by FHI-aims,
#: VASP (IVDW=2) and libmbd. H–Ba and Hf–Rn (no lanthanides); others: give ``c6_ev_a6`` and
#: ``r0_angstrom``.
TS_FREE_ATOM: dict[str, tuple[float, float, float]] = {
    "H": (4.5, 6.5, 3.1), "He": (1.38, 1.46, 2.65), "Li": (164.2, 1387.0, 4.16),
    "Be": (38.0, 214.0, 4.17), "B": (21.0, 99.5, 3.89), "C": (12.0, 46.6, 3.59),
    "N": (7.4, 24.2, 3.34), "O": (5.4, 15.6, 3.19), "F": (3.8, 9.52, 3.04),
    "Ne": (2.67, 6.38, 2.91), "Na": (162.7, 1556.0, 3.73), "Mg": (71.0, 627.0, 4.27),
    "Al": (60.0, 528.0, 4.33), "Si": (37.0, 305.0, 4.2), "P": (25.0, 185.0, 4.01),
    "S": (19.6, 134.0, 3.86), "Cl": (15.0, 94.6, 3.71), "Ar": (11.1, 64.3, 3.55),
    "K": (292.9, 3897.0, 3.71), "Ca": (160.0, 2221.0, 4.65), "Sc": (120.0, 1383.0, 4.59),
    "Ti": (98.0, 1044.0, 4.51), "V": (84.0, 832.0, 4.44), "Cr": (78.0, 602.0, 3.99),
    "Mn": (63.0, 552.0, 3.97), "Fe": (56.0, 482.0, 4.23), "Co": (50.0, 408.0, 4.18),
    "Ni": (48.0, 373.0, 3.82), "Cu": (42.0, 253.0, 3.76), "Zn": (40.0, 284.0, 4.02),
    "Ga": (60.0, 498.0, 4.19), "Ge": (41.0, 354.0, 4.2), "As": (29.0, 246.0, 4.11),
    "Se": (25.0, 210.0, 4.04), "Br": (20.0, 162.0, 3.93), "Kr": (16.8, 129.6, 3.82),
    "Rb": (319.2, 4691.0, 3.72), "Sr": (199.0, 3170.0, 4.54), "Y": (126.737, 1968.58, 4.8151),
    "Zr": (119.97, 1677.91, 4.53), "Nb": (101.603, 1263.61, 4.2365),
    "Mo": (88.4225785, 1028.73, 4.099), "Tc": (80.083, 1390.87, 4.076),
    "Ru": (65.895, 609.754, 3.9953), "Rh": (56.1, 469.0, 3.95), "Pd": (23.68, 157.5, 3.66),
    "Ag": (50.6, 339.0, 3.82), "Cd": (39.7, 452.0, 3.99), "In": (70.22, 707.046, 4.23198),
    "Sn": (55.95, 587.417, 4.303), "Sb": (43.67197, 459.322, 4.276), "Te": (37.65, 396.0, 4.22),
    "I": (35.0, 385.0, 4.17), "Xe": (27.3, 285.9, 4.08), "Cs": (427.12, 6582.08, 3.78),
    "Ba": (275.0, 5727.0, 4.77), "Hf": (99.52, 1274.8, 4.21), "Ta": (82.53, 1019.92, 4.15),
    "W": (71.041, 847.93, 4.08), "Re": (63.04, 710.2, 4.02), "Os": (55.055, 596.67, 3.84),
    "Ir": (42.51, 359.1, 4.0), "Pt": (39.68, 347.1, 3.92), "Au": (36.5, 298.0, 3.86),
    "Hg": (33.9, 392.0, 3.98), "Tl": (69.92, 717.44, 3.91), "Pb": (61.8, 697.0, 4.31),
    "Bi": (49.02, 571.0, 4.32), "Po": (45.013, 530.92, 4.097), "At": (38.93, 457.53, 4.07),
    "Rn": (33.54, 390.63, 4.23),
}  # fmt: skip

#: (α in bohr³, C6 in Hartree·bohr⁶) of ASE's ``vdWDB_alphaC6`` (Chu & Dalgarno 2004, as ASE
#: tabulates them) for the 13 of its 40 elements where they differ from :data:`TS_FREE_ATOM`;
#: for its other 27 elements ASE's values are TS_FREE_ATOM's. :func:`ts_free_atom` takes
#: ASE's values where it has them; holding the differences here spares every scan worker
#: the import of ``ase.calculators.vdwcorrection`` (scipy.special, scipy.sparse,
#: scipy.spatial, ase.neighborlist: ≈ 0.2 s of CPU at start) for a table lookup.
#: ``tests/potentials/test_lj.py`` checks both statements against ASE's table.
ASE_ALPHA_C6: dict[str, tuple[float, float]] = {
    "He": (1.38, 1.42), "Li": (164, 1392), "Be": (38, 227), "Ne": (2.67, 6.2),
    "Na": (163, 1518), "Mg": (71, 626), "Ar": (11.1, 64.2), "Ca": (160, 2163),
    "Kr": (16.7, 130), "Sr": (199, 3175), "Te": (40, 445), "Pd": (23.7, 158),
    "Pt": (39.7, 347),
}  # fmt: skip

#: TS 2009 free-atom vdW radii R0 (bohr), from :data:`TS_FREE_ATOM`.
TS_R0_BOHR: dict[str, float] = {k: v[2] for k, v in TS_FREE_ATOM.items()}


def ts_elements() -> frozenset[str]:
    """The elements with Tkatchenko–Scheffler free-atom C6, α and R0."""
    return frozenset(TS_FREE_ATOM)


@dataclass(frozen=True)
class LJPair:
    """LJ parameters of one element pair: ε (eV), σ (Å), C6 = 4εσ⁶ (eV·Å⁶)."""

    epsilon_ev: float
    sigma_angstrom: float
    c6_ev_a6: float


def pair_key(a: str, b: str) -> str:
    """Canonical key of an element pair: symbols sorted alphabetically, joined by '-'."""
    return "-".join(sorted((a, b)))


def ts_free_atom(symbol: str) -> tuple[float, float]:
    """Free-atom (C6 in eV·Å⁶, α in bohr³) of ``symbol`` from the TS/Chu–Dalgarno table:
    ASE's ``vdWDB_alphaC6`` values where ASE has the element (:data:`ASE_ALPHA_C6`), else
    :data:`TS_FREE_ATOM`'s."""
    if symbol in ASE_ALPHA_C6:
        alpha, c6 = ASE_ALPHA_C6[symbol]
    elif symbol in TS_FREE_ATOM:
        alpha, c6, _ = TS_FREE_ATOM[symbol]
    else:
        raise InputError(
            f"element '{symbol}' has no Tkatchenko–Scheffler C6 reference value; give c6_ev_a6 for its pairs"
        )
    return c6 * HARTREE_BOHR6_TO_EV_A6, float(alpha)


def ts_combined_c6(c6_a: float, alpha_a: float, c6_b: float, alpha_b: float) -> float:
    """TS 2009 Eq. (4): C6_AB = 2 C6_A C6_B / ((α_B/α_A) C6_A + (α_A/α_B) C6_B)."""
    return 2.0 * c6_a * c6_b / ((alpha_b / alpha_a) * c6_a + (alpha_a / alpha_b) * c6_b)


def lj_from_c6(c6_ev_a6: float, r0_a_angstrom: float, r0_b_angstrom: float) -> LJPair:
    """σ = 2^{-1/6}(R0_A + R0_B), ε = C6/(4σ⁶)."""
    if not (c6_ev_a6 > 0 and r0_a_angstrom > 0 and r0_b_angstrom > 0):
        raise InputError(
            f"C6={c6_ev_a6} eV·Å⁶ and radii ({r0_a_angstrom}, {r0_b_angstrom}) Å must be > 0"
        )
    sigma = 2.0 ** (-1.0 / 6.0) * (r0_a_angstrom + r0_b_angstrom)
    return LJPair(epsilon_ev=c6_ev_a6 / (4.0 * sigma**6), sigma_angstrom=sigma, c6_ev_a6=c6_ev_a6)


#: Number densities of α-quartz (nm⁻³) from the experimental cell (a = 4.916 Å,
#: c = 5.405 Å, 3 SiO₂ per cell), for :func:`pairwise_hamaker_constant_zj`.
ALPHA_QUARTZ_NUMBER_DENSITY_PER_NM3: dict[str, float] = {
    "Si": 3.0 / (np.sqrt(3.0) / 2.0 * 4.916**2 * 5.405) * 1.0e3,
    "O": 6.0 / (np.sqrt(3.0) / 2.0 * 4.916**2 * 5.405) * 1.0e3,
}


def pairwise_hamaker_constant_zj(
    table: dict[str, LJPair], number_density_per_nm3: dict[str, float]
) -> float:
    """Hamaker's pairwise-summation constant of two identical bodies (zJ).

    A = π² Σ_A Σ_B C6_AB ρ_A ρ_B (Hamaker, Physica 4, 1058 (1937)), the sum over ordered
    element pairs of the body, with the C6 of ``table`` (eV·Å⁶) and the number densities
    ρ (nm⁻³). The non-retarded interaction energy per area of two half-spaces at a gap D
    is then −A/(12πD²).

    Raises
    ------
    InputError
        If a pair of the given elements is missing from ``table``.
    """
    total_ev = 0.0
    for a, rho_a in number_density_per_nm3.items():
        for b, rho_b in number_density_per_nm3.items():
            key = pair_key(a, b)
            if key not in table:
                raise InputError(f"no LJ parameters for the element pair {key} (Hamaker sum)")
            total_ev += table[key].c6_ev_a6 * rho_a * rho_b * units_conv.PER_NM3_TO_PER_A3**2
    return float(np.pi**2 * total_ev * units_conv.EV_TO_ZJ)


def hamaker_c6_scale(
    table: dict[str, LJPair], number_density_per_nm3: dict[str, float], hamaker_zj: float
) -> float:
    """The factor on every C6 that makes the pairwise Hamaker constant equal ``hamaker_zj``.

    A is linear in the C6, so the factor is ``hamaker_zj / pairwise_hamaker_constant_zj``.
    """
    if not hamaker_zj > 0:
        raise InputError(f"hamaker_zj={hamaker_zj}: expected > 0 zJ")
    return hamaker_zj / pairwise_hamaker_constant_zj(table, number_density_per_nm3)


def lj_table(
    symbols_1: list[str] | tuple[str, ...],
    symbols_2: list[str] | tuple[str, ...],
    *,
    c6_ev_a6: dict[str, float] | None = None,
    r0_angstrom: dict[str, float] | None = None,
    volume_ratio: dict[str, float] | None = None,
    c6_scale: float = 1.0,
) -> dict[str, LJPair]:
    """LJ parameters for every element pair (A from slab 1, B from slab 2), keyed by :func:`pair_key`.

    ``c6_ev_a6`` overrides C6 for given pairs ("O-Si"); ``r0_angstrom`` overrides the free-atom
    radius per element; ``volume_ratio`` applies the Hirshfeld scaling of TS 2009 Eqs. (7)–(9);
    ``c6_scale`` multiplies every C6 last (e.g. :func:`hamaker_c6_scale`), leaving σ unchanged.
    """
    if not c6_scale > 0:
        raise InputError(f"c6_scale={c6_scale}: expected > 0")
    c6_user = {pair_key(*k.split("-")): v for k, v in (c6_ev_a6 or {}).items()}
    r0_user = dict(r0_angstrom or {})
    ratio = dict(volume_ratio or {})

    def radius(sym: str) -> float:
        if sym in r0_user:
            r0 = r0_user[sym]
        elif sym in TS_R0_BOHR:
            r0 = TS_R0_BOHR[sym] * BOHR_TO_ANGSTROM
        else:
            raise InputError(f"element '{sym}' has no TS vdW radius R0; give r0_angstrom['{sym}']")
        return r0 * ratio.get(sym, 1.0) ** (1.0 / 3.0)

    table: dict[str, LJPair] = {}
    for a in sorted(set(symbols_1)):
        for b in sorted(set(symbols_2)):
            key = pair_key(a, b)
            if key in table:
                continue
            if key in c6_user:
                c6 = c6_user[key]
            else:
                c6_a, alpha_a = ts_free_atom(a)
                c6_b, alpha_b = ts_free_atom(b)
                va, vb = ratio.get(a, 1.0), ratio.get(b, 1.0)
                c6 = ts_combined_c6(va**2 * c6_a, va * alpha_a, vb**2 * c6_b, vb * alpha_b)
            table[key] = lj_from_c6(c6_scale * c6, radius(a), radius(b))
    return table


def lj_energy(r: np.ndarray, pair: LJPair, cutoff_angstrom: float) -> np.ndarray:
    """Shifted, truncated LJ energy (eV) at distances ``r`` (Å)."""
    r = np.asarray(r, dtype=float)

    def raw(x):
        s6 = (pair.sigma_angstrom / x) ** 6
        return 4.0 * pair.epsilon_ev * (s6 * s6 - s6)

    return np.where(r < cutoff_angstrom, raw(r) - raw(cutoff_angstrom), 0.0)


def lj_cross_energy_forces(
    atoms: Atoms, groups: np.ndarray, table: dict[str, LJPair], cutoff_angstrom: float
) -> tuple[float, np.ndarray]:
    """LJ energy (eV) and forces (eV/Å) between atoms of different ``groups`` only (vectorised).

    Periodic images follow ``atoms.pbc``; each cross pair is counted once.
    """
    from ase.neighborlist import neighbor_list

    i, j, d, vec = neighbor_list("ijdD", atoms, cutoff_angstrom)
    cross = groups[i] != groups[j]
    i, j, d, vec = i[cross], j[cross], d[cross], vec[cross]
    symbols = np.array(atoms.get_chemical_symbols())
    si, sj = symbols[i], symbols[j]
    first = np.where(si <= sj, si, sj)
    second = np.where(si <= sj, sj, si)
    keys = np.char.add(np.char.add(first, "-"), second)
    eps = np.empty(len(d))
    sig = np.empty(len(d))
    for key in np.unique(keys):
        if key not in table:
            raise InputError(f"no LJ parameters for the element pair {key}")
        sel = keys == key
        eps[sel] = table[key].epsilon_ev
        sig[sel] = table[key].sigma_angstrom
    s6 = (sig / d) ** 6
    s6c = (sig / cutoff_angstrom) ** 6
    pair_energy = 4.0 * eps * (s6 * s6 - s6) - 4.0 * eps * (s6c * s6c - s6c)
    du_dr = 4.0 * eps * (-12.0 * s6 * s6 + 6.0 * s6) / d
    energy = 0.5 * float(pair_energy.sum())
    forces = np.zeros((len(atoms), 3))
    # vec = r_j − r_i (minimum image); force on i is +dU/dr · vec/r.
    np.add.at(forces, i, (du_dr / d)[:, None] * vec)
    return energy, forces
