"""Stackings are named by geometry, not energy order: a potential whose intrinsic stacking
fault lies below the perfect crystal (γ_isf < 0, :mod:`tests.analysis.fault_favoured`, an ASE
calculator) on a continued fcc(111) crystal. The zero shift is the perfect stacking whatever
its energy, the fault is named the fault although it is the global minimum, and W is taken at
the perfect stacking (scan.json says so)."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from flatcontact.config.load import build_config
from flatcontact.foundation.layout import BUILD_JSON, FRICTION_CSV, SCAN_JSON
from flatcontact.ispes.work_of_separation import AT_PERFECT_STACKING
from flatcontact.pipeline import Pipeline
from flatcontact.report.sections.analysis import stacking_rows
from flatcontact.report.stacking_names import stacking_family

CONFIG = {
    "structure": {"kind": "fcc111", "element": "Cu", "layers": 3},
    "potential": {"calculator": {"target": "tests.analysis.fault_favoured:fault_favoured"}},
    "scan": {
        "grid": [6, 6],
        "p_range_gpa": {"lo_gpa": 0.0, "hi_gpa": 0.5, "n": 3},
        "relax_mode": "normal",
        "workers": 1,
    },
    "analysis": {"p_gpa": [0.0, 0.2]},
    "contact": {"contact_modulus_gpa": 50.0, "shear_modulus_gpa": 40.0},  # not reached
}


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    root = tmp_path_factory.mktemp("fault")
    with Pipeline(build_config(CONFIG), root) as pipe:
        pipe.build()
        pipe.scan()
        pipe.analyze()
    return root


def _stage(root, name):
    return next(root.glob(f"*-{name}"))


@pytest.mark.slow
def test_the_fault_below_the_crystal_keeps_its_name(run):
    build = json.loads((_stage(run, "build") / BUILD_JSON).read_text())
    assert stacking_family(build) == "gamma"
    # the build relaxed the lattice with the ASE calculator: its fcc a, not ASE's 3.61 Å
    slab = build["lattice"]["slabs"]["slab1"]
    assert slab["potential_lengths_angstrom"][0] * np.sqrt(2) == pytest.approx(3.583, abs=2e-3)
    table = pd.read_csv(_stage(run, "analyze") / FRICTION_CSV)
    row = next(table.itertuples())
    energies = dict(
        (k, float(v))
        for k, v in (item.split("=") for item in row.stacking_energies_mev_per_a2.split(";"))
    )
    perfect = row.zero_shift_stacking
    fault = ({"AB", "BA"} - {perfect}).pop()
    assert perfect in ("AB", "BA") and fault in energies
    assert energies[fault] < energies[perfect]  # γ_isf < 0: the fault is the global minimum
    named = stacking_rows(table, "gamma")[0][1]
    assert named.startswith("intrinsic stacking fault 0, perfect stacking ")
    gamma_isf = energies[fault] - energies[perfect]
    assert f"perfect stacking {-gamma_isf:.4g}" in named


@pytest.mark.slow
def test_w_is_taken_at_the_perfect_stacking_not_at_the_fault(run):
    adhesion = json.loads((_stage(run, "scan") / SCAN_JSON).read_text())["adhesion"]
    assert adhesion["work_of_separation_stacking"] == AT_PERFECT_STACKING
    assert (adhesion["work_of_separation_shift_a"], adhesion["work_of_separation_shift_b"]) == (
        0.0,
        0.0,
    )
