"""The LAMMPS engine: one in-process LAMMPS instance per calculator, positions updated in place.

The engine runs what a :class:`LammpsSetup` says — atom types, molecule ids, the pair
commands — in a box made by the one box builder (:func:`flatcontact.potentials.lammps_box.create_box`).
The setup is compiled from an :class:`~flatcontact.potentials.model.InteractionModel` by
:func:`flatcontact.potentials.model.InteractionModel.lammps_setup`; the engine itself knows
no potential.

Forces come back in the caller's frame; the energy is the total potential energy (eV); for
a 3D-periodic cell the stress too (ASE convention, eV/Å³).
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass

import numpy as np

from flatcontact.errors import InputError
from flatcontact.potentials.lammps_box import create_box
from flatcontact.potentials.lammps_runtime import new_lammps


@dataclass(frozen=True)
class LammpsSetup:
    """What LAMMPS needs for one structure: types, molecule ids and the pair commands.

    Attributes
    ----------
    types
        LAMMPS type (1-based) per atom, in the atoms' order.
    type_elements
        Element of each type (type ``t`` is ``type_elements[t - 1]``).
    commands
        ``pair_style``/``pair_coeff``/``pair_modify`` commands, files as absolute paths.
    atom_style
        ``atomic``, or ``full`` when ``molecules`` are needed (interlayer potentials).
    molecules
        Molecule id per atom (``atom_style full``), else ``None``.
    charges
        Charge per atom (e; ``atom_style full``), else ``None``.
    """

    types: tuple[int, ...]
    type_elements: tuple[str, ...]
    commands: tuple[str, ...]
    atom_style: str = "atomic"
    molecules: tuple[int, ...] | None = None
    charges: tuple[float, ...] | None = None


class LammpsEngine:
    """Energy and forces (and the stress of a periodic cell) of a :class:`LammpsSetup`.

    Parameters
    ----------
    setup
        The types, molecule ids and pair commands.
    cell, pbc
        ASE cell (3×3) and pbc (see :class:`flatcontact.potentials.lammps_box.LammpsBox`).
    label
        The model's name, for error messages.
    """

    def __init__(self, setup: LammpsSetup, cell, pbc, label: str = "LAMMPS model"):
        self.setup = setup
        self.n = len(setup.types)
        self.lmp = new_lammps()
        try:
            self.box = create_box(
                self.lmp,
                cell,
                pbc,
                setup.types,
                setup.type_elements,
                atom_style=setup.atom_style,
                molecules=setup.molecules,
                charges=setup.charges,
            )
            self.lmp.commands_list(list(setup.commands))
            # pressures only for periodic cells (the virial costs time in every run)
            thermo = "pe pxx pyy pzz pyz pxz pxy" if self.box.bulk else "pe"
            self.lmp.commands_list(
                [
                    "neighbor 1.0 bin",
                    "neigh_modify every 1 delay 0 check yes",
                    f"thermo_style custom {thermo}",
                    "thermo_modify norm no",
                ]
            )
        except Exception as exc:
            self.close()
            if isinstance(exc, InputError):
                raise
            raise InputError(f"LAMMPS could not set up the potential {label}: {exc}") from None
        self._xbuf = (ctypes.c_double * (3 * self.n))()

    def compute(self, positions: np.ndarray, stress: bool = False):
        """Energy (eV) and forces (eV/Å, caller's frame) at ``positions`` (Å).

        With ``stress=True`` (3D-periodic cells only) also the stress (eV/Å³, ASE Voigt order
        and sign): ``(energy, forces, stress)``.
        """
        box = self.box.to_lammps(positions)
        self._xbuf[:] = box.ravel().tolist()
        self.lmp.scatter_atoms("x", 1, 3, self._xbuf)
        self.lmp.command("run 0 post no")
        energy = float(self.lmp.get_thermo("pe"))
        f = np.ctypeslib.as_array(self.lmp.gather_atoms("f", 1, 3), shape=(3 * self.n,)).reshape(
            self.n, 3
        )
        forces = self.box.vectors_to_caller(f)
        if not stress:
            return energy, forces
        p = [self.lmp.get_thermo(k) for k in ("pxx", "pyy", "pzz", "pyz", "pxz", "pxy")]
        return energy, forces, self.box.stress_to_caller(p)

    def close(self) -> None:
        lmp = getattr(self, "lmp", None)
        if lmp is not None:
            try:
                lmp.close()
            finally:
                self.lmp = None

    def __del__(self):  # pragma: no cover - best effort
        try:
            self.close()
        except Exception:
            pass
