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


def test_the_report_section_states_the_stored_ramp(tmp_path):
    """The measured sphere's ramp in the report: one row per amplitude with the atoms' k′, and
    the sentence's fall of k′ over the ramp computed from the same rows."""
    from flatcontact.report.format import fmt
    from flatcontact.report.sections.asperity import asperity_section

    doc = json.loads((MEASURED / "cu-lj-sphere-R50" / "asperity.json").read_text())
    rows = doc["ramp"][0]["amplitudes"]
    section = asperity_section(doc, tmp_path)
    ramp_table = section.tables[1]
    assert [r[4] for r in ramp_table.rows] == [fmt(r["atoms_lockin_n_per_m"]) for r in rows]
    fall = rows[-1]["atoms_lockin_n_per_m"] / rows[0]["atoms_lockin_n_per_m"]
    assert f"falls to {fall:.2f}" in " ".join(section.paragraphs)
    # the model has no steady cycle where the atoms' Q_amp passes its Q_peak
    for r, cells in zip(rows, ramp_table.rows, strict=True):
        assert (cells[6] == "–") == (r["q_amp_over_q_peak"] >= 1.0)
