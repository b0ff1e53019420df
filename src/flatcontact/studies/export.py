"""``flatcontact study export-uncertainty``: one uncertainty data file from the studies' outputs.

A convergence study fills ``convergence_<form>``, a models study ``model_spread_<form>``
(:func:`flatcontact.studies.output.uncertainty_block`, the ``uncertainty`` entry of each
``study.json``). :func:`merge_studies` lays them into one block — the format of the package
data file ``data/measured/law_uncertainty.json`` that the ``paper`` preset reads
(:data:`flatcontact.config.presets.LAW_UNCERTAINTY_FILE`) and of a run configuration's
``uncertainty:`` section (:class:`flatcontact.config.uncertainty.UncertaintyConfig`):

* the number blocks, each from the one study that measured it (two studies filling the same
  block are refused: which one counts would be a silent choice);
* ``coverage`` 1 (one standard error per component);
* ``measured_on``: the studies' common fingerprints (structure and model,
  :mod:`flatcontact.stages.measured_on`); studies measured on different structures or
  models are refused, in one line;
* ``source`` (the studies' own, joined, unless given) and ``provenance``: this command,
  the date, the version, and per study its file (name and SHA-256) and its own provenance.
"""

from __future__ import annotations

import datetime
from pathlib import Path

from pydantic import ValidationError

from flatcontact import __version__
from flatcontact.config.messages import one_line
from flatcontact.config.uncertainty import MEASURED_ON_KEYS, UncertaintyConfig
from flatcontact.foundation.errors import InputError
from flatcontact.foundation.fileio import file_sha256, quoted, read_json_file
from flatcontact.foundation.result_json import KINDS, ContractError, check_keys

#: The number blocks an uncertainty file may carry (per energy form).
NUMBER_BLOCKS = (
    "convergence_internal",
    "convergence_enthalpy",
    "model_spread_internal",
    "model_spread_enthalpy",
)
#: Largest study.json read (a study of a few hundred variants is well below).
MAX_STUDY_BYTES = 64 * 1024 * 1024


def read_study(path: str | Path) -> dict:
    """The ``study.json`` at ``path`` (or in the directory ``path``), checked to carry a block.

    Raises
    ------
    InputError
        Not readable, not JSON, or without an ``uncertainty`` block with ``measured_on``.
    """
    path = Path(path)
    if path.is_dir():
        path = path / "study.json"
    doc = read_json_file(path, "study.json", MAX_STUDY_BYTES)
    block = doc.get("uncertainty") if isinstance(doc, dict) else None
    if not isinstance(block, dict) or not block.get("measured_on"):
        raise InputError(
            f"{quoted(path)}: no uncertainty block with measured_on; expected the study.json "
            "written by 'flatcontact study convergence' or 'flatcontact study models'"
        )
    try:
        check_keys(
            block,
            {"measured_on": "mapping"},
            {"source": "text", "provenance": "mapping", **dict.fromkeys(NUMBER_BLOCKS, "mapping")},
            "uncertainty.",
        )
        for key, value in block["measured_on"].items():
            if not isinstance(value, str):
                raise ContractError(f"'uncertainty.measured_on.{key}' is {value!r}, not text")
        for number in NUMBER_BLOCKS:
            for key, value in (block.get(number) or {}).items():
                if not KINDS["number"][0](value):
                    raise ContractError(
                        f"'uncertainty.{number}.{key}' is {value!r}, not a finite number"
                    )
    except ContractError as exc:
        raise InputError(
            f"{quoted(path)}: {exc}; expected the study.json written by 'flatcontact study "
            "convergence' or 'flatcontact study models'"
        ) from None
    return doc


def merge_studies(
    studies: dict[str, dict], source: str | None = None, command: str = "", date: str | None = None
) -> dict:
    """One uncertainty document from ``studies`` (file name -> ``study.json`` document).

    Parameters
    ----------
    studies
        Study documents by the name of their file (recorded in the provenance).
    source
        The document's ``source``; default: the studies' sources joined by ``"; "``.
    command
        The command line recorded in the provenance.
    date
        ISO date of the export (default: today).

    Returns
    -------
    dict
        Number blocks, ``coverage``, ``source``, ``measured_on``, ``provenance``; valid as an
        ``uncertainty:`` section.

    Raises
    ------
    InputError
        No study, studies measured on different structures or models, or two studies
        filling the same number block.
    """
    if not studies:
        raise InputError("study export-uncertainty: expected at least one study.json")
    out: dict = {}
    origin: dict[str, str] = {}
    first_name, first = next(iter(studies.items()))
    measured_on = dict(first["uncertainty"]["measured_on"])
    for name, doc in studies.items():
        block = doc["uncertainty"]
        theirs = block["measured_on"]
        for key in MEASURED_ON_KEYS:
            if theirs.get(key) != measured_on.get(key):
                raise InputError(
                    f"{name}: uncertainty.measured_on.{key} {str(theirs.get(key))[:12]} differs "
                    f"from {first_name}'s {str(measured_on.get(key))[:12]}: the studies were "
                    "measured on different structures or models"
                )
        for number in NUMBER_BLOCKS:
            if number not in block:
                continue
            if number in out:
                raise InputError(
                    f"{name}: {number} is also measured by {origin[number]}; export one study "
                    "per block"
                )
            out[number] = dict(block[number])
            origin[number] = name
    doc = {
        **out,
        "coverage": 1.0,
        "source": source
        if source is not None
        else "; ".join(d["uncertainty"].get("source", "") for d in studies.values()),
        "measured_on": measured_on,
        "provenance": {
            "command": command,
            "date": date or datetime.date.today().isoformat(),
            "flatcontact_version": __version__,
            "studies": [
                {
                    "file": name,
                    "blocks": [n for n, o in origin.items() if o == name],
                    **({"sha256": d["_sha256"]} if "_sha256" in d else {}),
                    "provenance": d["uncertainty"].get("provenance", {}),
                }
                for name, d in studies.items()
            ],
        },
    }
    try:
        UncertaintyConfig.model_validate(doc)
    except ValidationError as exc:
        raise one_line(exc, "study export-uncertainty") from None
    return doc


def export_uncertainty(
    paths: list[str | Path], source: str | None = None, command: str = ""
) -> dict:
    """:func:`merge_studies` of the ``study.json`` files at ``paths`` (their SHA-256 recorded)."""
    studies = {}
    for p in paths:
        doc = read_study(p)
        path = Path(p) / "study.json" if Path(p).is_dir() else Path(p)
        studies[str(p)] = {**doc, "_sha256": file_sha256(path)}
    return merge_studies(studies, source, command)
