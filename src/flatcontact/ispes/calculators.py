"""Force-call counting for scan workers.

A scan worker builds its calculator once from a factory and reuses it for every grid point
it relaxes; the factory of every interaction model is
:func:`flatcontact.potentials.engines.calculator_factory` (a picklable
:class:`~flatcontact.potentials.engines.ModelFactory` with a JSON ``fingerprint`` that the
point store records). :func:`count_force_calls` makes any ASE calculator count its
evaluations.
"""

from __future__ import annotations

from ase.calculators.calculator import Calculator


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
