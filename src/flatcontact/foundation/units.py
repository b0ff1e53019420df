"""Named unit conversions used at stage boundaries.

The atomistic side works in ASE units (eV, Å, eV/Å); the continuum side in SI
(Pa, m, N). Values that people read or type carry their unit in their name
(``p0_gpa``, ``radius_um``, ``lateral_force_un``). Convert with these
constants, never with inline literals. The electron volt is the exact SI 2019
value (the elementary charge is defined, 1.602176634e-19 C: scipy.constants' value, bit for
bit), not ASE's older CODATA default.

Each constant is named ``<FROM>_TO_<TO>``: multiply a value in FROM to get TO.
"""

#: eV -> J, exact by the SI definition of 2019 (written out, not imported from
#: scipy.constants: its import cost every scan worker ≈ 0.07 s of CPU at start, and the
#: value is fixed; tests/test_units.py checks it equals scipy's)
_EV_J = 1.602176634e-19

#: eV/Å^3 -> GPa (stress of an energy per volume).
EV_PER_A3_TO_GPA = _EV_J * 1.0e30 / 1.0e9
#: eV/Å^3 -> MPa.
EV_PER_A3_TO_MPA = 1.0e3 * EV_PER_A3_TO_GPA
#: eV/Å^2 -> J/m^2 (surface energy, work of adhesion / separation).
EV_PER_A2_TO_J_PER_M2 = _EV_J * 1.0e20
#: eV -> J and eV -> zJ (1 zJ = 1e-21 J; Hamaker constants of solids are tens of zJ).
EV_TO_J = _EV_J
EV_TO_ZJ = _EV_J * 1.0e21
#: nm^-3 -> Å^-3 (number densities).
PER_NM3_TO_PER_A3 = 1.0e-3
#: eV/Å^2 -> meV/Å^2 (the paper's unit for ISPES energies per area).
EV_PER_A2_TO_MEV_PER_A2 = 1.0e3

#: GPa -> Pa, MPa -> Pa.
GPA_TO_PA = 1.0e9
MPA_TO_PA = 1.0e6
#: MPa/GPa is dimensionless: 1 MPa/GPa = 1e-3.
MPA_PER_GPA_TO_RATIO = 1.0e-3
#: GPa/nm -> Pa/m (interfacial shear stiffness per area).
GPA_PER_NM_TO_PA_PER_M = 1.0e18

#: lengths
UM_TO_M = 1.0e-6
NM_TO_M = 1.0e-9
ANGSTROM_TO_M = 1.0e-10
ANGSTROM_TO_NM = 0.1

#: forces
N_TO_UN = 1.0e6
UN_TO_N = 1.0e-6
N_PER_M_TO_N_PER_M = 1.0

#: J -> fJ (energies dissipated per oscillation cycle of a nanocontact)
J_TO_FJ = 1.0e15
