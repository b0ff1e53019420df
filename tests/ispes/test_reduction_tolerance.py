"""The symmetry verification's energy tolerance is relative to the landscape it verifies.

``tol(z) = max(F(z), min(energy_tolerance_mev_per_a2, fraction · R(z)))`` with R the energy
range of the computed points at the verified point's thickness and F their round-off
(:func:`flatcontact.ispes.reduction.energy_tolerances`). Constructed records whose numbers are
the measured ones of the cases the rule is for: the relaxed (1, 2) twisted graphene cell
(`normal`, fmax 0.005 eV/Å: verified 3.1e-4 meV/Å² on a range of 2.1e-2), a twist cell whose
verified point breaks the symmetry by a quarter of its corrugation (below the absolute 0.01),
a landscape of Cu(111)'s size, and a rigid cell at its round-off (the (3, 4) twist: range
8e-9 meV/Å² on |E|/area 5.6 eV/Å²). The relaxed (2, 3) cell through a real scan: the slow test
at the end.
"""

from __future__ import annotations

import numpy as np
import pytest

from flatcontact.config.scan import SymmetryConfig
from flatcontact.ispes.reduction import (
    ENERGY_RANGE_FRACTION,
    ROUND_OFF_RELATIVE,
    Reduction,
    SymmetrySettings,
    energy_tolerances,
    fallback_reason,
    symmetry_broken,
    verification,
)
from flatcontact.ispes.shift_symmetry import ShiftGroup, ShiftOperation

AREA = 36.7  # Å², the (1, 2) twist cell
E0_EV_PER_A2 = -5.6  # |E|/area of REBO + KC graphene cells (eV/Å²)


def _records(values_mev_per_a2: dict) -> dict:
    """Store records from energies per area (meV/Å², added to E0): index -> record."""
    return {
        idx: {"energy_ev": (E0_EV_PER_A2 + v * 1e-3) * AREA, "normal_stress_gpa": 1.0}
        for idx, v in values_mev_per_a2.items()
    }


def _reduction(verified: tuple, representative: tuple) -> Reduction:
    identity = ShiftOperation(((1, 0), (0, 1)), (0.0, 0.0), False)
    group = ShiftGroup((identity,), 1e-3, (6.5, 6.5))
    return Reduction(group, {verified: representative, representative: representative}, (verified,))


def _case(range_mev: float, difference_mev: float) -> tuple[Reduction, dict]:
    """A thickness with a landscape of range ``range_mev`` (min 0 at (0, 0)) whose verified
    point (2, 2) differs from its representative (1, 1) by ``difference_mev``; another
    thickness far rougher, which must not set this one's tolerance."""
    rep_value = 0.5 * range_mev
    values = {
        (0, 0, 0): 0.0,
        (0, 1, 0): range_mev,
        (1, 1, 0): rep_value,
        (2, 2, 0): rep_value + difference_mev,
        (0, 0, 1): 0.0,
        (0, 1, 1): 100.0,
    }
    return _reduction((2, 2, 0), (1, 1, 0)), _records(values)


def test_the_config_default_is_the_rule_s_fraction():
    assert SymmetryConfig().energy_tolerance_fraction == ENERGY_RANGE_FRACTION == 0.05


def test_the_tolerance_per_thickness_is_the_stated_rule():
    settings = SymmetrySettings()
    _, records = _case(2.1e-2, 3.1e-4)
    tol = energy_tolerances(records, AREA, settings)
    # independent: range and round-off of each thickness from the energies per area
    for iz, expected_range in ((0, 2.1e-2), (1, 100.0)):
        e = [r["energy_ev"] / AREA * 1e3 for (_, _, z), r in records.items() if z == iz]
        assert max(e) - min(e) == pytest.approx(expected_range, rel=1e-6)
        assert tol[iz]["range_mev_per_a2"] == pytest.approx(expected_range, rel=1e-6)
        assert tol[iz]["round_off_mev_per_a2"] == pytest.approx(
            ROUND_OFF_RELATIVE * max(abs(v) for v in e)
        )
    assert tol[0]["tolerance_mev_per_a2"] == pytest.approx(0.05 * 2.1e-2, rel=1e-6)
    assert tol[1]["tolerance_mev_per_a2"] == 0.01  # the absolute cap on a rough landscape


@pytest.mark.parametrize(
    ("range_mev", "difference_mev", "broken_absolute", "broken_relative"),
    [
        # the relaxed (1, 2) twist at fmax 0.005 (measured): 1.5 % of its range, accepted
        (2.1e-2, 3.1e-4, False, False),
        # a quarter of a twist cell's corrugation: the absolute 0.01 accepted it
        (1.2e-2, 3e-3, False, True),
        # the relaxed (2, 3) twist at fmax 0.005: a landscape of 2e-4 broken by half of it
        (2e-4, 1e-4, False, True),
        # a landscape of Cu(111)'s size (~15 meV/Å² at fixed thickness): the cap decides
        (15.0, 5e-3, False, False),
        (15.0, 2e-2, True, True),
        # a rigid cell at round-off: (3, 4) twist, range 8e-9, differences of round-off
        (8e-9, 5e-9, False, False),
    ],
)
def test_the_relative_tolerance_sees_breaking_the_absolute_one_accepted(
    range_mev, difference_mev, broken_absolute, broken_relative
):
    reduction, records = _case(range_mev, difference_mev)
    relative = SymmetrySettings()
    check = verification(reduction, records, AREA, relative)
    (entry,) = check["checked"]
    assert entry["energy_difference_mev_per_a2"] == pytest.approx(difference_mev, rel=1e-3)
    assert symmetry_broken(check, relative) is broken_relative
    # the old rule: the absolute tolerance alone (a fraction so large that the cap decides)
    absolute = SymmetrySettings(energy_tolerance_fraction=1.0)
    assert symmetry_broken(verification(reduction, records, AREA, absolute), absolute) is (
        broken_absolute
    )
    if broken_relative:
        reason = fallback_reason(check, relative, 12)
        assert "5 % of the range at its thickness" in reason
        assert f"(tolerance {entry['energy_tolerance_mev_per_a2']:.3g})" in reason


def test_the_round_off_floor_keeps_a_flat_rigid_landscape_reduced():
    """Without the floor, 5 % of an 8e-9 meV/Å² range (4e-10) is below the engine's round-off
    (measured 1.4e-8 to 3.1e-8 meV/Å² on the twist cells): every rigid scan of a cell that
    flat would be computed in full for nothing."""
    reduction, records = _case(8e-9, 5e-9)
    (entry,) = verification(reduction, records, AREA, SymmetrySettings())["checked"]
    floor = ROUND_OFF_RELATIVE * abs(E0_EV_PER_A2) * 1e3
    assert entry["energy_tolerance_mev_per_a2"] == pytest.approx(floor, rel=1e-6)
    assert 0.05 * 8e-9 < 5e-9 < floor


def test_a_bad_fraction_is_refused_in_one_line():
    from flatcontact.foundation.errors import InputError

    with pytest.raises(InputError, match="energy_tolerance_fraction: expected a positive"):
        SymmetrySettings(energy_tolerance_fraction=float("nan"))
    assert np.isfinite(SymmetrySettings().energy_tolerance_fraction)
