"""The CHGNet r2SCAN teacher (optional extra): label conventions, and the recipe end to end."""

import numpy as np
import pytest

pytest.importorskip("chgnet")
pytest.importorskip("torch")

from flatcontact.elastic import deformed
from flatcontact.training.label import label_frames, teacher_calculator
from flatcontact.training.polymorphs import build_polymorph


@pytest.fixture(scope="module")
def teacher():
    return teacher_calculator()


def test_teacher_stress_is_ase_convention(teacher):
    """stress_k = (1/V) dE/de_k (ASE sign, eV/Å^3, Voigt) by central differences of the energy."""
    q = build_polymorph("alpha_quartz")
    q.positions += np.random.default_rng(0).normal(0, 0.02, q.positions.shape)
    (frame,) = label_frames([q], teacher)
    stress = frame.calc.results["stress"]
    h = 2e-3
    for k in (0, 2, 3, 5):
        e = []
        for s in (1, -1):
            a = deformed(q, np.eye(6)[k] * s * h)
            a.calc = teacher
            e.append(a.get_potential_energy())
        assert stress[k] == pytest.approx((e[0] - e[1]) / (2 * h) / q.get_volume(), abs=3e-4)


@pytest.mark.slow
def test_small_recipe_runs_and_labels_every_group(teacher):
    from flatcontact.training.recipe import sio2_recipe

    frames = sio2_recipe(seed=1, calc=teacher, scale=0.05)
    groups = {a.info["config_type"] for a in frames}
    assert groups == {
        "quartz_strain",
        "quartz_relaxed_strain",
        "quartz_pressure",
        "polymorph",
        "md",
        "slab",
        "dense_slab",
        "defect",
        "close_contact",
    }
    assert all(a.pbc.all() for a in frames)
    labelled = label_frames(frames[:5], teacher)
    assert all(np.isfinite(a.calc.results["forces"]).all() for a in labelled)
