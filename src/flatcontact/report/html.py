"""A self-contained HTML report: sections of text, tables and embedded figures.

The report is one file (``report.html``) with every figure embedded as a data
URI (SVG inline when available, else PNG base64), so it can be mailed or
archived on its own. Content is escaped; nothing is fetched from the network.
"""

from __future__ import annotations

import base64
import html
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from flatcontact.foundation.fileio import write_text_atomic

_CSS = """
body { font-family: system-ui, -apple-system, "Segoe UI", sans-serif; max-width: 1100px;
       margin: 2em auto; padding: 0 1em; color: #1d1d1f; line-height: 1.5; }
h1 { border-bottom: 2px solid #3b6ea5; padding-bottom: .3em; }
h2 { color: #3b6ea5; margin-top: 2em; }
table { border-collapse: collapse; margin: 1em 0; font-variant-numeric: tabular-nums; }
th, td { border: 1px solid #ccc; padding: .35em .7em; text-align: right; }
th { background: #eef3f8; } td:first-child, th:first-child { text-align: left; }
figure { margin: 1.5em 0; } figure img { max-width: 100%; border: 1px solid #eee; }
figcaption { font-size: .92em; color: #444; }
.note { background: #fff8e6; border-left: 4px solid #e0a800; padding: .5em 1em; }
footer { margin-top: 3em; font-size: .85em; color: #666; }
"""


@dataclass
class Table:
    """A table: column headers and rows of already formatted cells."""

    headers: Sequence[str]
    rows: Sequence[Sequence[str]]
    caption: str = ""


@dataclass
class Figure:
    """A figure file (``.svg`` or ``.png``) and its caption."""

    path: Path
    caption: str = ""


@dataclass
class Section:
    """A report section: heading, paragraphs, tables, figures and highlighted notes (one box
    per note; a newline in a note breaks its line)."""

    title: str
    paragraphs: list[str] = field(default_factory=list)
    tables: list[Table] = field(default_factory=list)
    figures: list[Figure] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)


def figure_data_uri(path: str | Path) -> str:
    """A ``data:`` URI embedding the image file at ``path`` (SVG or PNG)."""
    path = Path(path)
    mime = {".svg": "image/svg+xml", ".png": "image/png"}.get(path.suffix.lower())
    if mime is None:
        raise ValueError(f"{path}: only .svg and .png figures can be embedded")
    return f"data:{mime};base64,{base64.b64encode(path.read_bytes()).decode()}"


def _table_html(table: Table) -> str:
    head = "".join(f"<th>{html.escape(h)}</th>" for h in table.headers)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>"
        for row in table.rows
    )
    caption = f"<caption>{html.escape(table.caption)}</caption>" if table.caption else ""
    return f"<table>{caption}<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _figure_html(figure: Figure) -> str:
    caption = html.escape(figure.caption)
    return (
        f'<figure><img src="{figure_data_uri(figure.path)}" alt="{caption}">'
        f"<figcaption>{caption}</figcaption></figure>"
    )


def render_html(title: str, sections: Sequence[Section], footer: str = "") -> str:
    """The report as one HTML string."""
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>{html.escape(title)}</title><style>{_CSS}</style></head><body>",
        f"<h1>{html.escape(title)}</h1>",
    ]
    for section in sections:
        parts.append(f"<h2>{html.escape(section.title)}</h2>")
        parts += [f"<p>{html.escape(p)}</p>" for p in section.paragraphs]
        parts += [
            f'<p class="note">{html.escape(n).replace(chr(10), "<br>")}</p>' for n in section.notes
        ]
        parts += [_table_html(t) for t in section.tables]
        parts += [_figure_html(f) for f in section.figures]
    if footer:
        parts.append(f"<footer>{html.escape(footer)}</footer>")
    parts.append("</body></html>")
    return "\n".join(parts)


def write_report(
    path: str | Path, title: str, sections: Sequence[Section], footer: str = ""
) -> Path:
    """Write the self-contained report to ``path`` atomically."""
    return write_text_atomic(path, render_html(title, sections, footer))
