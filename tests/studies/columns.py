"""Probed columns with a closed-form load, p(z) = p0 (e^{-2a(z-z0)} - e^{-a(z-z0)}), and the
thicknesses the scan's chooser takes from them: the thickness-step tests of the convergence
study and its estimate. Import by full name (tests/README.md)."""

from __future__ import annotations

import numpy as np

from flatcontact.ispes.probe import ColumnProbe
from flatcontact.ispes.thicknesses import thicknesses_spanning_columns


def column(z0: float, p0_gpa: float, a_per_angstrom: float, shift=(0.0, 0.0)) -> ColumnProbe:
    """A probed column whose load is the Morse-like p(z) = p0 (e^{-2a(z-z0)} - e^{-a(z-z0)}):
    P = 0 at z0, stiffness p0·a GPa/Å there, tensile maximum -p0/4 at z0 + ln 2 / a."""
    z = np.arange(13.8, 16.0, 0.01)
    d = z - z0
    p = p0_gpa * (np.exp(-2 * a_per_angstrom * d) - np.exp(-a_per_angstrom * d))
    return ColumnProbe(shift, z, np.zeros_like(z), p, 0, 7.0)


def chosen(probes, hi_gpa: float, n: int) -> dict:
    """``{"thickness_angstrom": [...]}``: the chooser's thicknesses for loads 0 … ``hi_gpa``
    in ``n`` steps at the first probe, bracketing every probe (as a variant's result holds them)."""
    z = thicknesses_spanning_columns(probes, 0.0, hi_gpa, n).thickness_angstrom
    return {"thickness_angstrom": z.tolist()}
