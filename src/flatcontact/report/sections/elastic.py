"""The report's tables of the elastic stage: the crystal's lattice, Cij and contact moduli."""

from __future__ import annotations

from flatcontact.report.format import fmt
from flatcontact.report.html import Table


def elastic_tables(doc: dict | None) -> list[Table]:
    """The elastic stage's lattice, Cij and moduli (``doc``: its ``elastic.json``; ``None``
    when the stage did not run: no table), shown in the contact section."""
    if doc is None:
        return []
    cij = doc.get("cij_gpa", {})
    moduli = doc.get("moduli_gpa", {})
    return [
        Table(
            ("α-quartz with the potential", "value"),
            [
                ("a, c (Å)", f"{fmt(doc.get('a_angstrom'))}, {fmt(doc.get('c_angstrom'))}"),
                *((f"{k} (GPa)", fmt(v)) for k, v in cij.items()),
                *((f"{k} (GPa)" if k != "poisson_ratio" else k, fmt(v)) for k, v in moduli.items()),
            ],
        )
    ]
