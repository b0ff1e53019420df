"""An analytic probed column (a 9-3 wall) shared by the work-of-separation and thickness tests."""

import numpy as np

from flatcontact.foundation.units import EV_PER_A3_TO_GPA
from flatcontact.ispes.probe import ColumnProbe


def lj_wall_probe(w_ev_per_a2=0.02, z0=10.0, area=7.0):
    """Analytic 9-3 wall: U(z) = w [ (z0/z)^8 / 3 - 4/3 (z0/z)^2 ] scaled so U(z0) = -w A, U(inf) = 0."""
    z = np.concatenate([np.linspace(8.5, 10.0, 31), np.linspace(10.05, 40.0, 1200)])
    s = z0 / z
    u = w_ev_per_a2 * area * (s**8 - 4 * s**2) / 3.0
    dudz = w_ev_per_a2 * area * (-8 * s**8 + 8 * s**2) / (3.0 * z)
    p = -dudz / area * EV_PER_A3_TO_GPA
    return ColumnProbe((0.0, 0.0), z, u, p, 0, area)
