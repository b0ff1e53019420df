"""The HTML report: its rendering (:mod:`.html`) and its content (:mod:`.assemble`, one
section per stage in :mod:`.sections`, numbers written by :mod:`.format`)."""

from flatcontact.report.html import (
    Figure,
    Section,
    Table,
    figure_data_uri,
    render_html,
    write_report,
)

__all__ = ["Figure", "Section", "Table", "figure_data_uri", "render_html", "write_report"]
