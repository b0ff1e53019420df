"""The report of a run refused after the scan (issue 32).

A stage that refuses after the scan (:meth:`flatcontact.pipeline.Pipeline.run`: a validity
gate before the contact stage, a fold or a load outside the data in the analysis, a law the
contact model cannot take) still leaves ``report.html``: the finished stages with their
figures and numbers, the refusal with its points and the remedies
(:mod:`flatcontact.report.sections.refusal`, ``07-report/refusal.json``). A run-directory
defect (a corrupt stage record, a link) is not a refusal and writes nothing.
"""

from __future__ import annotations

import logging
from pathlib import Path

from flatcontact.foundation.layout import STAGES
from flatcontact.stages.report import refusal_of

log = logging.getLogger("flatcontact.run")


def refused_report(pipe, stage: str, error: Exception) -> Path | str:
    """The report of ``pipe`` (a :class:`~flatcontact.pipeline.Pipeline`) refused at ``stage``
    with ``error``: its path, or a note when the report itself failed (logged: the refusal,
    not the report's failure, stays the run's error)."""
    log.error("stage %s: refused: %s", stage, error)
    try:
        gates = pipe.gates() if stage == "contact" and "laws" in pipe.results else None
        done = [name for name in STAGES if name in pipe.results]
        return pipe.report(refusal_of(pipe.config, stage, error, gates, done, pipe.scan_summary()))
    except Exception as failed:
        log.error("report of the refused run: failed: %s", failed)
        return "not written (run.log)"
