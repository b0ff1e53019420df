"""flatcontact.potentials: one interaction model behind every stage.

- :class:`InteractionModel` (alias :class:`PotentialSpec`): the run configuration's
  ``potential:`` section — LAMMPS pair styles as data (:class:`LammpsStyle`) with a coupling
  across the interface (``lj`` | ``same`` | ``interlayer`` | ``none``), named presets
  (:data:`PRESETS`), or an ASE calculator ``module:callable`` (:class:`AseCalculatorSpec`).
- :class:`LJSpec`: the cross-interface Lennard-Jones from Tkatchenko–Scheffler C6.
- :func:`make_calculator`, :func:`check_elements`: earlier entry points, now
  ``model.calculator(atoms)`` and ``model.check_atoms(atoms)``.
- :func:`parse_kwargs`: CLI ``key=value`` keyword arguments of an ASE calculator.
"""

from flatcontact.potentials.calculator import check_elements, make_calculator
from flatcontact.potentials.loader import call_factory, load_callable, parse_kwargs
from flatcontact.potentials.model import (
    AseCalculatorSpec,
    InteractionModel,
    LammpsStyle,
    LJSpec,
)
from flatcontact.potentials.presets import PRESETS

#: The earlier name of :class:`InteractionModel`.
PotentialSpec = InteractionModel

__all__ = [
    "PRESETS",
    "AseCalculatorSpec",
    "InteractionModel",
    "LJSpec",
    "LammpsStyle",
    "PotentialSpec",
    "call_factory",
    "check_elements",
    "load_callable",
    "make_calculator",
    "parse_kwargs",
]
