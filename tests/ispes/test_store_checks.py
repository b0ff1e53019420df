"""The store contract on rows built in the test (no database): what is kept, what is repaired."""

from __future__ import annotations

import numpy as np
import pytest

from flatcontact.ispes.store_checks import (
    PointStoreRepaired,
    grid_shape,
    repair_rows,
    resolved_defect,
    row_defect,
    settings_difference,
)

N_A, N_B, Z = 4, 2, [9.0, 10.5]
SETTINGS = {"grid": {"n_a": N_A, "n_b": N_B}}
RESOLVED = {"thickness_angstrom": Z, "a1": [3.0, 0.0], "a2": [0.0, 3.0], "potential_label": "toy"}


class Row:
    """The part of an ``ase.db`` row the checks read."""

    def __init__(self, id, i_a, i_b, i_z, energy=-1.0, n_atoms=2, **changes):
        self.id = id
        self.key_value_pairs = {
            "i_a": i_a,
            "i_b": i_b,
            "i_z": i_z,
            "shift_a": i_a / N_A,
            "shift_b": i_b / N_B,
            "thickness": Z[i_z] if 0 <= i_z < len(Z) else 0.0,
            "normal_stress_gpa": 0.1,
            "force_calls": 3,
            "converged": True,
            **changes,
        }
        self.energy = energy
        self.positions = np.zeros((n_atoms, 3))

    def get(self, key, default=None):
        if key == "energy":
            return self.energy
        if key == "positions":
            return self.positions
        return self.key_value_pairs.get(key, default)

    def __getattr__(self, key):
        return self.key_value_pairs[key]


class Db:
    def __init__(self):
        self.deleted = []

    def delete(self, ids):
        self.deleted.extend(ids)


def test_grid_shape_from_settings_and_resolved():
    assert grid_shape(SETTINGS, RESOLVED) == (N_A, N_B, len(Z))
    assert grid_shape(SETTINGS, None) == (N_A, N_B, 0)  # rows without thicknesses all fail
    assert grid_shape({}, RESOLVED) == (None, None, len(Z))


def test_settings_difference_names_the_first_key():
    assert settings_difference({"a": {"b": 1, "c": 2}}, {"a": {"b": 1, "c": 2}}) is None
    assert settings_difference({"a": {"b": 1}}, {"a": {"b": 2}}) == "a.b: 1 in the store vs 2 now"
    assert "<absent>" in settings_difference({"a": 1}, {})


def test_resolved_defects():
    assert resolved_defect(None) is None and resolved_defect(RESOLVED) is None
    assert "repeats" in resolved_defect({**RESOLVED, "thickness_angstrom": [9.0, 9.0]})
    assert "'a1'" in resolved_defect({**RESOLVED, "a1": [float("nan"), 0.0]})


def test_row_defects():
    shape = grid_shape(SETTINGS, RESOLVED)
    assert row_defect(Row(1, 3, 1, 1), shape, Z, 2) is None
    assert "outside the grid" in row_defect(Row(1, N_A, 0, 0), shape, Z, 2)
    assert "outside the grid" in row_defect(Row(1, -1, 0, 0), shape, Z, 2)
    assert "differs from the grid" in row_defect(Row(1, 1, 0, 0, shift_a=0.3), shape, Z, 2)
    assert "energy" in row_defect(Row(1, 1, 0, 0, energy=float("inf")), shape, Z, 2)
    assert "2 × 3" in row_defect(Row(1, 1, 0, 0, n_atoms=3), shape, Z, 2)
    assert "start" in row_defect(Row(1, 1, 0, 0, start="9,0,0"), shape, Z, 2)


def test_repair_keeps_sound_rows_and_drops_the_rest():
    rows = [
        Row(1, 0, 0, 0),
        Row(2, 0, 0, 0),  # identical copy of row 1: dropped without a warning
        Row(3, 1, 0, 1, shift_a=0.5),  # shift of another index
        Row(4, 2, 1, 0, energy=-1.0),
        Row(5, 2, 1, 0, energy=-2.0),  # two different rows for one point: both go
    ]
    db = Db()
    with pytest.warns(PointStoreRepaired, match="3 stored point"):
        kept = repair_rows(db, rows, SETTINGS, RESOLVED, 2, "points.db")
    assert list(kept) == [(0, 0, 0)] and kept[(0, 0, 0)].id == 1
    assert sorted(db.deleted) == [2, 3, 4, 5]


def test_settings_difference_names_the_model_field_as_the_run_settings_do():
    """The store keeps the model's fingerprint nested (``potential.potential.model...``); a
    difference names the setting the user wrote (``potential.calculator.kwargs.x``)."""
    import json

    from flatcontact.potentials.engines import calculator_factory
    from flatcontact.potentials.model import InteractionModel

    def settings(**kwargs):
        model = InteractionModel(calculator={"target": "ase.calculators.emt:EMT", "kwargs": kwargs})
        return {"potential": json.loads(calculator_factory(model).fingerprint)}

    said = settings_difference(settings(asap_cutoff=False), settings(asap_cutoff=True))
    assert said == "potential.calculator.kwargs.asap_cutoff: false in the store vs true now"
    old, new = settings(), settings()
    old["potential"]["potential"]["files_sha256"] = {"Cu.eam": "a" * 8}
    new["potential"]["potential"]["files_sha256"] = {"Cu.eam": "b" * 8}
    said = settings_difference(old, new)
    assert said.startswith("the content (SHA-256) of potential file Cu.eam: ")
    assert "potential.potential" not in said
