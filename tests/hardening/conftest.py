"""Fixtures shared by the hardening tests."""

import pytest
from tests.hardening.helpers import finished_toy_run


@pytest.fixture(scope="session")
def finished_toy(tmp_path_factory):
    """(config folder, run directory) of one finished toy study, built once per test process
    (each pytest-xdist worker has its own ``tmp_path_factory``). Tests change copies of it; a
    rerun on it must skip every stage."""
    return finished_toy_run(tmp_path_factory.mktemp("finished_toy"))
