"""units.py: the unit constants against their definitions."""

import pytest

from flatcontact.foundation import units


def test_unit_constants_against_definitions():
    # 1 eV/Å^3 = 1.602176634e-19 J / 1e-30 m^3 = 160.2176634 GPa
    assert units.EV_PER_A3_TO_GPA == pytest.approx(160.2176634, rel=1e-9)
    assert units.EV_PER_A2_TO_J_PER_M2 == pytest.approx(16.02176634, rel=1e-9)
    assert units.EV_PER_A3_TO_MPA == pytest.approx(1e3 * units.EV_PER_A3_TO_GPA)


def test_electron_volt_is_scipys_si_value_bit_for_bit():
    """units.py writes the SI 2019 electron volt out (no scipy import at start-up); it must be
    scipy.constants' value exactly, so every stress and energy conversion is unchanged."""
    import scipy.constants

    assert units.EV_TO_J == scipy.constants.electron_volt
    assert units.EV_PER_A3_TO_GPA == scipy.constants.electron_volt * 1.0e30 / 1.0e9
    assert units.EV_PER_A2_TO_J_PER_M2 == scipy.constants.electron_volt * 1.0e20
