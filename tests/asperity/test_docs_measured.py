"""docs/asperity.md's measured table is the rows of the stored asperity.json files
(docs/measured/asperity/<case>/: the run's asperity.json, its config.yaml, the wall time)."""

import json
from pathlib import Path

from flatcontact.report.sections.asperity import markdown_table, measured_row

ROOT = Path(__file__).parents[2]
MEASURED = ROOT / "docs" / "measured" / "asperity"
CASES = {"cu-lj": "Cu(111), LJ across", "cu-eam": "Cu(111), EAM across (bonded)"}


def measured_table() -> str:
    """The table as docs/asperity.md holds it (regenerate it with this function)."""
    rows = []
    for kind, label in CASES.items():
        folders = sorted(
            MEASURED.glob(f"{kind}-R*"), key=lambda p: float(p.name.rsplit("-R", 1)[1])
        )
        for folder in folders:
            doc = json.loads((folder / "asperity.json").read_text())
            wall = float((folder / "wall.txt").read_text().split()[0])
            rows.append(measured_row(label, doc, wall))
    return markdown_table(rows)


def test_the_docs_table_is_the_stored_measurements():
    assert len(list(MEASURED.glob("cu-*-R*"))) >= 4
    assert measured_table() in (ROOT / "docs" / "asperity.md").read_text()


def test_each_stored_case_ran_with_its_example_interface():
    for folder in MEASURED.glob("cu-*-R*"):
        doc = json.loads((folder / "asperity.json").read_text())
        config = (folder / "config.yaml").read_text()
        assert f"radius_angstrom: {doc['radius_angstrom']}" in config
        assert ("coupling: lj" in config) == folder.name.startswith("cu-lj")
        assert all(r["atoms"] is not None for r in doc["peak_shear_stress_mpa"])
