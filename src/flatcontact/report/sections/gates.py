"""The box at the top of the report: which numbers are not to be trusted and why.

From ``summary.json["gates"]`` (:mod:`flatcontact.stages.gates`): every validity gate that
fired and was passed with ``contact.accept_untrusted``, and the notes (a negative slope used
as fitted). A run where nothing fired and nothing is noted has no such section.
"""

from __future__ import annotations

from flatcontact.report.html import Section

#: What each gate makes untrustworthy (the numbers downstream of it).
UNTRUSTED = {
    "in_slab_slip": "the ISPES, τ and σ_MSS at every load, the load laws and every contact result",
    "broken_symmetry": "the ISPES, τ and σ_MSS at the loads named, the load laws and every "
    "contact result",
    "load_fold": "τ and σ_MSS beyond the fold, the load laws and every contact result",
    "negative_slope": "the load laws (k or μ) and every contact result",
    "degenerate_minima": "τ at the loads named, the law τ = k·P + τ0 and every contact result",
}


def gates_section(contact: dict) -> Section | None:
    """The section of the gates recorded by the contact stage, or None if there is nothing
    to say."""
    gates = contact.get("gates") or {}
    fired = gates.get("fired") or []
    notes = gates.get("notes") or []
    if not fired and not notes:
        return None
    boxes = [
        f"Not to be trusted: {UNTRUSTED.get(f['gate'], 'the results')}. Gate {f['gate']} "
        f"fired and was passed with contact.accept_untrusted: {f['message']}"
        for f in fired
    ]
    boxes += [f"Note: {n}" for n in notes]
    paragraphs = []
    if fired:
        paragraphs.append(
            "The validity gates checked before the contact stage fired; the run went on "
            "because contact.accept_untrusted lists them. The figures and tables below are "
            "computed from these numbers."
        )
    return Section(
        "Numbers not to be trusted" if fired else "Notes on the laws", paragraphs, notes=boxes
    )
