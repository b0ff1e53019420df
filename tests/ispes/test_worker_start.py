"""What a scan worker imports: a point on a LAMMPS model with the LJ coupling needs no scipy.

A spawned worker imports what unpickling its task needs and what relaxing the point needs;
every module more is CPU it spends at start on the cores the scan uses (scipy.constants,
scipy.spatial, ase.calculators.vdwcorrection: ≈ 0.2 s a worker before they were kept
out). The worker here is a fresh interpreter doing exactly what a
``ProcessExecutor`` worker does: import the executor module, unpickle the context and the
task, relax the point; its result must be the driver's own relaxation of the same point.
"""

import json
import pickle
import subprocess
import sys
import textwrap

import numpy as np

WORKER = textwrap.dedent(
    """
    import json, pickle, sys
    import flatcontact.ispes.executors  # the worker's initializer's module
    from flatcontact.ispes.relax import run_task

    with open(sys.argv[1], "rb") as handle:
        context, task = pickle.load(handle)
    result = run_task(context, task)
    with open(sys.argv[2], "wb") as handle:
        pickle.dump(result, handle)
    print(json.dumps(sorted(sys.modules)))
    """
)

#: modules a worker relaxing a point on a LAMMPS model never needs
NOT_IN_A_WORKER = (
    "scipy",
    "scipy.spatial",
    "scipy.constants",
    "ase.calculators.vdwcorrection",
    "ase.neighborlist",
)


def test_a_worker_relaxes_a_point_without_scipy(tmp_path):
    from flatcontact.ispes.geometry import thickness
    from flatcontact.ispes.relax import PointTask, RelaxSettings, ScanContext, run_task
    from flatcontact.potentials import InteractionModel
    from flatcontact.potentials.engines import calculator_factory
    from flatcontact.structures.build import build_quartz_interface

    spec = InteractionModel(intra="vashishta")  # with the default LJ coupling across
    reference, _ = build_quartz_interface(spec, layers=6, source="shipped")
    context = ScanContext(reference, calculator_factory(spec), RelaxSettings(0.01))
    task = PointTask((1, 2, 0), 0.25, 0.5, thickness(reference) + 0.3)
    with open(tmp_path / "task.pkl", "wb") as handle:
        pickle.dump((context, task), handle)
    out = subprocess.run(
        [sys.executable, "-c", WORKER, str(tmp_path / "task.pkl"), str(tmp_path / "result.pkl")],
        capture_output=True,
        text=True,
        check=True,
    )
    modules = set(json.loads(out.stdout.splitlines()[-1]))
    assert "flatcontact.potentials.lj" in modules  # the coupling was built in the worker
    assert "lammps" in modules
    assert not modules & set(NOT_IN_A_WORKER), sorted(modules & set(NOT_IN_A_WORKER))
    with open(tmp_path / "result.pkl", "rb") as handle:
        theirs = pickle.load(handle)
    ours = run_task(context, task)  # here, where scipy is loaded: the same numbers
    assert theirs.converged and ours.force_calls == theirs.force_calls
    assert ours.energy_ev == theirs.energy_ev
    assert ours.normal_stress_gpa == theirs.normal_stress_gpa
    np.testing.assert_array_equal(ours.positions, theirs.positions)
