"""Fixtures for the ISPES scan tests: the toy two-slab LJ interface (fast)."""

import pytest

from flatcontact.potentials.engines import calculator_factory
from flatcontact.potentials.model import InteractionModel
from flatcontact.structures.toy import toy_interface


@pytest.fixture(scope="session")
def toy_reference():
    return toy_interface(layers=3)


@pytest.fixture(scope="session")
def toy_factory():
    return calculator_factory(
        InteractionModel(calculator={"target": "flatcontact.ispes.toy:toy_calculator"})
    )
