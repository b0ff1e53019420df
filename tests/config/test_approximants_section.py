"""The ``approximants`` section: defaults, bounds and one-line refusals naming the field."""

import pytest

from flatcontact.config.approximants import (
    DEFAULT_STRAIN_LADDER_PERCENT,
    ApproximantSettings,
    parse_approximants,
)
from flatcontact.foundation.errors import InputError


def test_defaults():
    s = parse_approximants(None)
    assert s == ApproximantSettings()
    assert (s.twist_deg, s.max_atoms, s.max_cells, s.strain_percent, s.strain_on) == (
        None,
        2000,
        6,
        None,
        "slab2",
    )
    assert list(DEFAULT_STRAIN_LADDER_PERCENT) == sorted(DEFAULT_STRAIN_LADDER_PERCENT)[::-1]


@pytest.mark.parametrize(
    ("data", "field"),
    [
        ({"twist_deg": 75.0}, "twist_deg"),
        ({"twist_deg": float("nan")}, "twist_deg"),
        ({"max_atoms": 1}, "max_atoms"),
        ({"max_cells": 0}, "max_cells"),
        ({"strain_percent": []}, "strain_percent"),
        ({"strain_percent": [1.0, 3.0]}, "strain_percent"),
        ({"strain_percent": [1.0, 1.0]}, "strain_percent"),
        ({"strain_percent": [30.0]}, "strain_percent"),
        ({"strain_on": "slab1"}, "strain_on"),
        ({"angle_tolerance_deg": 0.0}, "angle_tolerance_deg"),
        ({"twist_deg": -1.0}, "twist_deg"),
        ({"twist": 1.1}, "twist"),
    ],
)
def test_bad_values_are_refused_in_one_line_naming_the_field(data, field):
    with pytest.raises(InputError) as err:
        parse_approximants(data)
    text = str(err.value)
    assert "\n" not in text and text.startswith(f"approximants: {field}")
