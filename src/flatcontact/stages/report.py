"""Stage 7, report: one self-contained ``report.html`` from the other stages' folders.

Content in :mod:`flatcontact.report.assemble` (one section per stage,
:mod:`flatcontact.report.sections`), rendering in :mod:`flatcontact.report.html`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from flatcontact.fileio import file_sha256
from flatcontact.layout import EXPERIMENT_COLLAPSE_JSON, REPORT_HTML


@dataclass(frozen=True)
class ReportInputs:
    """The folders of the stages to report (``folders[name]``, name as in
    :data:`flatcontact.layout.STAGES`; ``elastic`` optional) and the package versions."""

    folders: dict[str, Path]
    versions: dict[str, str] = field(default_factory=dict)


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


def _stage_rows(folders: dict[str, Path]) -> list[tuple[str, str, str, str]]:
    from flatcontact.report.format import fmt
    from flatcontact.rundir import RunDirectory

    rows = []
    for name, folder in folders.items():
        rec = RunDirectory.read_record(folder) if folder.exists() else None
        if rec is None or name == "report":
            continue
        rows.append((name, rec.get("state", "?"), fmt(rec.get("seconds")), rec.get("finished", "")))
    return rows


def run_report(settings, inputs: ReportInputs, folder: Path | None, progress=None) -> ReportResult:
    """Write ``folder/report.html`` (title ``report.title``) from ``inputs.folders``."""
    from flatcontact import __version__
    from flatcontact.report.assemble import build_sections
    from flatcontact.report.html import write_report

    sections = build_sections(settings, inputs.folders, _stage_rows(inputs.folders))
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
    return ReportResult(path, [path])
