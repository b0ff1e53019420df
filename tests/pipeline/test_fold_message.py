"""A load that is not monotonic where the scan recorded folds is named as a recorded
fold (``scan.json`` ``load_folds``) with both causes and their remedies, in one line."""

from __future__ import annotations

import json

import pytest

from flatcontact.foundation.errors import InputError
from flatcontact.stages.analyze import _folds_named

NOT_MONOTONIC = (
    "grid column at shift (0.333, 0.167): -(1/A) dU/dz is not monotonic on the repulsive "
    "branch: p = 0.268 GPa at z = 13.33 Å, 1.23 GPa at z = 13.46 Å"
)


#: The required keys of a ``scan.json`` (flatcontact.foundation.result_json's contract) around the folds.
SCAN_RECORD = {
    "points_total": 36,
    "points_done": 36,
    "force_calls_total": 500,
    "thickness_angstrom": [13.2, 13.33, 13.46, 13.6],
    "area_angstrom2": 20.9,
}


def test_a_recorded_fold_is_named_with_its_column_and_the_physical_remedy(tmp_path):
    scan = tmp_path / "scan.json"
    fold = {"column": "grid column at shift (0.333, 0.167)", "z_angstrom": 13.46, "p_gpa": 1.23}
    scan.write_text(json.dumps({**SCAN_RECORD, "load_folds": [fold, fold]}))
    with pytest.raises(InputError) as info, _folds_named(scan):
        raise InputError(NOT_MONOTONIC)
    text = str(info.value)
    assert text.startswith(NOT_MONOTONIC) and "\n" not in text
    assert "2 folding column(s)" in text and "z = 13.46 Å" in text
    assert "scan.relax_mode: normal" in text and "scan.fmax_ev_per_angstrom" in text


@pytest.mark.parametrize("record", [None, {}, {"load_folds": []}, "not json"])
def test_without_a_recorded_fold_the_message_is_unchanged(tmp_path, record):
    scan = tmp_path / "scan.json"
    if record is not None:
        scan.write_text(record if isinstance(record, str) else json.dumps(record))
    with pytest.raises(InputError) as info, _folds_named(scan):
        raise InputError(NOT_MONOTONIC)
    assert str(info.value) == NOT_MONOTONIC
