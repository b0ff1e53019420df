"""Stage 7, report: one self-contained ``report.html`` from the other stages' folders.

Content in :mod:`flatcontact.report.assemble` (one section per stage,
:mod:`flatcontact.report.sections`), rendering in :mod:`flatcontact.report.html`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from flatcontact.foundation.fileio import file_sha256, write_json_atomic
from flatcontact.foundation.layout import EXPERIMENT_COLLAPSE_JSON, REFUSAL_JSON, REPORT_HTML


@dataclass(frozen=True)
class ReportInputs:
    """The folders of the stages to report (``folders[name]``, name as in
    :data:`flatcontact.foundation.layout.STAGES`; ``elastic`` optional), the package versions, and for a
    run refused after the scan its refusal
    (:func:`flatcontact.report.sections.refusal.refusal_record`: only the stages it lists as
    finished are reported)."""

    folders: dict[str, Path]
    versions: dict[str, str] = field(default_factory=dict)
    refusal: dict | None = None


@dataclass
class ReportResult:
    """Where the report was written."""

    path: Path | None
    files: list[Path] = field(default_factory=list)

    def to_json(self) -> dict:
        return {"report": str(self.path) if self.path is not None else None}


def approximant_study_digest(path: str | Path) -> dict:
    """The content of the approximant study's files the report reads (sha256 of
    ``study.json`` and of ``experiment_collapse.json`` beside it, if present): part of the
    report stage's fingerprint, so a rerun or an extended study reruns the report."""
    path = Path(path)
    collapse = path.parent / EXPERIMENT_COLLAPSE_JSON
    return {
        "study_json_sha256": file_sha256(path),
        "experiment_collapse_sha256": file_sha256(collapse) if collapse.is_file() else None,
    }


def refusal_of(settings, stage: str, error, gates, finished: list[str], scan: dict) -> dict:
    """The refusal record of a run refused at ``stage`` with ``error`` after the scan
    (:func:`flatcontact.report.sections.refusal.refusal_record`): the findings of ``gates``
    (a :class:`flatcontact.analysis.gates.GateReport`, or None) not in
    ``contact.accept_untrusted``, the ``finished`` stages, and from ``scan`` (``scan.json``)
    the folds recorded and their re-relaxation."""
    from flatcontact.report.sections.refusal import refusal_record

    refused = gates.refused(settings.contact.accept_untrusted) if gates is not None else []
    return refusal_record(
        stage,
        str(error),
        [{"gate": f.gate, "message": f.message} for f in refused],
        finished,
        settings.scan.grid,
        scan.get("load_folds") or [],
        scan.get("fold_rerelaxation"),
    )


def _stage_rows(
    folders: dict[str, Path], refusal: dict | None = None
) -> list[tuple[str, str, str, str]]:
    from flatcontact.foundation.rundir import RunDirectory
    from flatcontact.report.format import fmt

    rows = []
    for name, folder in folders.items():
        if refusal is not None and name == refusal["stage"]:
            rows.append((name, "refused", "", ""))
            continue
        if refusal is not None and name not in refusal["finished"]:
            continue  # not run (or a folder of an earlier run's settings)
        rec = RunDirectory.read_record(folder) if folder.exists() else None
        if rec is None or name == "report":
            continue
        rows.append((name, rec.get("state", "?"), fmt(rec.get("seconds")), rec.get("finished", "")))
    return rows


def report_stage(
    settings, inputs: ReportInputs, folder: Path | None, progress=None
) -> ReportResult:
    """Write ``folder/report.html`` (title ``report.title``) from ``inputs.folders``; a refused
    run's also ``refusal.json`` (``inputs.refusal``)."""
    from flatcontact import __version__
    from flatcontact.report.assemble import build_sections
    from flatcontact.report.html import write_report

    folders, refusal = inputs.folders, inputs.refusal
    if refusal is not None:
        folders = {k: v for k, v in folders.items() if k in refusal["finished"]}
    rows = _stage_rows(inputs.folders, refusal)
    sections = build_sections(settings, folders, rows, refusal)
    footer = (
        "flatcontact "
        + __version__
        + " · "
        + ", ".join(f"{k} {v}" for k, v in inputs.versions.items())
    )
    if folder is None:
        return ReportResult(None)
    folder.mkdir(parents=True, exist_ok=True)
    path = write_report(folder / REPORT_HTML, settings.report.title, sections, footer)
    files = [path]
    if refusal is not None:
        files.append(write_json_atomic(folder / REFUSAL_JSON, refusal))
    return ReportResult(path, files)
