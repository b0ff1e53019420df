"""The reference-Hessian preconditioner keeps the exact resume: its Hessian is a function of
the reference, the calculator and the mode, computed on an engine started afresh, so a point
relaxed after it was computed, on a fresh engine or in a resumed scan, has the same bits
(Cu(111) EAM interface, LAMMPS)."""

from __future__ import annotations

import sys

import numpy as np
import pytest
from tests.hardening.test_exact_resume import STRUCTURE, _identical

from flatcontact.ispes import precondition
from flatcontact.ispes.executors import SerialExecutor
from flatcontact.ispes.geometry import fixed_mask, thickness
from flatcontact.ispes.grid import GridSpec
from flatcontact.ispes.relax import PointTask, RelaxSettings, relax_point
from flatcontact.ispes.scan import run_scan
from flatcontact.potentials.calculator import LammpsInterfaceCalculator
from flatcontact.potentials.engines import calculator_factory
from flatcontact.potentials.model import InteractionModel
from flatcontact.structures.construct import build_interface

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="Linux only")

MODEL = InteractionModel(preset="cu-eam")


@pytest.fixture(scope="module")
def cu_reference():
    atoms, _ = build_interface(STRUCTURE)
    return atoms


@pytest.mark.parametrize("optimizer", ["LBFGS", "LBFGS-scaled"])
@pytest.mark.parametrize("mode", ["full", "normal"])
def test_a_preconditioned_point_does_not_depend_on_the_engine_or_the_cache(
    cu_reference, mode, optimizer
):
    """The same task on a fresh calculator (which computes the Hessian first: 2 force calls
    per relaxed coordinate, counted apart from the point's own) and on one that relaxed other
    points with the Hessian cached: the same bits, and fewer force calls than without it (the
    same energy in ``normal`` mode)."""
    ref = cu_reference
    z0 = thickness(ref)
    settings = RelaxSettings(0.005, optimizer, mode=mode, precondition=True)
    task = PointTask((0, 0, 0), 1 / 6, 1 / 3, z0 - 0.15)
    precondition._CACHE.clear()
    calc = LammpsInterfaceCalculator(MODEL, ref)
    fresh = relax_point(ref, calc, task, settings)
    free = int((~fixed_mask(ref)).sum()) * (3 if mode == "full" else 1)
    assert fresh.hessian_force_calls == 2 * free
    assert calc.force_calls == fresh.force_calls + fresh.hessian_force_calls
    used = LammpsInterfaceCalculator(MODEL, ref)
    for other in (PointTask((1, 0, 0), 0.5, 0.0, z0 + 0.3), PointTask((2, 0, 0), 0.0, 0.5, z0)):
        relax_point(ref, used, other, settings)
    again = relax_point(ref, used, task, settings)
    assert again.hessian_force_calls == 0  # cached with the calculator
    assert again.energy_ev == fresh.energy_ev
    assert again.normal_stress_gpa == fresh.normal_stress_gpa
    assert np.array_equal(again.positions, fresh.positions)
    assert fresh.converged and fresh.max_force_ev_per_a < 0.005
    plain = relax_point(
        ref, used, task, RelaxSettings(0.005, optimizer, mode=mode, precondition=False)
    )
    assert fresh.force_calls < plain.force_calls
    if mode == "normal":  # one minimum along z; in 3D the free layers have two wells here:
        # the unpreconditioned steps slide into the lower (-27.4175 eV), the preconditioned stay in
        # the nearer (-27.3840 eV), each a minimum to 1e-4 eV/Å (docs/performance.md)
        assert abs(plain.energy_ev - fresh.energy_ev) < 1e-4


def test_interrupted_preconditioned_scan_resumes_to_the_same_bits(cu_reference, tmp_path):
    """A 4 × 4 × 3 grid relaxed whole, and one stopped after 10 points and resumed (the
    Hessian cache emptied before each run, as in a new process): the same ispes.nc."""
    ref = cu_reference
    z0 = thickness(ref)
    grid = GridSpec(4, 4, thickness_angstrom=(z0 - 0.2, z0, z0 + 0.3))
    settings = RelaxSettings(0.005, "LBFGS", precondition=True)
    factory = calculator_factory(MODEL)
    whole, resumed = tmp_path / "whole", tmp_path / "resumed"

    def scan(out, **kw):
        precondition._CACHE.clear()
        return run_scan(ref, factory, grid, out, settings, executor=SerialExecutor(), **kw)

    done = scan(whole)
    assert done.points_computed == 48 and done.dataset.converged.all()
    assert scan(resumed, max_new_points=10).points_computed == 10
    assert scan(resumed).points_computed == 38
    _identical(whole, resumed)
