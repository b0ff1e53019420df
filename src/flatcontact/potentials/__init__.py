"""flatcontact.potentials: interaction models behind one interface.

- :class:`PotentialSpec`, :class:`LJSpec`: what to use (intra-slab model, cross-interface LJ).
- :func:`make_calculator`: an ASE calculator for an interface (LAMMPS or ASE-calculator engine).
- :func:`check_elements`: element compatibility of a spec and a structure.
"""

from flatcontact.potentials.calculator import check_elements, make_calculator
from flatcontact.potentials.spec import LJSpec, PotentialSpec

__all__ = ["LJSpec", "PotentialSpec", "check_elements", "make_calculator"]
