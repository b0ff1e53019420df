"""The dated aliases of the old factory names give the factory of the same model, with a warning."""

import pytest

from flatcontact.ispes.calculators import CalculatorFactory, PotentialFactory
from flatcontact.potentials.engines import calculator_factory
from flatcontact.potentials.model import InteractionModel

TOY = "flatcontact.ispes.toy:toy_calculator"


def test_potential_factory_is_calculator_factory():
    model = InteractionModel(intra="vashishta")
    with pytest.warns(DeprecationWarning, match="since 2026-11-25: use calculator_factory"):
        old = PotentialFactory.from_spec(model)
    assert old == calculator_factory(model)


def test_calculator_factory_is_the_factory_of_a_calculator_model(toy_reference):
    with pytest.warns(DeprecationWarning, match="since 2026-11-25"):
        old = CalculatorFactory.from_target(TOY, eps_cross_ev=0.05)
    new = calculator_factory(
        InteractionModel(calculator={"target": TOY, "kwargs": {"eps_cross_ev": 0.05}})
    )
    assert old.fingerprint == new.fingerprint
    assert old(toy_reference).parameters["eps_cross_ev"] == 0.05
