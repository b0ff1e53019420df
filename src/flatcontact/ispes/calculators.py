"""Picklable calculator factories for scan workers, and force-call counting.

A scan worker builds its calculator once from a factory and reuses it for every
grid point it relaxes. A factory is a small frozen object that pickles to any
worker process (local pool or Dask) and has a JSON ``fingerprint`` that the point
store records, so a store is never mixed across interaction models.

Two kinds:

- :class:`PotentialFactory`: a :class:`flatcontact.potentials.PotentialSpec`
  (LAMMPS SNAP / classical per slab + cross-interface LJ, or an ASE model per slab),
  built with :func:`flatcontact.potentials.make_calculator`.
- :class:`CalculatorFactory`: any ASE calculator given as ``"module:callable"``
  plus JSON keyword arguments; ``callable(atoms, **kwargs)`` returns the calculator.
"""

from __future__ import annotations

import dataclasses
import importlib
import json
from typing import Any

from ase import Atoms
from ase.calculators.calculator import Calculator

from flatcontact.errors import InputError


@dataclasses.dataclass(frozen=True)
class CalculatorFactory:
    """Build ``callable(atoms, **kwargs)`` from ``target = "module:callable"``."""

    target: str
    kwargs_json: str = "{}"

    @classmethod
    def from_target(cls, target: str, **kwargs: Any) -> CalculatorFactory:
        factory = cls(target, json.dumps(kwargs, sort_keys=True))
        factory.resolve()  # fail now, not in a worker
        return factory

    def resolve(self):
        module_name, _, attr = self.target.partition(":")
        if not module_name or not attr:
            raise InputError(
                f"calculator '{self.target}': expected 'module:callable' returning an ASE calculator"
            )
        try:
            obj = importlib.import_module(module_name)
        except ImportError as exc:
            raise InputError(
                f"calculator '{self.target}': cannot import {module_name} ({exc})"
            ) from None
        for part in attr.split("."):
            if not hasattr(obj, part):
                raise InputError(f"calculator '{self.target}': {module_name} has no '{attr}'")
            obj = getattr(obj, part)
        if not callable(obj):
            raise InputError(f"calculator '{self.target}': '{attr}' is not callable")
        return obj

    def __call__(self, atoms: Atoms) -> Calculator:
        return self.resolve()(atoms, **json.loads(self.kwargs_json))

    @property
    def fingerprint(self) -> str:
        return json.dumps(
            {"calculator": self.target, "kwargs": json.loads(self.kwargs_json)}, sort_keys=True
        )

    @property
    def label(self) -> str:
        return f"{self.target} {self.kwargs_json}"


@dataclasses.dataclass(frozen=True)
class PotentialFactory:
    """Build :func:`flatcontact.potentials.make_calculator` from a spec's JSON form."""

    spec_json: str

    @classmethod
    def from_spec(cls, spec: Any) -> PotentialFactory:
        return cls(spec.model_dump_json())

    def spec(self):
        from flatcontact.potentials import PotentialSpec

        return PotentialSpec.model_validate_json(self.spec_json)

    def __call__(self, atoms: Atoms) -> Calculator:
        from flatcontact.potentials import make_calculator

        return make_calculator(self.spec(), atoms)

    @property
    def fingerprint(self) -> str:
        return json.dumps({"potential": json.loads(self.spec_json)}, sort_keys=True)

    @property
    def label(self) -> str:
        spec = self.spec()
        return str(getattr(spec, "label", self.spec_json))


def count_force_calls(calc: Calculator) -> Calculator:
    """Make ``calc.force_calls`` count evaluations, if the calculator does not already.

    Calculators of :mod:`flatcontact.potentials` count themselves. For any other ASE
    calculator the instance's ``calculate`` is wrapped (ASE calls it exactly once
    per evaluation of new positions; cached results do not count).
    """
    if hasattr(calc, "force_calls"):
        return calc
    calc.force_calls = 0
    inner = calc.calculate

    def calculate(*args, **kwargs):
        calc.force_calls += 1
        return inner(*args, **kwargs)

    calc.calculate = calculate
    return calc
