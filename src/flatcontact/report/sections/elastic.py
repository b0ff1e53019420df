"""The report's tables of the elastic stage: the crystal's lattice, Cij and contact moduli."""

from __future__ import annotations

import math

from flatcontact.report.format import fmt
from flatcontact.report.html import Table

#: Cij below this fraction of the largest are zero by the crystal's symmetry (not listed).
CIJ_ZERO_FRACTION = 1e-3


def crystal_name(doc: dict) -> str:
    """The bulk crystal ``elastic.json`` was computed for (its ``crystal`` record)."""
    record = doc.get("crystal")
    name = record.get("crystal") if isinstance(record, dict) else record
    if not name or name == "alpha-quartz":
        return "α-quartz"
    return str(name)


def lattice_rows(doc: dict) -> list[tuple[str, str]]:
    """The relaxed lattice of ``doc``: α-quartz's a, c; another crystal's cell parameters
    (``cellpar``: a, b, c in Å, angles in degrees), with the cubic a of an fcc crystal
    (its primitive cell's a·√2)."""
    if "a_angstrom" in doc:
        return [("a, c (Å)", f"{fmt(doc.get('a_angstrom'))}, {fmt(doc.get('c_angstrom'))}")]
    cellpar = doc.get("cellpar")
    if not cellpar:
        return []
    a, b, c, alpha, beta, gamma = cellpar
    rows = [
        ("cell a, b, c (Å)", f"{fmt(a)}, {fmt(b)}, {fmt(c)}"),
        ("cell angles α, β, γ (°)", f"{alpha:.4g}, {beta:.4g}, {gamma:.4g}"),
    ]
    if crystal_name(doc).startswith("fcc "):
        rows.insert(0, ("cubic lattice parameter a (Å)", fmt(a * math.sqrt(2.0))))
    return rows


def cij_rows(doc: dict) -> list[tuple[str, str]]:
    """The named Cij (``cij_gpa``, α-quartz's trigonal set), else the nonzero upper triangle
    of the Voigt tensor ``tensor_gpa`` (GPa)."""
    if doc.get("cij_gpa"):
        return [(f"{k} (GPa)", fmt(v)) for k, v in doc["cij_gpa"].items()]
    tensor = doc.get("tensor_gpa") or []
    largest = max((abs(v) for row in tensor for v in row), default=0.0)
    return [
        (f"C{i + 1}{j + 1} (GPa)", fmt(float(tensor[i][j])))
        for i in range(len(tensor))
        for j in range(i, len(tensor))
        if abs(tensor[i][j]) > CIJ_ZERO_FRACTION * largest
    ]


def elastic_tables(doc: dict | None) -> list[Table]:
    """The elastic stage's lattice, Cij and moduli (``doc``: its ``elastic.json``; ``None``
    when the stage did not run: no table), shown in the contact section, headed by the bulk
    crystal it was computed for."""
    if doc is None:
        return []
    moduli = doc.get("moduli_gpa", {})
    model = doc.get("potential")
    title = crystal_name(doc) + (f" with {model}" if model else " with the potential")
    return [
        Table(
            (title, "value"),
            [
                *lattice_rows(doc),
                *cij_rows(doc),
                *((f"{k} (GPa)" if k != "poisson_ratio" else k, fmt(v)) for k, v in moduli.items()),
            ],
        )
    ]
