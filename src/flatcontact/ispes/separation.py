"""Equilibrium thickness, tensile strength and pull-off work of a probed column.

Pull-off work (per area, J/m²) from the probed column (the paper's z-scan):
W_pull = [U(z_sep) - U(z_eq)] / A = -∫_{z_eq}^{z_sep} p dz, with z_eq the thickness of
zero load and z_sep a thickness where the slabs no longer interact (p ≈ 0 beyond the
tensile maximum). Both forms are reported; they agree when the cross-interface
potential is continuous at its cutoff and the relaxations are converged.

It is a diagnostic: with the inner planes free, a column pulled apart between its held
layers may open more than one gap (two for a bonded metal: ≈ 4γ instead of 2γ). The work
of separation of the interface, one cut, is
:mod:`flatcontact.ispes.work_of_separation`.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.units import EV_PER_A2_TO_J_PER_M2, EV_PER_A3_TO_GPA
from flatcontact.ispes.probe import ColumnProbe


@dataclasses.dataclass(frozen=True)
class Adhesion:
    """Equilibrium, tensile strength and pull-off work of a probed column."""

    equilibrium_thickness_angstrom: float
    max_tension_gpa: float
    max_tension_thickness_angstrom: float
    pull_off_work_j_per_m2: float
    pull_off_work_integral_j_per_m2: float
    separated: bool

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


def adhesion(probe: ColumnProbe) -> Adhesion:
    """Equilibrium thickness (p = 0), maximum tension and pull-off work of a column.

    z_eq is the zero of p(z) between the last compressed and first tensile sample
    (linear interpolation); U(z_eq) is interpolated linearly (U is stationary there).
    W_pull = [U(z_last) - U(z_eq)]/A and W_int = -∫ p dz (trapezoid from z_eq to z_last), in
    J/m² (``EV_PER_A2_TO_J_PER_M2``; p in GPa -> eV/Å³ by division with
    ``EV_PER_A3_TO_GPA``).
    """
    z, e, p = probe.thickness_angstrom, probe.energy_ev, probe.normal_stress_gpa
    sign_change = np.nonzero((p[:-1] >= 0) & (p[1:] < 0))[0]
    if sign_change.size == 0:
        raise InputError(
            "probe column: the load never changes sign from compression to tension; no equilibrium thickness"
        )
    k = int(sign_change[0])
    z_eq = z[k] + (z[k + 1] - z[k]) * p[k] / (p[k] - p[k + 1])
    e_eq = np.interp(z_eq, z[k : k + 2], e[k : k + 2])
    above = z > z_eq
    zz = np.concatenate([[z_eq], z[above]])
    pp = np.concatenate([[0.0], p[above]]) / EV_PER_A3_TO_GPA  # eV/Å³
    integral = -float(np.sum(0.5 * (pp[1:] + pp[:-1]) * np.diff(zz)))  # eV/Å²
    i_min = int(np.argmin(p))
    return Adhesion(
        equilibrium_thickness_angstrom=float(z_eq),
        max_tension_gpa=float(p[i_min]),
        max_tension_thickness_angstrom=float(z[i_min]),
        pull_off_work_j_per_m2=float((e[-1] - e_eq) / probe.area_angstrom2 * EV_PER_A2_TO_J_PER_M2),
        pull_off_work_integral_j_per_m2=integral * EV_PER_A2_TO_J_PER_M2,
        separated=bool(i_min < len(p) - 1 and abs(p[-1]) < 0.01 * abs(p[i_min])),
    )
