"""The box of the validity gates at the top of the report (flatcontact.report.sections.gates)."""

from __future__ import annotations

from flatcontact.report.html import render_html
from flatcontact.report.sections.gates import gates_section


def test_an_overridden_gate_puts_a_box_above_the_figures():
    contact = {
        "gates": {
            "fired": [
                {"gate": "in_slab_slip", "message": "planes slid 0.38 Å", "overridden": True}
            ],
            "overridden": ["in_slab_slip"],
            "notes": ["k = -0.5 MPa/GPa is negative but not significantly"],
            "not_checked": [],
        }
    }
    section = gates_section(contact)
    assert section.title == "Numbers not to be trusted"
    assert any("in_slab_slip" in n and "planes slid 0.38 Å" in n for n in section.notes)
    assert any("not significantly" in n for n in section.notes)
    page = render_html("t", [section])
    assert page.index("Numbers not to be trusted") < page.index("in_slab_slip")
    assert 'class="note"' in page


def test_a_clean_run_has_no_box():
    assert gates_section({}) is None
    assert gates_section({"gates": {"fired": [], "notes": [], "overridden": []}}) is None
    notes_only = gates_section({"gates": {"fired": [], "notes": ["a note"]}})
    assert notes_only.title == "Notes on the laws" and notes_only.notes == ["Note: a note"]
