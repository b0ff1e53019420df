"""flatcontact.potentials: one interaction model behind every stage.

- :class:`InteractionModel` (alias :class:`PotentialSpec`): the run configuration's
  ``potential:`` section — LAMMPS pair styles as data (:class:`LammpsStyle`) with a coupling
  across the interface (``lj`` | ``same`` | ``interlayer`` | ``none``), named presets
  (:data:`PRESETS`), or an ASE calculator ``module:callable`` (:class:`AseCalculatorSpec`).
- :class:`LJSpec`: the cross-interface Lennard-Jones from Tkatchenko–Scheffler C6.
- :func:`make_calculator`: the ASE calculator of a model for given atoms; the scan's
  picklable factory and the bulk calculator are beside it in :mod:`flatcontact.potentials.engines`.
- :func:`parse_kwargs`: CLI ``key=value`` keyword arguments of an ASE calculator.
"""

from flatcontact.potentials.coupling import LJSpec
from flatcontact.potentials.engines import make_calculator
from flatcontact.potentials.loader import call_factory, load_callable, parse_kwargs
from flatcontact.potentials.model import InteractionModel
from flatcontact.potentials.presets import PRESETS
from flatcontact.potentials.styles import AseCalculatorSpec, LammpsStyle

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
    "load_callable",
    "make_calculator",
    "parse_kwargs",
]
