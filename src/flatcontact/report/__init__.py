"""The HTML report: its rendering (:mod:`.html`) and its content (:mod:`.content`)."""

from flatcontact.report.html import (
    Figure,
    Section,
    Table,
    figure_data_uri,
    render_html,
    write_report,
)

__all__ = ["Figure", "Section", "Table", "figure_data_uri", "render_html", "write_report"]
