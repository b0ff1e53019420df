"""docs/asperity.md's measured table is the rows of the stored asperity.json files
(docs/measured/asperity/<case>/: the run's asperity.json, its config.yaml, the wall time),
as ``python docs/gen_asperity_table.py`` writes it."""

import json

from docs.gen_asperity_table import MEASURED, PAGE, folders, page_with_table


def test_the_docs_table_is_the_stored_measurements():
    assert len(folders()) >= 4
    text = PAGE.read_text(encoding="utf-8")
    assert page_with_table(text) == text, "rerun: python docs/gen_asperity_table.py"


def test_each_stored_case_ran_with_its_example_interface():
    cases = list(MEASURED.glob("cu-*-R*"))
    assert {p for _, p in folders()} == set(cases)
    for folder in cases:
        doc = json.loads((folder / "asperity.json").read_text())
        config = (folder / "config.yaml").read_text()
        assert f"radius_angstrom: {doc['radius_angstrom']}" in config
        assert ("coupling: lj" in config) == folder.name.startswith("cu-lj")
        assert ("-sphere-" in folder.name) == (doc["geometry"] == "sphere")
        assert all(r["atoms"] is not None for r in doc["peak_shear_stress_mpa"])
