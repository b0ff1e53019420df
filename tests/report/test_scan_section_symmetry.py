"""The report's scan section says how many points a reduced scan relaxed and its group."""

from pathlib import Path

from flatcontact.report.sections.scan import scan_section

BASE = {
    "points_total": 468,
    "points_done": 468,
    "converged": 468,
    "force_calls_total": 470,
    "thickness_angstrom": [6.0, 6.5],
    "adhesion": {},
    "notes": [],
    "warnings": [],
}


def _rows(scan):
    return dict(scan_section(scan, Path("/nonexistent")).tables[0].rows)


def test_reduced_scan_rows_name_the_relaxed_points_and_the_group():
    rows = _rows(
        {**BASE, "computed_points": 132, "symmetry": {"order": 6, "computed_in_full": False}}
    )
    assert rows["shift-space group order"] == "6"
    assert rows["relaxed points"].startswith("132 relaxed")
    fell_back = _rows(
        {**BASE, "computed_points": 468, "symmetry": {"order": 6, "computed_in_full": True}}
    )
    assert "symmetry broken" in fell_back["relaxed points"]


def test_full_and_older_scans_have_no_symmetry_rows():
    full = {**BASE, "computed_points": 468, "symmetry": {"order": 1, "operations": []}}
    for scan in (BASE, full):
        rows = _rows(scan)
        assert "relaxed points" not in rows and rows["grid points"] == "468 of 468"
