"""Force-call counting for scan workers, and the dated aliases of the old factory names.

A scan worker builds its calculator once from a factory and reuses it for every grid point
it relaxes; the factory of every interaction model is
:func:`flatcontact.potentials.engines.calculator_factory` (a picklable
:class:`~flatcontact.potentials.engines.ModelFactory` with a JSON ``fingerprint`` that the
point store records). :func:`count_force_calls` makes any ASE calculator count its
evaluations.

Deprecated since 2026-11-25 (each call raises a :class:`DeprecationWarning`):

- ``PotentialFactory.from_spec(model)``: use ``calculator_factory(model)``;
- ``CalculatorFactory.from_target(target, **kwargs)``: use
  ``calculator_factory(InteractionModel(calculator={"target": target, "kwargs": kwargs}))``.
"""

from __future__ import annotations

import warnings
from typing import Any

from ase.calculators.calculator import Calculator

from flatcontact.potentials.engines import ModelFactory, calculator_factory
from flatcontact.potentials.loader import load_callable
from flatcontact.potentials.model import InteractionModel

#: The date the old factory names were deprecated.
FACTORY_NAMES_DEPRECATED = "2026-11-25"


def _deprecated(old: str, new: str) -> None:
    warnings.warn(
        f"{old} is deprecated since {FACTORY_NAMES_DEPRECATED}: use {new}",
        DeprecationWarning,
        stacklevel=3,
    )


class PotentialFactory:
    """Deprecated since 2026-11-25: use
    :func:`~flatcontact.potentials.engines.calculator_factory` of the model."""

    @staticmethod
    def from_spec(spec: InteractionModel) -> ModelFactory:
        """``calculator_factory(spec)``, with a :class:`DeprecationWarning`."""
        _deprecated("PotentialFactory.from_spec(model)", "calculator_factory(model)")
        return calculator_factory(spec)


class CalculatorFactory:
    """Deprecated since 2026-11-25: use
    :func:`~flatcontact.potentials.engines.calculator_factory` of
    ``InteractionModel(calculator={"target": target, "kwargs": kwargs})``."""

    @staticmethod
    def from_target(target: str, **kwargs: Any) -> ModelFactory:
        """The factory of the whole-interface calculator ``target(**kwargs)``, with a warning."""
        _deprecated(
            "CalculatorFactory.from_target(target, **kwargs)",
            'calculator_factory(InteractionModel(calculator={"target": target, "kwargs": kwargs}))',
        )
        load_callable(target, "calculator")  # fail now, not in a worker
        return calculator_factory(InteractionModel(calculator={"target": target, "kwargs": kwargs}))


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
