"""Grid definition, overlap check, pressure-range thicknesses and work of separation."""

import numpy as np
import pytest

from flatcontact.errors import InputError
from flatcontact.ispes.geometry import thickness
from flatcontact.ispes.grid import (
    ColumnProbe,
    GridSpec,
    adhesion,
    check_thicknesses,
    thicknesses_for_pressures,
)
from flatcontact.units import EV_PER_A2_TO_J_PER_M2, EV_PER_A3_TO_GPA


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"n_a": 0, "n_b": 3, "thickness_angstrom": (10.0,)}, "n_a"),
        ({"n_a": 3, "n_b": 0, "thickness_angstrom": (10.0,)}, "n_b"),
        ({"n_a": 3, "n_b": 3, "thickness_angstrom": ()}, "thickness"),
        ({"n_a": 3, "n_b": 3, "thickness_angstrom": (10.0, 10.0)}, "repeat"),
        ({"n_a": 3, "n_b": 3, "thickness_angstrom": (-1.0,)}, "positive"),
        ({"n_a": 3, "n_b": 3}, "either"),
        ({"n_a": 3, "n_b": 3, "p_range_gpa": (2.0, 1.0, 4)}, "LO < HI"),
        ({"n_a": 3, "n_b": 3, "p_range_gpa": (-1.0, 3.0, 1)}, "N must"),
    ],
)
def test_bad_grids_are_one_line_errors(kwargs, match):
    with pytest.raises(InputError, match=match) as err:
        GridSpec(**kwargs)
    assert "\n" not in str(err.value)


def test_overlapping_thickness_is_refused(toy_reference):
    grid = GridSpec(2, 2, thickness_angstrom=(thickness(toy_reference) - 2.0,))
    with pytest.raises(InputError, match="overlap"):
        check_thicknesses(toy_reference, grid, grid.thickness_angstrom)


def _lj_wall_probe(w_ev_per_a2=0.02, z0=10.0, area=7.0):
    """Analytic 9-3 wall: U(z) = w [ (z0/z)^8 / 3 - 4/3 (z0/z)^2 ] scaled so U(z0) = -w A, U(inf) = 0."""
    z = np.concatenate([np.linspace(8.5, 10.0, 31), np.linspace(10.05, 40.0, 1200)])
    s = z0 / z
    u = w_ev_per_a2 * area * (s**8 - 4 * s**2) / 3.0
    dudz = w_ev_per_a2 * area * (-8 * s**8 + 8 * s**2) / (3.0 * z)
    p = -dudz / area * EV_PER_A3_TO_GPA
    return ColumnProbe((0.0, 0.0), z, u, p, 0, area)


def test_adhesion_of_an_analytic_curve():
    w = 0.02
    probe = _lj_wall_probe(w)
    adh = adhesion(probe)
    assert adh.equilibrium_thickness_angstrom == pytest.approx(10.0, abs=1e-3)
    # U(40) is not quite zero: compare with the exact energy difference of the curve
    expected = (
        (probe.energy_ev[-1] + w * probe.area_angstrom2)
        / probe.area_angstrom2
        * EV_PER_A2_TO_J_PER_M2
    )
    assert adh.work_of_separation_j_per_m2 == pytest.approx(expected, rel=1e-6)
    assert adh.work_of_separation_integral_j_per_m2 == pytest.approx(expected, rel=1e-3)
    # tensile maximum: the minimum of the exact p(z) on a fine grid
    zz = np.linspace(10.0, 14.0, 400001)
    s = 10.0 / zz
    p_exact = w * 8 * (s**8 - s**2) / (3.0 * zz) * EV_PER_A3_TO_GPA
    assert adh.max_tension_gpa == pytest.approx(p_exact.min(), rel=1e-3)


def test_thicknesses_span_the_pressure_range():
    probe = _lj_wall_probe()
    z, notes = thicknesses_for_pressures(probe, -0.1, 2.0, 5)
    assert notes == []
    p_at = np.interp(z, probe.thickness_angstrom, probe.normal_stress_gpa)
    np.testing.assert_allclose(np.sort(p_at)[::-1], np.linspace(-0.1, 2.0, 5)[::-1], atol=2e-3)
    _, notes = thicknesses_for_pressures(probe, -50.0, 2.0, 3)
    assert notes and "maximum adhesive tension" in notes[0]
    with pytest.raises(InputError, match="most compressed"):
        thicknesses_for_pressures(probe, 0.0, 1e4, 3)
