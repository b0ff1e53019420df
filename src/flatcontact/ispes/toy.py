"""The toy pair model as a scan calculator factory (``flatcontact.ispes.toy:toy_calculator``).

The toy interface and its pair model (:class:`~flatcontact.structures.toy.ToyPairCalculator`)
live in :mod:`flatcontact.structures.toy`; this module is the target the scan's
``calculator.target`` names for it, so a scan on the toy needs no interatomic potential file.
"""

from __future__ import annotations

from ase import Atoms

from flatcontact.structures.toy import ToyPairCalculator


def toy_calculator(atoms: Atoms | None = None, **params: float) -> ToyPairCalculator:
    """Factory for :class:`ToyPairCalculator` (the ``atoms`` argument is ignored)."""
    return ToyPairCalculator(**params)
