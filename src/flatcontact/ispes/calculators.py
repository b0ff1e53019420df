"""Picklable calculator factories for scan workers, and force-call counting.

A scan worker builds its calculator once from a factory and reuses it for every
grid point it relaxes. A factory is a small frozen object that pickles to any
worker process (local pool or Dask) and has a JSON ``fingerprint`` that the point
store records, so a store is never mixed across interaction models.

The factory of every interaction model is ``calculator_factory(model)``
(:class:`flatcontact.potentials.engines.ModelFactory`). Earlier names kept here:

- :class:`PotentialFactory`: ``PotentialFactory.from_spec(model)``, the same factory;
- :class:`CalculatorFactory`: a whole-interface ASE calculator ``"module:callable"`` plus
  JSON keyword arguments (the model ``{calculator: {target, kwargs}}``).
"""

from __future__ import annotations

import dataclasses
import json
from typing import Any

from ase import Atoms
from ase.calculators.calculator import Calculator

from flatcontact.potentials.engines import ModelFactory, calculator_factory
from flatcontact.potentials.loader import call_factory, load_callable
from flatcontact.potentials.model import InteractionModel


@dataclasses.dataclass(frozen=True)
class CalculatorFactory:
    """Build ``callable(**kwargs)`` from ``target = "module:callable"`` (a whole-interface model).

    Kept for callers of the earlier API; the same as the factory of
    ``InteractionModel(calculator={"target": target, "kwargs": kwargs})`` (one loader:
    :func:`flatcontact.potentials.loader.call_factory`).
    """

    target: str
    kwargs_json: str = "{}"

    @classmethod
    def from_target(cls, target: str, **kwargs: Any) -> CalculatorFactory:
        factory = cls(target, json.dumps(kwargs, sort_keys=True))
        factory.resolve()  # fail now, not in a worker
        return factory

    def resolve(self):
        return load_callable(self.target, "calculator")

    def __call__(self, atoms: Atoms) -> Calculator:
        return call_factory(self.target, atoms, json.loads(self.kwargs_json))

    def model(self):
        """The equivalent :class:`~flatcontact.potentials.model.InteractionModel`."""
        return InteractionModel(
            calculator={"target": self.target, "kwargs": json.loads(self.kwargs_json)}
        )

    @property
    def fingerprint(self) -> str:
        return calculator_factory(self.model()).fingerprint

    @property
    def label(self) -> str:
        return f"{self.target} {self.kwargs_json}"


class PotentialFactory(ModelFactory):
    """The factory of an interaction model (earlier name of :class:`ModelFactory`)."""

    @classmethod
    def from_spec(cls, spec: Any) -> PotentialFactory:
        return cls(spec.model_dump_json())


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
