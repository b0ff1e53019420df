"""Single-body LAMMPS evaluations (bulk crystals, free slabs) for training and validation.

The interface engine of :mod:`flatcontact.potentials` handles two slabs with
cross-interface LJ; this module is the small single-body counterpart that the
training pipeline needs: set up a periodic (triclinic) box from ASE ``Atoms``,
run ``pair_style snap`` / ``vashishta`` (or ``zero`` for descriptors) and map
energies, forces and stresses back to ASE's frame and conventions.

Conventions: energies in eV, forces in eV/Å, stress in eV/Å³ with ASE's sign
(positive = tensile, i.e. minus the pressure tensor), Voigt order
(xx, yy, zz, yz, xz, xy).
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np
from ase import Atoms
from ase.calculators.calculator import Calculator, all_changes
from ase.calculators.lammps import Prism
from ase.data import atomic_masses, atomic_numbers

from flatcontact.errors import InputError
from flatcontact.potentials.lammps_runtime import lammps_potential_file, new_lammps

#: Voigt pairs in ASE order (xx, yy, zz, yz, xz, xy).
VOIGT_PAIRS = ((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))


def voigt_to_tensor(v: np.ndarray) -> np.ndarray:
    """Voigt 6-vector(s) ``(..., 6)`` (xx, yy, zz, yz, xz, xy) -> symmetric tensors ``(..., 3, 3)``."""
    v = np.asarray(v, dtype=float)
    t = np.empty((*v.shape[:-1], 3, 3))
    for k, (i, j) in enumerate(VOIGT_PAIRS):
        t[..., i, j] = v[..., k]
        t[..., j, i] = v[..., k]
    return t


def tensor_to_voigt(t: np.ndarray) -> np.ndarray:
    """Symmetric tensors ``(..., 3, 3)`` -> Voigt 6-vectors ``(..., 6)`` (xx, yy, zz, yz, xz, xy)."""
    t = np.asarray(t, dtype=float)
    return np.stack([t[..., i, j] for i, j in VOIGT_PAIRS], axis=-1)


def setup_box(lmp, atoms: Atoms, elements: Sequence[str]) -> Prism:
    """Create a periodic triclinic box with ``atoms`` in the (empty) LAMMPS instance ``lmp``.

    Atom type ``k + 1`` is ``elements[k]``; atom ids follow the order of ``atoms``
    and LAMMPS never sorts them, so per-atom rows map one-to-one onto ``atoms``.
    Returns the :class:`ase.calculators.lammps.Prism` that rotates between frames.
    """
    symbols = atoms.get_chemical_symbols()
    unknown = sorted(set(symbols) - set(elements))
    if unknown:
        raise InputError(
            f"elements {unknown} are not among the potential's elements {list(elements)}"
        )
    prism = Prism(np.asarray(atoms.cell))
    xhi, yhi, zhi, xy, xz, yz = (float(v) for v in prism.get_lammps_prism())
    lines = [
        "units metal",
        "atom_style atomic",
        "atom_modify map array sort 0 0",
        "boundary p p p",
        f"region box prism 0 {xhi!r} 0 {yhi!r} 0 {zhi!r} {xy!r} {xz!r} {yz!r} units box",
        f"create_box {len(elements)} box",
    ]
    lines += [
        f"mass {k + 1} {float(atomic_masses[atomic_numbers[el]])!r}"
        for k, el in enumerate(elements)
    ]
    lmp.commands_string("\n".join(lines))
    types = [elements.index(s) + 1 for s in symbols]
    pos = prism.vector_to_lammps(atoms.positions, wrap=True)
    lmp.create_atoms(len(atoms), list(range(1, len(atoms) + 1)), types, pos.ravel().tolist())
    return prism


def snap_pair_commands(coeff_file: Path, param_file: Path, elements: Sequence[str]) -> list[str]:
    """``pair_style snap`` commands for a coefficient/parameter file pair."""
    return [
        "pair_style snap",
        f"pair_coeff * * {coeff_file} {param_file} {' '.join(elements)}",
    ]


def vashishta_pair_commands(elements: Sequence[str] = ("Si", "O")) -> list[str]:
    """Vashishta et al. (1990) SiO2 potential as shipped with LAMMPS (``SiO.1990.vashishta``)."""
    path = lammps_potential_file("SiO.1990.vashishta")
    return ["pair_style vashishta", f"pair_coeff * * {path} {' '.join(elements)}"]


def tersoff_pair_commands(elements: Sequence[str] = ("Si", "O")) -> list[str]:
    """Tersoff SiO potential (Munetoh et al. 2007) as shipped with LAMMPS (``SiO.tersoff``)."""
    path = lammps_potential_file("SiO.tersoff")
    return ["pair_style tersoff", f"pair_coeff * * {path} {' '.join(elements)}"]


class LammpsBulkCalculator(Calculator):
    """ASE calculator for one periodic body with a LAMMPS pair style.

    Parameters
    ----------
    pair_commands
        LAMMPS commands defining the interaction (``pair_style``/``pair_coeff``),
        e.g. :func:`snap_pair_commands` or :func:`vashishta_pair_commands`.
    elements
        Element of each LAMMPS atom type, in type order.

    Notes
    -----
    Each calculation rebuilds the box (bulk cells are small, so this is cheap and
    robust against cell changes). ``force_calls`` counts evaluations.
    """

    implemented_properties = ("energy", "free_energy", "forces", "stress")

    def __init__(self, pair_commands: Sequence[str], elements: Sequence[str], **kwargs):
        super().__init__(**kwargs)
        self.pair_commands = list(pair_commands)
        self.elements = list(elements)
        self.force_calls = 0
        self._lmp = new_lammps()

    def calculate(self, atoms=None, properties=("energy",), system_changes=all_changes):
        super().calculate(atoms, properties, system_changes)
        lmp = self._lmp
        lmp.command("clear")
        prism = setup_box(lmp, self.atoms, self.elements)
        lmp.commands_string("\n".join(self.pair_commands))
        lmp.commands_string(
            "thermo_style custom step pe pxx pyy pzz pyz pxz pxy\nthermo_modify norm no\nrun 0"
        )
        energy = float(lmp.get_thermo("pe"))
        forces = np.array(lmp.numpy.extract_atom("f")[: len(self.atoms)], dtype=float)
        # LAMMPS metal pressure is in bar; ASE stress = -pressure, eV/Å^3.
        from ase.units import bar

        p_voigt = np.array([lmp.get_thermo(k) for k in ("pxx", "pyy", "pzz", "pyz", "pxz", "pxy")])
        stress = -prism.tensor2_to_ase(voigt_to_tensor(p_voigt)) * bar
        self.results = {
            "energy": energy,
            "free_energy": energy,
            "forces": prism.vector_to_ase(forces),
            "stress": tensor_to_voigt(stress),
        }
        self.force_calls += 1


def snap_calculator(coeff_file: str | Path, param_file: str | Path | None = None):
    """A :class:`LammpsBulkCalculator` for a SNAP ``.snapcoeff`` (``.snapparam`` beside it)."""
    from flatcontact.training.snapfiles import read_snapcoeff

    coeff_file = Path(coeff_file)
    param_file = Path(param_file) if param_file else coeff_file.with_suffix(".snapparam")
    for path in (coeff_file, param_file):
        if not path.is_file():
            raise InputError(f"{path}: SNAP file not found")
    elements = list(read_snapcoeff(coeff_file).elements)
    return LammpsBulkCalculator(snap_pair_commands(coeff_file, param_file, elements), elements)


def vashishta_calculator() -> LammpsBulkCalculator:
    """A :class:`LammpsBulkCalculator` with the Vashishta (1990) SiO2 potential."""
    return LammpsBulkCalculator(vashishta_pair_commands(), ["Si", "O"])
