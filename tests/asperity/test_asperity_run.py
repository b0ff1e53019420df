"""A small Cu(111) asperity (EAM inside, LJ across) end to end, its equilibrium checked with
an independent force evaluation, and kill -9 / resume giving bit-identical states."""

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from flatcontact.asperity.compare import Laws
from flatcontact.asperity.driver import EV_PER_ANGSTROM_N, load_state
from flatcontact.asperity.experiment import ExperimentSpec, run_experiment
from flatcontact.potentials.model import InteractionModel
from flatcontact.structures.recipe import parse_recipe

pytestmark = pytest.mark.slow

RECIPE = {"kind": "fcc111", "element": "Cu", "a_angstrom": 3.615, "layers": 3, "gap_angstrom": 3.0}
MODEL = {
    "intra": [{"pair_style": "eam/alloy", "pair_coeff": ["Cu_mishin1.eam.alloy"]}],
    "coupling": "lj",
    "lj": {"cutoff_angstrom": 8.0},
}
SPEC = ExperimentSpec(
    geometry="cylinder",
    radius_angstrom=100.0,
    p0_gpa=(1.0,),
    contact_modulus_gpa=73.0,
    step_angstrom=0.1,
    steps=4,
    fmax_ev_per_angstrom=1e-3,
    max_iterations=20000,
    depth_factor=2.0,
    lateral_factor=4.0,
    axis_repeats=2,
    rigid_angstrom=6.0,
    repeats=None,
    layers=None,
    gap_angstrom=None,
    bin_width_angstrom=2.0,
    contact_force_ev_per_angstrom=0.005,
    slip_threshold_angstrom=0.1,
)
LAWS = Laws(5.0, 185.0, 0.4, 56.0)


@pytest.fixture(scope="module")
def experiment(tmp_path_factory):
    folder = tmp_path_factory.mktemp("asperity")
    model = InteractionModel.model_validate(MODEL)
    exp = run_experiment(SPEC, parse_recipe(RECIPE), model, LAWS, folder / "state")
    return exp, folder, model


def test_every_state_is_an_equilibrium_under_the_target_load(experiment):
    from flatcontact.potentials.engines import make_calculator

    exp, folder, model = experiment
    atoms = exp.atoms.copy()
    block = atoms.arrays["block"]
    target = exp.targets_ev_per_angstrom[0]
    for k in (0, SPEC.steps):
        state = load_state(folder / "state" / "load_0" / f"step_{k:04d}.npz")
        atoms.positions = state.positions
        atoms.calc = make_calculator(model, atoms)  # the tool's ASE engine, a fresh instance
        f = atoms.get_forces()
        assert np.max(np.abs(f[block == 0])) < 1.5 * SPEC.fmax_ev_per_angstrom
        # the contact pushes the tip block up with the target force (1 % tolerance)
        assert f[block == 2, 2].sum() == pytest.approx(target, rel=0.011)
        assert state.tip_force == pytest.approx(f[block == 2].sum(axis=0), abs=1e-6)
        # the block was displaced rigidly by k steps along y
        moved = state.positions[block == 2] - exp.atoms.positions[block == 2]
        assert moved[:, 1] == pytest.approx(k * SPEC.step_angstrom, abs=1e-9)
        assert moved[:, 0] == pytest.approx(0.0, abs=1e-9)
        assert np.ptp(moved[:, 2]) < 1e-9


def test_records_are_consistent_and_the_comparison_is_filled(experiment):
    exp, _, _ = experiment
    recs = exp.records[0]
    target_n = exp.targets_ev_per_angstrom[0] * EV_PER_ANGSTROM_N
    assert [r.normal_force_n for r in recs] == pytest.approx([target_n] * len(recs), rel=0.011)
    # fcc(111) has no mirror y -> -y (ABC stacking), so the pressed state may carry a small Q;
    # pushing the tip along +y raises it
    assert recs[1].lateral_force_n > recs[0].lateral_force_n
    # the binned pressure integrates to the normal load (the cross forces are the load)
    areas = np.diff(exp.binning.edges_angstrom) * exp.binning.axis_length_angstrom
    load = np.sum(recs[0].pressure_gpa * areas) / 160.21766208 * EV_PER_ANGSTROM_N
    assert load == pytest.approx(target_n, rel=0.05)
    assert all(r.converged for r in recs)
    comp = exp.comparisons[0]
    q0 = recs[0].lateral_force_n  # Q is counted from the pressed state
    assert comp["atoms"]["lateral_force_at_zero_displacement_n"] == q0
    assert comp["atoms"]["peak_lateral_force_n"] == pytest.approx(
        max(r.lateral_force_n for r in recs) - q0, rel=1e-12
    )
    assert comp["fitted_compliance_m_per_n"] > 0
    assert len(comp["model_hertz"]["lateral_force_n"]) == len(recs)


_CHILD = textwrap.dedent(
    """
    import sys
    from pathlib import Path
    sys.path.insert(0, {src!r})
    from flatcontact.asperity.experiment import run_experiment
    from flatcontact.potentials.model import InteractionModel
    from flatcontact.structures.recipe import parse_recipe
    import test_asperity_run as t
    run_experiment(t.SPEC, parse_recipe(t.RECIPE), InteractionModel.model_validate(t.MODEL),
                   None, Path(sys.argv[1]))
    """
)


def test_kill_and_resume_gives_identical_states(experiment, tmp_path):
    _, folder, _ = experiment
    here = Path(__file__).parent
    src = str(Path(__file__).parents[2] / "src")
    script = tmp_path / "child.py"
    script.write_text(_CHILD.format(src=src))
    env = {**os.environ, "PYTHONPATH": f"{src}{os.pathsep}{here}"}
    state = tmp_path / "state"
    child = subprocess.Popen([sys.executable, str(script), str(state)], env=env)
    target = state / "load_0" / "step_0002.npz"
    deadline = time.monotonic() + 600
    while not target.exists() and child.poll() is None and time.monotonic() < deadline:
        time.sleep(0.05)
    os.kill(child.pid, signal.SIGKILL)
    child.wait()
    done_before = sorted(p.name for p in (state / "load_0").glob("step_*.npz"))
    assert "step_0002.npz" in done_before and "step_0004.npz" not in done_before
    subprocess.run([sys.executable, str(script), str(state)], env=env, check=True)
    for k in range(SPEC.steps + 1):
        a = load_state(state / "load_0" / f"step_{k:04d}.npz")
        b = load_state(folder / "state" / "load_0" / f"step_{k:04d}.npz")
        assert np.array_equal(a.positions, b.positions)
        assert np.array_equal(a.tip_force, b.tip_force)
        assert np.array_equal(a.cross_force, b.cross_force)
