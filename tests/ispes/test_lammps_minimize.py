"""``optimizer: lammps-cg``: LAMMPS's own minimiser for a grid point (issue 22, large cells)."""

from __future__ import annotations

import numpy as np
import pytest

from flatcontact.foundation.errors import InputError
from flatcontact.ispes.geometry import thickness
from flatcontact.ispes.relax import PointTask, RelaxSettings, relax_point
from flatcontact.potentials import InteractionModel
from flatcontact.potentials.calculator import LammpsInterfaceCalculator


@pytest.fixture(scope="module")
def cu_bicrystal():
    from flatcontact.structures.construct import build_interface

    ref, _ = build_interface({"kind": "fcc111", "element": "Cu", "layers": 4})
    return ref.repeat((2, 2, 1))


def _point(ref, optimizer, mode, fmax):
    calc = LammpsInterfaceCalculator(InteractionModel(preset="cu-eam"), ref)
    task = PointTask((0, 0, 0), 1 / 6, 1 / 6, thickness(ref))  # a stacking fault: relaxes
    before = calc.force_calls
    result = relax_point(ref, calc, task, RelaxSettings(fmax, optimizer=optimizer, mode=mode))
    assert result.force_calls + result.hessian_force_calls == calc.force_calls - before
    return result


@pytest.mark.parametrize("mode", ["full", "normal"])
def test_lammps_cg_reaches_the_minimum_lbfgs_reaches(cu_bicrystal, mode):
    """At a tight tolerance both optimisers end in the same minimum of the same energy: equal
    energies, positions and loads (to what the tolerance leaves), the tolerance met on the raw
    forces (computed by relax_point, not taken from LAMMPS), held atoms where they were (the
    relax_point guards) and, in normal mode, no lateral motion."""
    fmax = 1e-4
    ours = _point(cu_bicrystal, "LBFGS", mode, fmax)
    cg = _point(cu_bicrystal, "lammps-cg", mode, fmax)
    assert cg.converged and cg.max_force_ev_per_a < fmax
    assert cg.energy_ev == pytest.approx(ours.energy_ev, abs=1e-6)
    assert np.abs(cg.positions - ours.positions).max() < 1e-3
    assert cg.normal_stress_gpa == pytest.approx(ours.normal_stress_gpa, abs=0.02)
    assert cg.steps >= 1 and cg.force_calls > cg.steps  # cg's line search: ≥ 1 call per step


def test_lammps_cg_refuses_rigid_layers_before_any_work():
    with pytest.raises(InputError, match="rigid layers"):
        RelaxSettings(optimizer="lammps-cg", mode="rigid-layers")


def test_lammps_cg_needs_a_lammps_model(toy_reference):
    from flatcontact.ispes.toy import toy_calculator

    task = PointTask((0, 0, 0), 0.1, 0.0, thickness(toy_reference))
    with pytest.raises(InputError, match="LAMMPS interaction model"):
        relax_point(toy_reference, toy_calculator(), task, RelaxSettings(optimizer="lammps-cg"))


def test_config_check_refuses_lammps_cg_with_an_ase_calculator_before_any_stage(tmp_path, capsys):
    """The pre-run check (``config --check`` and the pipeline's first step) refuses
    ``lammps-cg`` with an ASE calculator in one line, before the build."""
    from tests.hardening.helpers import TOY_YAML, refused, run_cli

    conf = tmp_path / "run.yaml"
    conf.write_text(
        TOY_YAML.replace("executor: serial", "executor: serial\n  optimizer: lammps-cg")
    )
    code, _, err = run_cli(["config", "--check", conf], capsys)
    refused(code, err, "scan.optimizer", "lammps-cg", "toy_calculator")
    code, _, err = run_cli(["run", conf, "--out", tmp_path / "run"], capsys)
    refused(code, err, "scan.optimizer")
    assert not any((tmp_path / "run").glob("0*-*"))
