"""flatcontact.potentials: one interaction model behind every stage.

- :class:`InteractionModel`: the run configuration's ``potential:`` section — LAMMPS pair
  styles as data (:class:`LammpsStyle`) with a coupling across the interface (``lj`` |
  ``same`` | ``interlayer`` | ``none``), named presets (:data:`PRESETS`), or an ASE calculator
  ``module:callable`` (:class:`AseCalculatorSpec`). The model is data; its engines are built
  by :mod:`.engines`.
- :class:`LJSpec`: the cross-interface Lennard-Jones from Tkatchenko–Scheffler C6.
- :func:`make_calculator` (the ASE calculator of a model for given atoms),
  :func:`calculator_factory` (the scan's picklable factory), :func:`bulk_calculator` (a bulk
  cell's calculator, from a model or a name, teachers included).
- :func:`parse_kwargs`: CLI ``key=value`` keyword arguments of an ASE calculator.

Names load on first use (:mod:`lazy_loader`); code inside flatcontact imports them from the
module that defines them.
"""

import lazy_loader

__getattr__, __dir__, __all__ = lazy_loader.attach(
    __name__,
    submod_attrs={
        "coupling": ["LJSpec"],
        "engines": ["bulk_calculator", "calculator_factory", "make_calculator"],
        "loader": ["call_factory", "load_callable", "parse_kwargs"],
        "model": ["InteractionModel"],
        "presets": ["PRESETS"],
        "styles": ["AseCalculatorSpec", "LammpsStyle"],
    },
)
