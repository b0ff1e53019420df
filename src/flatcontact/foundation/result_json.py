"""Checked readers of the JSON files a stage writes and a later stage, the report or a study
reads back: ``scan.json``, ``analyze.json``, ``laws.json``, ``elastic.json``,
``summary.json``.

A stage records the SHA-256 of each output (:mod:`flatcontact.foundation.rundir`), so a file changed
after its stage is recomputed. What is read back must still follow the file's contract,
whatever put it there (a truncated write beside an edited record, a bug, a file copied from
another run), the way ``ispes.nc`` (:mod:`flatcontact.ispes.contract`) and the netCDF
results (:mod:`flatcontact.stages.result_files`) are checked. :func:`read_result_json`
checks, before a value is used:

- the file: a regular file (a FIFO is refused before it is opened), at most
  :data:`MAX_BYTES`, UTF-8, one complete JSON document (:func:`flatcontact.foundation.fileio.
  read_json_file`);
- the document: a mapping holding the contract's required keys, each of its kind
  (:data:`KINDS`: finite numbers, counts, text, mappings, lists of finite numbers); keys the
  contract does not name are accepted (files gain optional fields over versions);
- its consistency with what the caller knows: the stage record's inputs (``scan.json``'s
  points are the record's grid times its thicknesses) and the run's settings (``laws.json``'s
  energy form, ``summary.json``'s loads p0).

A file that fails is one :class:`~flatcontact.foundation.errors.InputError` line naming it and the
first defect, with the way to recompute it.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import quoted, read_json_file

#: Largest JSON result read (bytes): the paper's run writes < 200 kB per file.
MAX_BYTES = 64_000_000
#: The law coefficients every laws block holds.
LAW_KEYS = ("k_mpa_per_gpa", "tau0_mpa", "mu_mpa_per_gpa", "sigma0_mpa")
#: Interval fields that must be finite numbers where an interval gives them.
INTERVAL_NUMBERS = ("value", "low", "high", "half_width")


def _finite(v: Any) -> bool:
    return isinstance(v, int | float) and not isinstance(v, bool) and math.isfinite(v)


#: kind -> (test, what the kind is, for the message)
KINDS: dict[str, tuple[Callable[[Any], bool], str]] = {
    "number": (_finite, "a finite number"),
    "number?": (lambda v: v is None or _finite(v), "a finite number or null"),
    "count": (lambda v: isinstance(v, int) and not isinstance(v, bool) and v >= 0, "a count"),
    "text": (lambda v: isinstance(v, str), "text"),
    "mapping": (lambda v: isinstance(v, dict), "a mapping"),
    "mapping?": (lambda v: v is None or isinstance(v, dict), "a mapping or null"),
    "list": (lambda v: isinstance(v, list), "a list"),
    "numbers": (
        lambda v: isinstance(v, list) and bool(v) and all(_finite(x) for x in v),
        "a non-empty list of finite numbers",
    ),
    "numbers?": (
        lambda v: v is None or (isinstance(v, list) and all(_finite(x) for x in v)),
        "a list of finite numbers or null",
    ),
    "strains": (
        lambda v: v is None or _finite(v) or (isinstance(v, list) and all(_finite(x) for x in v)),
        "a finite number, a list of them or null",
    ),
    "flag": (lambda v: isinstance(v, bool), "true or false"),
    "texts": (
        lambda v: isinstance(v, list) and all(isinstance(x, str) for x in v),
        "a list of text",
    ),
}


class ContractError(ValueError):
    """One defect of a document (the reader turns it into the file's InputError line)."""


@dataclass(frozen=True)
class JsonContract:
    """What one JSON file must hold: ``required`` key -> kind (:data:`KINDS`), ``optional``
    key -> kind where present, and ``check(doc, expect)`` for the rest (raising
    :class:`ContractError`)."""

    name: str
    required: Mapping[str, str]
    optional: Mapping[str, str] = field(default_factory=dict)
    check: Callable[[dict, Mapping[str, Any]], None] | None = None


def check_keys(doc: Any, required: Mapping[str, str], optional: Mapping[str, str], where=""):
    """Raise :class:`ContractError` unless ``doc`` is a mapping whose ``required`` keys are
    present and of their kind, and whose ``optional`` keys are of their kind where present."""
    if not isinstance(doc, dict):
        raise ContractError(f"{where or 'the document'} is {type(doc).__name__}, not a mapping")
    for key, kind in (*required.items(), *optional.items()):
        if key not in doc:
            if key in required:
                raise ContractError(f"'{where}{key}' missing")
            continue
        test, what = KINDS[kind]
        if not test(doc[key]):
            raise ContractError(f"'{where}{key}' is {_shown(doc[key])}, expected {what}")


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def _laws_block(block: Any, where: str) -> None:
    check_keys(block, dict.fromkeys(LAW_KEYS, "number"), {"intervals": "mapping"}, where)
    for coef, iv in (block.get("intervals") or {}).items():
        here = f"{where}intervals.{coef}."
        check_keys(
            iv,
            {},
            {**dict.fromkeys(INTERVAL_NUMBERS, "number"), "components": "mapping"},
            here,
        )
        for part, v in (iv.get("components") or {}).items():
            if part == "grid" and v is None:  # the run could not estimate its grid's error
                continue
            if not _finite(v):
                raise ContractError(f"'{here}components.{part}' is {_shown(v)}, not finite")


def _check_laws(doc: dict, expect: Mapping[str, Any]) -> None:
    form = doc["energy_form"]
    if form not in ("internal", "enthalpy"):
        raise ContractError(f"'energy_form' is {form!r}, expected internal or enthalpy")
    want = expect.get("energy_form")
    if want is not None and form != want:
        raise ContractError(f"'energy_form' is {form!r}, the settings ask for {want!r}")
    _laws_block(doc, "")
    for f in ("internal", "enthalpy"):
        if f in doc:
            _laws_block(doc[f], f"{f}.")
    if isinstance(doc.get(form), dict):
        for key in LAW_KEYS:
            if doc[key] != doc[form][key]:
                raise ContractError(
                    f"'{key}' {doc[key]!r} is not the {form} block's {doc[form][key]!r}"
                )


def _check_scan(doc: dict, expect: Mapping[str, Any]) -> None:
    if doc.get("points_done", 0) > doc["points_total"]:
        raise ContractError(
            f"'points_done' {doc['points_done']} exceeds 'points_total' {doc['points_total']}"
        )
    grid = expect.get("grid")
    lattice = doc.get("shift_lattice")
    if grid is not None and isinstance(lattice, dict) and isinstance(lattice.get("grid"), list):
        # a coincidence cell scans scan.grid's coprime n x n (the scan stage's shift_lattice
        # record states both); the record's request must still be the stage record's grid
        if lattice.get("grid_requested") != [int(v) for v in grid]:
            raise ContractError(
                f"'shift_lattice.grid_requested' {lattice.get('grid_requested')} is not the "
                f"stage record's grid {list(grid)}"
            )
        grid = lattice["grid"]
    if grid is not None and "thickness_angstrom" in doc:
        want = int(grid[0]) * int(grid[1]) * len(doc["thickness_angstrom"])
        if doc["points_total"] != want:
            raise ContractError(
                f"'points_total' {doc['points_total']} is not the stage record's grid "
                f"{grid[0]}x{grid[1]} times its {len(doc['thickness_angstrom'])} thicknesses"
            )
    if doc.get("area_angstrom2", 1.0) <= 0:
        raise ContractError(f"'area_angstrom2' {doc['area_angstrom2']!r} is not positive")
    adhesion = doc.get("adhesion")
    if adhesion:
        check_keys(adhesion, {}, {"work_of_separation_j_per_m2": "number?"}, "adhesion.")


def _check_summary(doc: dict, expect: Mapping[str, Any]) -> None:
    params = doc["parameters"]
    for key, v in params.items():
        if not (v is None or _finite(v) or isinstance(v, str)):
            raise ContractError(f"'parameters.{key}' is {_shown(v)}, not a finite number")
    for i, row in enumerate(doc["results"]):
        check_keys(row, SUMMARY_ROW, {}, f"results[{i}].")
    want = expect.get("p0_gpa")
    if want is not None:
        have = sorted(row["p0_gpa"] for row in doc["results"])
        if len(have) != len(want) or any(
            abs(a - b) > 1e-9 for a, b in zip(have, sorted(want), strict=True)
        ):
            raise ContractError(f"'results' are at p0 {have} GPa, the settings ask for {want}")


#: What every row of ``summary.json``'s ``results`` holds (one per p0) that a reader indexes.
SUMMARY_ROW = {"p0_gpa": "number", "effective_shear_strength_mpa": "number?"}
SCAN = JsonContract(
    "scan.json",
    required={"points_total": "count", "force_calls_total": "count"},
    optional={
        "points_done": "count",
        "thickness_angstrom": "numbers",
        "area_angstrom2": "number",
        "points_computed": "count",
        "adhesion": "mapping",
        "warnings": "list",
        "load_folds": "list",
        "fold_rerelaxation": "mapping?",
        "symmetry": "mapping",
    },
    check=_check_scan,
)
ANALYZE = JsonContract(
    "analyze.json",
    required={"warnings": "list"},
    optional={
        "symmetry": "mapping",
        "noise": "mapping",
        "load_source": "text",
        "fig2": "list",
        "grid": "mapping",
    },
)
LAWS = JsonContract(
    "laws.json",
    required={"energy_form": "text", **dict.fromkeys(LAW_KEYS, "number")},
    optional={"internal": "mapping", "enthalpy": "mapping", "warnings": "list"},
    check=_check_laws,
)
ELASTIC = JsonContract("elastic.json", required={}, optional={"warnings": "list"})
SUMMARY = JsonContract(
    "summary.json",
    required={"parameters": "mapping", "results": "list"},
    optional={"intervals": "mapping", "gates": "mapping", "provenance": "mapping"},
    check=_check_summary,
)
#: file name -> its contract
CONTRACTS = {c.name: c for c in (SCAN, ANALYZE, LAWS, ELASTIC, SUMMARY)}


def check_document(doc: Any, contract: JsonContract, expect: Mapping[str, Any] | None = None):
    """Raise :class:`ContractError` (the first defect) unless ``doc`` follows ``contract``."""
    check_keys(doc, contract.required, contract.optional)
    if contract.check is not None:
        contract.check(doc, expect or {})


def read_result_json(
    path: str | os.PathLike[str], contract: JsonContract | None = None, **expect: Any
) -> dict:
    """The document of ``path`` checked against ``contract`` (by default the one of its file
    name) and ``expect`` (what the caller knows: ``grid`` of the scan's stage record,
    ``energy_form`` and ``p0_gpa`` of the settings).

    Raises
    ------
    InputError
        One line naming the file and its first defect (see the module).
    """
    path = Path(path)
    contract = contract or CONTRACTS[path.name]
    remedy = f"remove {quoted(path.parent)} and rerun to recompute it"
    try:
        doc = read_json_file(path, contract.name, MAX_BYTES)
    except InputError as exc:
        raise InputError(f"{exc}; {remedy}") from None
    try:
        check_document(doc, contract, expect)
    except ContractError as exc:
        raise InputError(
            f"{quoted(path)}: {exc}; the file does not follow its contract: {remedy}"
        ) from None
    return doc
