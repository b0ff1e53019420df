"""The asperity's loads as jobs on the scan's executors give the states of a sequential run,
bit for bit; the amplitude ramp end to end on a small Cu(111) cylinder (EAM inside, LJ
across)."""

import dataclasses

import numpy as np
import pytest
from tests.asperity.test_asperity_run import LAWS, MODEL, RECIPE, SPEC

from flatcontact.asperity.driver import load_state
from flatcontact.asperity.experiment import run_experiment
from flatcontact.asperity.ramp import loop_lockin
from flatcontact.ispes.executors import ProcessExecutor, SerialExecutor
from flatcontact.potentials.model import InteractionModel
from flatcontact.structures.recipe import parse_recipe

pytestmark = pytest.mark.slow

TWO_LOADS = dataclasses.replace(SPEC, p0_gpa=(0.5, 1.0), steps=1)


def _states(folder, spec):
    return [
        [load_state(folder / f"load_{i}" / f"step_{k:04d}.npz") for k in range(spec.steps + 1)]
        for i in range(len(spec.p0_gpa))
    ]


@pytest.mark.parametrize(
    "make", [SerialExecutor, lambda: ProcessExecutor(2)], ids=["serial", "pool"]
)
def test_loads_as_jobs_equal_a_sequential_run(tmp_path, make):
    model = InteractionModel.model_validate(MODEL)
    recipe = parse_recipe(RECIPE)
    seq = run_experiment(TWO_LOADS, recipe, model, LAWS, tmp_path / "seq")
    executor = make()
    try:
        par = run_experiment(TWO_LOADS, recipe, model, LAWS, tmp_path / "par", executor=executor)
    finally:
        executor.close()
    for a_load, b_load in zip(
        _states(tmp_path / "seq", TWO_LOADS), _states(tmp_path / "par", TWO_LOADS), strict=True
    ):
        for a, b in zip(a_load, b_load, strict=True):
            assert np.array_equal(a.positions, b.positions)
            assert np.array_equal(a.tip_force, b.tip_force)
            assert np.array_equal(a.cross_force, b.cross_force)
    assert seq.comparisons == par.comparisons
    # the two loads differ (the jobs did not run one load twice)
    assert seq.records[0][0].normal_force_n < 0.75 * seq.records[1][0].normal_force_n


def test_the_ramp_end_to_end(tmp_path):
    """One small amplitude, inside the stick regime of this LJ contact (it slips at u ≈ 0.4 Å):
    the cycle is elastic, so k' is the secant Q_amp/U and the loop closes; the ramp's first
    state is the slide's first step (the same displacement from the same pressed state)."""
    spec = dataclasses.replace(SPEC, steps=1, ramp_amplitudes_angstrom=(0.1,))
    model = InteractionModel.model_validate(MODEL)
    exp = run_experiment(spec, parse_recipe(RECIPE), model, LAWS, tmp_path / "state")
    (ramp,) = exp.ramps
    first, last = ramp["loops"][0]
    u = np.asarray(ramp["displacement_angstrom"])
    assert u[first : last + 1].tolist() == pytest.approx([0.1, 0.0, -0.1, 0.0, 0.1])
    slide1 = load_state(tmp_path / "state" / "load_0" / "step_0001.npz")
    ramp1 = load_state(tmp_path / "state" / "load_0" / "ramp" / "step_0001.npz")
    assert np.array_equal(slide1.positions, ramp1.positions)
    q = np.asarray(ramp["lateral_force_n"])
    row = ramp["amplitudes"][0]
    assert row["atoms_lockin_n_per_m"] == pytest.approx(
        loop_lockin(u[first : last + 1] * 1e-10, q[first : last + 1]).stiffness
    )
    # elastic: back to the same force after the cycle, no loss, k' = secant
    assert q[last] == pytest.approx(q[first], rel=0.02)
    assert abs(row["atoms_loss_tangent"]) < 0.05
    assert row["atoms_lockin_n_per_m"] == pytest.approx(row["atoms_secant_n_per_m"], rel=0.05)
    # the models are at the atoms' Q_amp/Q_peak with the atoms' K0: inside the stick regime
    # both are close to K0
    k0 = ramp["initial_stiffness_n_per_m"]
    for key in ("model_hertz_lockin_n_per_m", "model_measured_pressure_lockin_n_per_m"):
        if row[key] is not None:
            assert 0.3 * k0 < row[key] <= k0 * (1 + 1e-9)
    # extending the ramp reuses the saved states
    ramp_dir = tmp_path / "state" / "load_0" / "ramp"
    stamp = (ramp_dir / "step_0005.npz").stat().st_mtime_ns
    longer = dataclasses.replace(spec, ramp_amplitudes_angstrom=(0.1, 0.2))
    exp2 = run_experiment(longer, parse_recipe(RECIPE), model, LAWS, tmp_path / "state")
    assert (ramp_dir / "step_0005.npz").stat().st_mtime_ns == stamp
    assert exp2.ramps[0]["amplitudes"][0] == row


def test_radii_as_jobs_equal_one_run_per_radius(tmp_path):
    """``flatcontact asperity --radii``: every (radius, load) a job on the scan's pool gives
    each radius the asperity.json of its own sequential run."""
    import json

    import yaml

    from flatcontact.config import load_config
    from flatcontact.stages.asperity import (
        AsperityInputs,
        asperity_stage,
        radius_settings,
        run_asperity_radii,
    )

    doc = {
        "structure": RECIPE,
        "potential": MODEL,
        "scan": {"executor": "processes", "workers": 2},
        "asperity": {
            "enabled": True,
            "radius_angstrom": 100.0,
            "p0_gpa": [1.0],
            "contact_modulus_gpa": 73.0,
            "step_angstrom": 0.1,
            "steps": 1,
            "depth_factor": 2.0,
        },
    }
    path = tmp_path / "run.yaml"
    path.write_text(yaml.safe_dump(doc))
    settings = load_config(path)
    inputs = AsperityInputs(laws=dataclasses.asdict(LAWS))
    results = run_asperity_radii(settings, inputs, tmp_path / "par", [100.0, 120.0])
    for radius, result in zip([100.0, 120.0], results, strict=True):
        alone = asperity_stage(radius_settings(settings, radius), inputs, tmp_path / f"seq{radius}")
        assert result.doc["radius_angstrom"] == radius
        assert json.dumps(result.doc["loads"]) == json.dumps(alone.doc["loads"])
        assert (tmp_path / "par" / f"R{radius:g}" / "asperity.json").is_file()
    assert results[0].doc["n_atoms"] < results[1].doc["n_atoms"]
