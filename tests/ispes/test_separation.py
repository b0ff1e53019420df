"""Work of separation of a probed column."""

import numpy as np
import pytest
from tests.ispes.analytic_column import lj_wall_probe

from flatcontact.foundation.units import EV_PER_A2_TO_J_PER_M2, EV_PER_A3_TO_GPA
from flatcontact.ispes.separation import adhesion


def test_adhesion_of_an_analytic_curve():
    w = 0.02
    probe = lj_wall_probe(w)
    adh = adhesion(probe)
    assert adh.equilibrium_thickness_angstrom == pytest.approx(10.0, abs=1e-3)
    # U(40) is not quite zero: compare with the exact energy difference of the curve
    expected = (
        (probe.energy_ev[-1] + w * probe.area_angstrom2)
        / probe.area_angstrom2
        * EV_PER_A2_TO_J_PER_M2
    )
    assert adh.pull_off_work_j_per_m2 == pytest.approx(expected, rel=1e-6)
    assert adh.pull_off_work_integral_j_per_m2 == pytest.approx(expected, rel=1e-3)
    # tensile maximum: the minimum of the exact p(z) on a fine grid
    zz = np.linspace(10.0, 14.0, 400001)
    s = 10.0 / zz
    p_exact = w * 8 * (s**8 - s**2) / (3.0 * zz) * EV_PER_A3_TO_GPA
    assert adh.max_tension_gpa == pytest.approx(p_exact.min(), rel=1e-3)
