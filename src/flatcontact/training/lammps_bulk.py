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

from flatcontact.foundation.errors import InputError
from flatcontact.potentials.engines import bulk_calculator
from flatcontact.potentials.lammps_box import (  # noqa: F401 - re-exported for training modules
    VOIGT_PAIRS,
    LammpsBox,
    create_box,
    tensor_to_voigt,
    voigt_to_tensor,
)
from flatcontact.potentials.lammps_runtime import lammps_potential_file, new_lammps
from flatcontact.potentials.model import InteractionModel
from flatcontact.potentials.styles import LammpsStyle


def setup_box(lmp, atoms: Atoms, elements: Sequence[str]) -> Prism:
    """Create a periodic triclinic box with ``atoms`` in the (empty) LAMMPS instance ``lmp``.

    Atom type ``k + 1`` is ``elements[k]``; atom ids follow the order of ``atoms``. Built by
    the one box builder (:func:`flatcontact.potentials.lammps_box.create_box`). Returns the
    :class:`ase.calculators.lammps.Prism` that rotates between frames.
    """
    symbols = atoms.get_chemical_symbols()
    unknown = sorted(set(symbols) - set(elements))
    if unknown:
        raise InputError(
            f"elements {unknown} are not among the potential's elements {list(elements)}"
        )
    types = [list(elements).index(s) + 1 for s in symbols]
    box = create_box(
        lmp, atoms.cell.array, (True, True, True), types, list(elements), positions=atoms.positions
    )
    return box.prism


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


class LammpsBulkCalculator(Calculator):
    """ASE calculator for one periodic body with raw LAMMPS pair commands.

    Parameters
    ----------
    pair_commands
        LAMMPS commands defining the interaction (``pair_style``/``pair_coeff``),
        e.g. :func:`snap_pair_commands` or :func:`vashishta_pair_commands`.
    elements
        Element of each LAMMPS atom type, in type order.

    Notes
    -----
    For hand-written pair commands; a potential of :mod:`flatcontact.potentials` gives its
    bulk calculator through :func:`flatcontact.potentials.engines.bulk_calculator`. Each calculation rebuilds
    the box (bulk cells are small). ``force_calls`` counts evaluations.
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
        setup_box(lmp, self.atoms, self.elements)
        box = LammpsBox(self.atoms.cell.array, (True, True, True))
        lmp.commands_string("\n".join(self.pair_commands))
        lmp.commands_string(
            "thermo_style custom step pe pxx pyy pzz pyz pxz pxy\nthermo_modify norm no\nrun 0"
        )
        energy = float(lmp.get_thermo("pe"))
        forces = np.array(lmp.numpy.extract_atom("f")[: len(self.atoms)], dtype=float)
        p_voigt = [lmp.get_thermo(k) for k in ("pxx", "pyy", "pzz", "pyz", "pxz", "pxy")]
        self.results = {
            "energy": energy,
            "free_energy": energy,
            "forces": box.vectors_to_caller(forces),
            "stress": box.stress_to_caller(p_voigt),
        }
        self.force_calls += 1


def snap_calculator(coeff_file: str | Path, param_file: str | Path | None = None):
    """The bulk calculator of a SNAP ``.snapcoeff`` (``.snapparam`` beside it, or given)."""
    coeff_file = Path(coeff_file)
    param_file = Path(param_file) if param_file else coeff_file.with_suffix(".snapparam")
    for path in (coeff_file, param_file):
        if not path.is_file():
            raise InputError(f"{path}: SNAP file not found")
    style = LammpsStyle(pair_style="snap", pair_coeff=(str(coeff_file), str(param_file)))
    return bulk_calculator(InteractionModel(intra=(style,), coupling="none"), None)


def vashishta_calculator():
    """The bulk calculator of the Vashishta (1990) SiO2 potential."""
    return bulk_calculator(InteractionModel(intra="vashishta", coupling="none"), None)
