"""The scan physics on an α-quartz (0001) interface with Vashishta + TS-LJ (LAMMPS engine).

The interface is the builder's verified dense (0001) interface (6 layers, the shipped
CHGNet-relaxed slab re-relaxed with Vashishta), the one the default run scans.
"""

import pytest

from flatcontact.foundation.units import EV_PER_A3_TO_GPA
from flatcontact.ispes.contract import cell_area
from flatcontact.ispes.geometry import in_plane_vectors, thickness
from flatcontact.ispes.relax import PointTask, RelaxSettings, relax_point

TIGHT = RelaxSettings(fmax_ev_per_angstrom=1e-4, optimizer="LBFGS", max_steps=5000)


@pytest.fixture(scope="module")
def quartz():
    from flatcontact.potentials import InteractionModel, make_calculator
    from flatcontact.structures.build import build_quartz_interface

    spec = InteractionModel(intra="vashishta")
    atoms, _report = build_quartz_interface(
        spec, layers=6, source="shipped"
    )  # raises unless verified
    return atoms, make_calculator(spec, atoms)


def test_quartz_load_is_minus_energy_derivative(quartz):
    ref, calc = quartz
    area = cell_area(*in_plane_vectors(ref))
    z0, h = thickness(ref) - 0.2, 2e-3
    lo, mid, hi = (
        relax_point(ref, calc, PointTask((0, 0, 0), 0.3, 0.6, z0 + d), TIGHT) for d in (-h, 0.0, h)
    )
    fd_gpa = -(hi.energy_ev - lo.energy_ev) / (2 * h) / area * EV_PER_A3_TO_GPA
    assert mid.converged and mid.normal_stress_gpa > 0.1  # compressed
    assert mid.normal_stress_gpa == pytest.approx(fd_gpa, abs=0.01)


def test_quartz_energy_is_periodic(quartz):
    ref, calc = quartz
    z = thickness(ref) - 0.1
    a = relax_point(ref, calc, PointTask((0, 0, 0), 0.25, 0.5, z), TIGHT)
    b = relax_point(ref, calc, PointTask((0, 0, 0), 1.25, -0.5, z), TIGHT)
    assert a.energy_ev == pytest.approx(b.energy_ev, abs=1e-6)
    assert a.normal_stress_gpa == pytest.approx(b.normal_stress_gpa, abs=1e-3)
