"""The report's section on the approximant study of the run's interface
(``report.approximant_study``).

An ordinary run computes one commensurate cell (a coincidence lock, a commensurate twist, or
an interface commensurate by construction). ``flatcontact study approximants`` of the same
interface computes the sequence of cells toward the incommensurate contact
(docs/incommensurate.md); this section tables that study beside the run: per cell its size,
twist and strain, τ0, corrugation, whether it is resolved above the noise floor, the gates
that fired and, when the study compared with the experiment (``contact.experiment.compare``),
its collapse stress. The row whose cell has the run's atoms and twist is marked. Every
number is read from the study's ``study.json`` and ``experiment_collapse.json``; nothing is
computed here.
"""

from __future__ import annotations

import math
from pathlib import Path

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import quoted, read_json_file
from flatcontact.foundation.layout import EXPERIMENT_COLLAPSE_JSON
from flatcontact.foundation.result_json import KINDS, ContractError, check_keys
from flatcontact.report.format import fmt
from flatcontact.report.html import Section, Table

#: Largest study.json read (a study of thousands of cells is a few MB).
MAX_STUDY_BYTES = 64 * 1024 * 1024


def read_approximant_study(path: str | Path, field: str = "report.approximant_study") -> dict:
    """The approximant study's ``study.json`` at ``path`` and, beside it, its
    ``experiment_collapse.json`` if there is one (key ``experiment_collapse``).

    Raises
    ------
    InputError
        One line naming ``field`` and the file when it is not an approximant study's record.
    """
    path = Path(path)
    doc = _json(path, field)
    if not isinstance(doc, dict) or doc.get("study") != "approximants":
        kind = doc.get("study") if isinstance(doc, dict) else type(doc).__name__
        raise InputError(
            f"{field}: {path}: expected the study.json of 'flatcontact study approximants', "
            f"got study {kind!r}"
        )
    if not isinstance(doc.get("cells"), list) or not doc["cells"]:
        raise InputError(f"{field}: {path}: the study has no cells")
    _check(
        path, field, lambda: [_check_cell(c, f"cells[{i}].") for i, c in enumerate(doc["cells"])]
    )
    collapse = path.parent / EXPERIMENT_COLLAPSE_JSON
    if collapse.exists():
        rows = _json(collapse, field)
        _check(collapse, field, lambda: _check_collapse(rows))
        doc = {**doc, "experiment_collapse": rows}
    return doc


#: What a cell of the approximant study's ``cells`` holds where it ran (a refused cell:
#: ``label`` and ``error``).
CELL_KEYS = {
    "twist_deg": "number?",
    "strain_percent_slab1": "strains",
    "strain_percent_slab2": "strains",
    "tau0_mpa": "number?",
    "barrier_mev_per_a2": "number?",
    "resolved": "flag",
    "gates": "mapping?",
}


def _check(path: Path, field: str, check) -> None:
    try:
        check()
    except ContractError as exc:
        raise InputError(
            f"{field}: {quoted(path)}: {exc}; expected the files of 'flatcontact study "
            "approximants' (rerun the study)"
        ) from None


def _check_cell(cell, where: str) -> None:
    check_keys(cell, {"label": "text"}, {"error": "text", "n_atoms": "count"}, where)
    if "error" not in cell:
        check_keys(cell, {"n_atoms": "count"}, CELL_KEYS, where)
        check_keys(cell.get("gates") or {}, {}, {"fired": "texts"}, f"{where}gates.")


def _check_collapse(rows) -> None:
    check_keys(rows, {"cells": "list"}, {"p0_gpa": "number", "measured_mpa": "mapping"})
    for i, row in enumerate(rows["cells"]):
        where = f"cells[{i}]."
        check_keys(
            row,
            {"label": "text"},
            {"collapse_stress_mpa": "number?", "ratio_to_measured": "mapping?"},
            where,
        )
        for k, v in (row.get("ratio_to_measured") or {}).items():
            if not KINDS["number"][0](v):
                raise ContractError(f"'{where}ratio_to_measured.{k}' is {v!r}, not a finite number")


def _json(path: Path, field: str):
    try:
        return read_json_file(path, "study file", MAX_STUDY_BYTES)
    except InputError as exc:
        raise InputError(f"{field}: {exc}") from None


def this_run_label(doc: dict, build: dict | None) -> str | None:
    """The study's cell that is the run's own (same atoms and, to 1e-3°, the same twist of
    ``build.json``'s lock), or None."""
    rec = (build or {}).get("recipe")
    match = rec.get("match") if isinstance(rec, dict) else None
    if not isinstance(match, dict):
        return None
    n_atoms = match.get("n_atoms")
    twist = rec.get("twist_angle_deg")
    for cell in doc["cells"]:
        if cell.get("n_atoms") != n_atoms:
            continue
        if twist is not None and abs(float(cell.get("twist_deg", math.nan)) - float(twist)) > 1e-3:
            continue
        return cell.get("label")
    return None


def _strain(cell: dict) -> str:
    s1, s2 = cell.get("strain_percent_slab1"), cell.get("strain_percent_slab2")
    return f"{fmt(s1)} / {fmt(s2)}"


def approximant_study_section(doc: dict, path: str, build: dict | None = None) -> Section:
    """The study ``doc`` (:func:`read_approximant_study` of ``path``) as a report section,
    the run's own cell marked (:func:`this_run_label`)."""
    collapse = {r["label"]: r for r in (doc.get("experiment_collapse") or {}).get("cells", [])}
    measured = (doc.get("experiment_collapse") or {}).get("measured_mpa") or {}
    own = this_run_label(doc, build)
    headers = [
        "cell",
        "atoms",
        "twist (°)",
        "largest strain slab 1 / 2 (%)",
        "τ0 (MPa)",
        "corrugation (meV/Å²)",
        "resolved",
        "gates fired",
    ]
    p0 = (doc.get("experiment_collapse") or {}).get("p0_gpa")
    if collapse:
        headers += [f"collapse at p0 = {p0:g} GPa (MPa)", *(f"÷ {k}" for k in measured)]
    rows = []
    for cell in doc["cells"]:
        label = cell["label"] + (" (this run's cell)" if cell["label"] == own else "")
        if "error" in cell:
            rows.append((label, fmt(cell.get("n_atoms")), "", "", "refused: " + cell["error"]))
            continue
        row = [
            label,
            str(cell.get("n_atoms")),
            f"{float(cell.get('twist_deg', math.nan)):.4f}",
            _strain(cell),
            fmt(cell.get("tau0_mpa")),
            fmt(cell.get("barrier_mev_per_a2")),
            "yes" if cell.get("resolved") else "no (upper bound)",
            ", ".join((cell.get("gates") or {}).get("fired") or []) or "none",
        ]
        if collapse:
            c = collapse.get(cell["label"], {})
            value = c.get("collapse_stress_mpa")
            ratios = c.get("ratio_to_measured") or {}
            row += [
                fmt(value) if value is not None else (c.get("reason") or "—"),
                *(f"{ratios[k]:.3g}" if k in ratios else "" for k in measured),
            ]
        rows.append(tuple(row))
    where = (
        f"its cell {own} is this run's (same atoms and twist)"
        if own
        else "none of its cells has this run's atoms and twist (another structure or "
        "another sequence: compare with care)"
    )
    notes = list(doc.get("caveats") or [])
    notes.append(
        "Each cell is a periodic, commensurate contact: its τ0 and corrugation are the "
        "interior of a contact locked at that angle or strain; the rim, edges and defects of a "
        "real finite contact are in none (docs/incommensurate.md)."
    )
    return Section(
        "Toward the incommensurate contact: the approximant study",
        paragraphs=[
            f"The approximant study {path} ({len(doc['cells'])} cells, relax_mode "
            f"{doc.get('relax_mode', '?')}) computes the sequence of commensurate cells of this "
            f"interface toward the incommensurate contact; {where}. Cells whose corrugation is "
            "not resolved above the energy noise floor have no laws (their corrugation is an "
            "upper bound)."
        ],
        notes=notes,
        tables=[
            Table(
                tuple(headers),
                rows,
                "The approximant study's cells (study.json"
                + (", experiment_collapse.json" if collapse else "")
                + ")",
            )
        ],
    )
